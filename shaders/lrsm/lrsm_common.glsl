// The layer partition, warp, overlap falloff and Eq. 12 of src/techniques/lrsm/lrsm.h (the same
// formulas as lrsm_math.cpp). Needs common/lights.glsl (u_light) included before.
uniform int u_depthIntervals;   // a + 1
uniform int u_normalIntervals;  // b + 1
uniform float u_zNear, u_zFar;  // depth range of the scene seen from the light (m)
uniform float u_delta;          // overlap width (m)

// Light depth: planar along a directional light's direction, radial from a spot or point light.
float lightDepth(vec3 p) {
  if (u_light.positionType.w > VOXLAB_LIGHT_DIRECTIONAL + 0.5) return length(p - u_light.positionType.xyz);
  return dot(p, u_light.directionRange.xyz);
}

int depthIntervalOf(float z) {
  float t = (z - u_zNear) / max(u_zFar - u_zNear, 1e-20);
  return clamp(int(floor(t * float(u_depthIntervals))), 0, u_depthIntervals - 1);
}
int normalIntervalOf(float ndotl) { return clamp(int(floor(ndotl * float(u_normalIntervals))), 0, u_normalIntervals - 1); }

void layerRange(int d, out float zMin, out float zMax) {
  float w = (u_zFar - u_zNear) / float(u_depthIntervals);
  zMin = u_zNear + w * float(d) - (d > 0 ? 0.5 * u_delta : 0.0);
  zMax = u_zNear + w * float(d + 1) + (d + 1 < u_depthIntervals ? 0.5 * u_delta : 0.0);
}

float falloffK(float t, bool smoothK) {
  t = clamp(t, 0.0, 1.0);
  return smoothK ? t * t * (3.0 - 2.0 * t) : t;
}

// Eq. 15 (0 outside the layer's range).
float layerFalloff(int d, float z, bool smoothK) {
  float lo, hi;
  layerRange(d, lo, hi);
  if (z < lo || z > hi) return 0.0;
  if (u_delta <= 0.0) return 1.0;
  float f = 1.0;
  if (d > 0 && z < lo + u_delta) f = min(f, falloffK((z - lo) / u_delta, smoothK));
  if (d + 1 < u_depthIntervals && z > hi - u_delta) f = min(f, falloffK((hi - z) / u_delta, smoothK));
  return f;
}

// Abramowitz and Stegun 7.1.26 (|error| < 1.5e-7).
float approxErf(float x) {
  float s = x < 0.0 ? -1.0 : 1.0;
  x = abs(x);
  float t = 1.0 / (1.0 + 0.3275911 * x);
  float y = 1.0 - (((((1.061405429 * t - 1.453152027) * t) + 1.421413741) * t - 0.284496736) * t + 0.254829592) * t * exp(-x * x);
  return s * y;
}

// Eq. 12: the Gaussian N(mu, sigma2) integrated over [zc - rc, zc + rc] (warped units).
float gaussianVisibility(float zc, float rc, float mu, float sigma2) {
  float k = 1.0 / sqrt(2.0 * sigma2);
  return clamp(0.5 * (approxErf((zc + rc - mu) * k) - approxErf((zc - rc - mu) * k)), 0.0, 1.0);
}
