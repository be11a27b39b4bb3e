// The shared a-trous filter's sizing (src/techniques/common/atrous_filter_stage.h): how many
// pixels its equivalent kernel averages, and the passes it picks for a number of rays per pixel.
#include <gtest/gtest.h>

#include "techniques/common/atrous_filter_stage.h"

namespace voxlab {
namespace {

TEST(AtrousFilter, EffectivePixelsOfTheB3KernelWithHoles) {
  EXPECT_DOUBLE_EQ(atrousEffectivePixels(0), 1.0);
  // One pass: the 1D B3 taps (1, 4, 6, 4, 1) / 16 have squares summing to 70 / 256, so the 2D
  // kernel averages (256 / 70)^2 pixels.
  EXPECT_NEAR(atrousEffectivePixels(1), (256.0 / 70.0) * (256.0 / 70.0), 1e-9);
  // Each further pass with a doubled hole roughly quadruples it (the kernel doubles along each
  // axis): 65.6, 274.5, 1110 (the values the parameter's help quotes).
  EXPECT_NEAR(atrousEffectivePixels(2), 65.6, 0.05);
  EXPECT_NEAR(atrousEffectivePixels(3), 274.5, 0.05);
  EXPECT_NEAR(atrousEffectivePixels(4), 1110.0, 0.5);
}

TEST(AtrousFilter, FewerRaysPerPixelGetMorePasses) {
  // filter.samples = 1024 (the default): 2 rays need 4 passes, 4 and 8 rays 3, 16 and 32 rays 2.
  EXPECT_EQ(atrousPassesFor(1024.0, 2, 6), 4);
  EXPECT_EQ(atrousPassesFor(1024.0, 4, 6), 3);
  EXPECT_EQ(atrousPassesFor(1024.0, 8, 6), 3);
  EXPECT_EQ(atrousPassesFor(1024.0, 16, 6), 2);
  EXPECT_EQ(atrousPassesFor(1024.0, 32, 6), 2);
  EXPECT_EQ(atrousPassesFor(1.0, 1, 6), 0);      // one ray is enough: no filter
  EXPECT_EQ(atrousPassesFor(1e9, 1, 6), 6);      // never more than the cap
}

}  // namespace
}  // namespace voxlab
