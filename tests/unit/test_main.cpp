// Test entry point. Besides the ordinary TEST()s, it registers one snapshot test per declared
// output of every registered technique (tests/unit/snapshot_test.cpp), so a new technique, stage or
// output is covered without test code. A listener fails every test during which GL reported a
// message of severity high or medium (gpu/gl_debug.h), naming the message and its scope.
//
// Each test process gets a temporary folder of its own (TMPDIR and TEST_TMPDIR, read by
// ::testing::TempDir() and std::filesystem::temp_directory_path()): ctest runs tests side by side
// (scripts/test.sh, -j2), and scenes and images written under fixed names in a shared /tmp were
// truncated by one test while another read them. The folder is removed when every test passed and
// kept, with its path printed, when one failed, for the files a failure message names.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>

#include "gpu/gl_debug.h"

namespace voxlab::snapshot {
void registerSnapshotTests();
}

namespace {

// gtest allows failures from OnTestEnd (they count against the test that just ran) when the
// listener comes before the result printer, which main() arranges.
class GLErrorsFailTests : public ::testing::EmptyTestEventListener {
  void OnTestStart(const ::testing::TestInfo&) override { voxlab::takeGLFailures(); }
  void OnTestEnd(const ::testing::TestInfo&) override {
    for (const auto& m : voxlab::takeGLFailures()) ADD_FAILURE() << m.describe();
  }
};

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  const char* base = std::getenv("TMPDIR");
  const fs::path tmp = fs::path(base && *base ? base : "/tmp") / ("voxlab-test-" + std::to_string(::getpid()));
  fs::create_directories(tmp);
  setenv("TMPDIR", tmp.c_str(), 1);
  setenv("TEST_TMPDIR", tmp.c_str(), 1);
  ::testing::InitGoogleTest(&argc, argv);
  voxlab::snapshot::registerSnapshotTests();
  auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
  auto* printer = listeners.Release(listeners.default_result_printer());
  listeners.Append(new GLErrorsFailTests);
  if (printer) listeners.Append(printer);
  const int status = RUN_ALL_TESTS();
  std::error_code ignored;
  if (status == 0)
    fs::remove_all(tmp, ignored);
  else
    std::cerr << "voxlab_tests: temporary files kept in " << tmp.string() << "\n";
  return status;
}
