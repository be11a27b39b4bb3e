#version 450
// A plot of the probed pixel's ray (the RaySample records written so far): one bar per sample,
// its height the sample's contribution (luminance) over the largest one, yellow where the
// sample was lit, a red tick on the axis where it was shadowed; the transmittance T in blue and
// the running sum over its final value in green, both on a 0..1 scale.
#include "volumetric/volumetric_shared.h"
layout(local_size_x = 8, local_size_y = 8) in;
layout(std430, binding = VOXLAB_BINDING_RAY_RECORDS) readonly buffer Records { RaySample records[]; };
layout(std430, binding = VOXLAB_BINDING_RAY_RECORD_COUNT) readonly buffer RecordCount { uint recordCount; };
layout(rgba8, binding = 0) uniform writeonly image2D u_plot;
uniform int u_steps;

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 size = imageSize(u_plot);
  if (px.x >= size.x || px.y >= size.y) return;
  int n = int(min(recordCount, uint(VOXLAB_MAX_MARCH_STEPS)));
  float largest = 1e-30, total = 1e-30;
  for (int i = 0; i < n; ++i) largest = max(largest, luminance(records[i].contribution.rgb));
  if (n > 0) total = max(records[n - 1].contribution.a, 1e-30);
  vec3 c = vec3(0.01);
  int i = px.x * u_steps / size.x;  // the sample this column shows
  float y = (float(px.y) + 0.5) / float(size.y);
  if (i < n) {
    RaySample s = records[i];
    float h = luminance(s.contribution.rgb) / largest;
    if (s.medium.x > 0.5 && y <= h) c = vec3(0.9, 0.75, 0.3);
    if (s.medium.x < 0.5 && px.y < 3) c = vec3(0.9, 0.1, 0.1);
    float pixel = 1.0 / float(size.y);
    if (abs(y - s.phase.w) < pixel) c = vec3(0.3, 0.5, 1.0);
    if (abs(y - s.contribution.a / total) < pixel) c = vec3(0.3, 0.9, 0.4);
  }
  imageStore(u_plot, px, vec4(c, 1.0));
}
