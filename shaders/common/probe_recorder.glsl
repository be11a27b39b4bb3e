// The probed pixel's records in a program of their own (docs/architecture.md, "Shaders"). A stage
// whose records of one pixel (cone samples, a ray's walk, a gather's layers) would cost every pixel
// their stores behind a per-pixel flag builds its shader twice (techniques/common/probe_recorder.h):
// for every pixel, where kRecordProbe is a compile-time false and the recording code is not there
// (llvmpipe runs a branch that depends on the invocation in every lane, masked), and with
// VOXLAB_RECORD_PROBE, the recorder: one work group in which only the first invocation runs, at the
// probed pixel, tracing it again and writing its records and nothing else.
#ifndef VOXLAB_PROBE_RECORDER_GLSL
#define VOXLAB_PROBE_RECORDER_GLSL
#ifdef VOXLAB_RECORD_PROBE
const bool kRecordProbe = true;
#else
const bool kRecordProbe = false;
#endif

// The pixel this invocation traces: its own, or in the recorder the probed one. False for the
// recorder's other invocations, which do nothing.
bool recorderPixel(ivec2 probePixel, out ivec2 px) {
#ifdef VOXLAB_RECORD_PROBE
  px = probePixel;
  return gl_LocalInvocationIndex == 0u;
#else
  px = ivec2(gl_GlobalInvocationID.xy);
  return true;
#endif
}
#endif
