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
// "" when every cone's accumulated opacity never decreases, else a message naming the cone/sample.
std::string checkOpacityMonotonic(const std::vector<ConeSeries>& cones);

}  // namespace voxlab
