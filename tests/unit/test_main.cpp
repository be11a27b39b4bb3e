// Test entry point. Besides the ordinary TEST()s, it registers one snapshot test per declared
// output of every registered technique (tests/unit/snapshot_test.cpp), so a new technique, stage or
// output is covered without test code.
#include <gtest/gtest.h>

namespace voxlab::snapshot {
void registerSnapshotTests();
}

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  voxlab::snapshot::registerSnapshotTests();
  return RUN_ALL_TESTS();
}
