#version 450
// The phase function for the current g: VOXLAB_PHASE_SAMPLES samples of p(mu) (for the printed
// integral and the tests) and a plot of log10 p against mu in [-1, 1]: Henyey-Greenstein white,
// the thesis' (1-g)^2 version red, isotropic 1/(4 pi) grey; vertical line at mu = 0, horizontal
// lines at each power of ten from 1e-3 to 1e2.
#include "volumetric/volumetric_shared.h"
#include "volumetric/phase.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = VOXLAB_BINDING_PHASE_SAMPLES) writeonly buffer Samples { PhaseSample samples[]; };
layout(rgba8, binding = 0) uniform writeonly image2D u_plot;
uniform float u_g;
uniform ivec2 u_plotSize;

const float LOG_MIN = -3.0, LOG_MAX = 2.0;
float rowOf(float p) { return (log(max(p, 1e-12)) / log(10.0) - LOG_MIN) / (LOG_MAX - LOG_MIN) * float(u_plotSize.y); }
float muOf(float x) { return -1.0 + 2.0 * x / float(u_plotSize.x); }
// Whether row y lies within the curve's vertical extent over column x (so steep parts stay joined).
bool onCurve(int x, float y, int which) {
  float a = muOf(float(x)), b = muOf(float(x + 1));
  float pa = which == 0 ? phaseHenyeyGreenstein(a, u_g) : which == 1 ? phaseThesis(a, u_g) : 1.0 / (4.0 * VOL_PI);
  float pb = which == 0 ? phaseHenyeyGreenstein(b, u_g) : which == 1 ? phaseThesis(b, u_g) : 1.0 / (4.0 * VOL_PI);
  float ya = rowOf(pa), yb = rowOf(pb);
  return y >= min(ya, yb) - 1.0 && y <= max(ya, yb) + 1.0;
}

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  uint linear = uint(px.y * u_plotSize.x + px.x);
  if (linear < uint(VOXLAB_PHASE_SAMPLES)) {
    float mu = -1.0 + 2.0 * float(linear) / float(VOXLAB_PHASE_SAMPLES - 1);
    samples[linear].value = vec4(mu, phaseHenyeyGreenstein(mu, u_g), phaseThesis(mu, u_g), 1.0 / (4.0 * VOL_PI));
  }
  if (px.x >= u_plotSize.x || px.y >= u_plotSize.y) return;
  float y = float(px.y) + 0.5;
  vec3 c = vec3(0.01);
  for (int k = int(LOG_MIN); k <= int(LOG_MAX); ++k)
    if (px.y == min(int(floor(rowOf(pow(10.0, float(k))))), u_plotSize.y - 1)) c = vec3(0.06);
  if (px.x == u_plotSize.x / 2) c = vec3(0.06);
  if (onCurve(px.x, y, 2)) c = vec3(0.5);
  if (onCurve(px.x, y, 1)) c = vec3(0.9, 0.15, 0.1);
  if (onCurve(px.x, y, 0)) c = vec3(1.0);
  imageStore(u_plot, px, vec4(c, 1.0));
}
