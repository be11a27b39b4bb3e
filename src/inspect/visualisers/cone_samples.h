// Cone samples (Semantic::ConeSamples): the probe record of a cone tracer. Every record is one
// sample of one cone of the probed pixel, in the ConeSample layout of shaders/common/shared.h.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "capture/capture.h"

namespace voxlab {

// One cone of a probed pixel, samples in the order they were taken (the ConeSample layout of
// shaders/common/shared.h, which every Semantic::ConeSamples output uses).
struct ConeSeries {
  int cone = 0;
  std::vector<float> distance, lod, opacity, luminance, diameter, sampleAlpha;
  std::vector<glm::vec3> position;  // sample centres (world units)
};
std::vector<ConeSeries> decodeConeSamples(const CapturedOutput& out);
// "" when every cone's samples are composited front to back, else a message naming the cone and
// the sample: distances increase along the cone, every sample alpha lies in 0..1, and each
// accumulated opacity is the one before composited with the sample's alpha,
// opacity[i] = opacity[i-1] + (1 - opacity[i-1]) * alpha[i] (opacity[-1] = 0), within
// kCompositingTolerance. This holds for a tracer that composites correctly whatever the volume
// holds, and fails for one that adds alphas, takes their maximum or composites back to front
// (all of which still never decrease).
std::string checkFrontToBackCompositing(const std::vector<ConeSeries>& cones);
// The recorded opacities are fp32 values the shader computed (with fma or without); recomputing
// one step from the recorded previous opacity and alpha differs by rounding only: measured at most
// 3.0e-8 (lrsm, which stores 1 - transmittance; vct-grid and svo exactly 0) on the Cornell box
// probes of ConeSamples.EveryTechniquesRecordsAreCompositedFrontToBack. A tracer that adds alphas
// or takes their maximum is off by about opacity * alpha, over 1e-2 after the first samples.
inline constexpr float kCompositingTolerance = 1e-6f;

}  // namespace voxlab
