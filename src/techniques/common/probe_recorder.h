// A stage's shader built twice, for every pixel and as the recorder of the probed pixel's records
// (shaders/common/probe_recorder.glsl says why).
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "gpu/gl.h"
#include "gpu/shader_library.h"

namespace voxlab {

struct TracerAndRecorder {
  GLuint tracer = 0;    // every pixel, nothing recorded
  GLuint recorder = 0;  // the probed pixel alone, its records only (VOXLAB_RECORD_PROBE)
};

TracerAndRecorder tracerAndRecorder(ShaderLibrary& shaders, const std::vector<std::string>& files,
                                    const std::string& defines);

// Runs the recorder (bound here): one work group of 'localSize', whose first invocation traces the
// probed pixel.
void dispatchRecorder(GLuint recorder, glm::ivec3 localSize);

}  // namespace voxlab
