// Test entry point. Besides the ordinary TEST()s, it registers one snapshot test per declared
// output of every registered technique (tests/unit/snapshot_test.cpp), so a new technique, stage or
// output is covered without test code. A listener fails every test during which GL reported a
// message of severity high or medium (gpu/gl_debug.h), naming the message and its scope.
#include <gtest/gtest.h>

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
  ::testing::InitGoogleTest(&argc, argv);
  voxlab::snapshot::registerSnapshotTests();
  auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
  auto* printer = listeners.Release(listeners.default_result_printer());
  listeners.Append(new GLErrorsFailTests);
  if (printer) listeners.Append(printer);
  return RUN_ALL_TESTS();
}
