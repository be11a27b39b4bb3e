// The item index of a 1D dispatch that dispatchCompute (src/gpu/shader_library.cpp) may have
// folded into rows of at most 65535 work groups: x + y * (invocations per row). Include it after
// the layout(local_size_x = ...) line: gl_WorkGroupSize is declared from there on.
#ifndef VOXLAB_INVOCATION_GLSL
#define VOXLAB_INVOCATION_GLSL
uint linearInvocation() {
  return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * (gl_NumWorkGroups.x * gl_WorkGroupSize.x);
}
#endif
