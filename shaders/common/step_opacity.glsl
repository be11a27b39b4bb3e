// The opacity of a cone's step: a texel's opacity belongs to a path one texel long, and a step of
// 'ratio' texels sees 1 - (1 - alpha)^ratio. For small alpha the series ratio * alpha * (1 + (1 -
// ratio) alpha / 2) (its next term is of order alpha^3, below 1e-6 of alpha here): llvmpipe's pow
// of a base just below 1 answers in steps of 2^-23, so a texel of opacity 1e-13 got 1.2e-7, and
// the radiance of the step, its premultiplied colour times the ratio of the two, was a million
// times too bright (svo's ring cones along a tangent, which see a wall with weight 1e-15).
#ifndef VOXLAB_STEP_OPACITY_GLSL
#define VOXLAB_STEP_OPACITY_GLSL
float stepOpacity(float alpha, float ratio) {
  alpha = clamp(alpha, 0.0, 1.0);
  return alpha < 1e-3 ? ratio * alpha * (1.0 + 0.5 * (1.0 - ratio) * alpha) : 1.0 - pow(1.0 - alpha, ratio);
}

// A cone's sample s (a texel's premultiplied radiance and opacity) composited front to back into
// what the cone has gathered (radiance, opacity), its opacity corrected to a step of 'ratio'
// texels. Returns the corrected opacity.
float compositeSample(inout vec3 radiance, inout float opacity, vec4 s, float ratio) {
  float a = stepOpacity(s.a, ratio);
  vec3 c = s.a > 0.0 ? s.rgb * (a / s.a) : vec3(0.0);
  radiance += (1.0 - opacity) * c;
  opacity += (1.0 - opacity) * a;
  return a;
}
#endif
