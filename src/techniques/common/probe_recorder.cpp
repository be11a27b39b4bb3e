#include "techniques/common/probe_recorder.h"

namespace voxlab {

TracerAndRecorder tracerAndRecorder(ShaderLibrary& shaders, const std::vector<std::string>& files,
                                    const std::string& defines) {
  return {shaders.program(files, defines), shaders.program(files, defines + "#define VOXLAB_RECORD_PROBE 1\n")};
}

void dispatchRecorder(GLuint recorder, glm::ivec3 localSize) {
  glUseProgram(recorder);
  dispatchCompute(localSize, localSize);
}

}  // namespace voxlab
