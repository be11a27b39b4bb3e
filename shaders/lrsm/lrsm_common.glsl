// The layer partition, warp, overlap falloff and Eq. 12 of src/techniques/lrsm/lrsm.h (the same
// formulas as lrsm_math.cpp). Needs common/lights.glsl (u_light) included before.
uniform int u_depthIntervals;   // a + 1
uniform int u_normalIntervals;  // b + 1
uniform float u_zNear, u_zFar;  // depth range of the scene seen from the light (m)
uniform float u_delta;          // overlap width (m)

// Light depth: planar along a directional light's direction, radial from a spot or point light.
float lightDepth(vec3 p) {
  if (lightType() > VOXLAB_LIGHT_DIRECTIONAL + 0.5) return length(p - u_light.positionType.xyz);
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

// One lobe: the layer's Gaussian (Eq. 12 as printed).
int singleLobe(float mu, float sigma2, out vec3 means, out vec3 weights, out vec3 variances) {
  means = vec3(mu, 0.0, 0.0);
  weights = vec3(1.0, 0.0, 0.0);
  variances = vec3(sigma2, 1.0, 1.0);
  return 1;
}

// A layer's depths as Gaussian lobes (means, weights summing to 1, variances; warped units) for
// Eq. 12. A layer may hold two surfaces at different depths (a box's top and the floor beyond its
// shadow, both facing the light): one Gaussian fitted to both puts surface in the empty air
// between them, and its mean point there. From the first four moments (E[z'^k], k = 1..4) the
// depths are matched by two Gaussians of equal variance lambda sigma^2 whose means carry the rest
// of the variance and all of the skewness: lambda = 0 is two planes, lambda = 1 one Gaussian
// (kurtosis 3, no skew), a tilted plane's even spread gives lambda = 0.23. Where sigma^2 is small
// the third and fourth central moments are lost in the UNORM16 rounding (about 1e-5 / alpha per
// moment), so the two lobes take over from the single one over sigma^2 in
// [LRSM_TWO_LOBE_VARIANCE, 3 LRSM_TWO_LOBE_VARIANCE]: lobe 0 is the single Gaussian, 1 and 2 the pair.
int depthLobes(vec4 moments, float minVariance, out vec3 means, out vec3 weights, out vec3 variances) {
  float mu = moments.x, var = moments.y - mu * mu;
  singleLobe(mu, max(var, minVariance), means, weights, variances);
  float blend = smoothstep(LRSM_TWO_LOBE_VARIANCE, 3.0 * LRSM_TWO_LOBE_VARIANCE, var);
  if (blend <= 0.0) return 1;
  float c3 = moments.z - 3.0 * mu * moments.y + 2.0 * mu * mu * mu;
  float c4 = moments.w - 4.0 * mu * moments.z + 6.0 * mu * mu * moments.y - 3.0 * mu * mu * mu * mu;
  float skew = c3 / (var * sqrt(var));
  float kurtosis = max(c4 / (var * var), skew * skew + 1.0);  // no distribution lies below
  // The pair's kurtosis, skew^2 / (1 - lambda) + 1 + 4 lambda - 2 lambda^2, rises with lambda.
  // The bisection's count is 0 where the single lobe was returned above: llvmpipe runs a returned
  // lane's code masked, and only a loop that no lane is left in stops costing (most layers hold
  // one surface, and their rows would pay 16 masked iterations).
  float lo = 0.0, hi = 1.0;
  int bisections = blend > 0.0 ? 16 : 0;
  for (int i = 0; i < bisections; ++i) {
    float lambda = 0.5 * (lo + hi);
    float k = skew * skew / max(1.0 - lambda, 1e-6) + 1.0 + 4.0 * lambda - 2.0 * lambda * lambda;
    if (k < kurtosis) lo = lambda; else hi = lambda;
  }
  float lambda = 0.5 * (lo + hi);
  if (lambda > 0.999) return 1;
  // The lobes' means: a two-point distribution of variance (1 - lambda) sigma^2 and skewness gamma0.
  float rest = 1.0 - lambda, gamma0 = skew / (rest * sqrt(rest));
  float q = clamp(0.5 * (1.0 - sign(gamma0) * sqrt(gamma0 * gamma0 / (gamma0 * gamma0 + 4.0))), 1e-4, 1.0 - 1e-4);
  float spread = sqrt(rest * var), lobeVariance = max(lambda * var, minVariance);
  means = vec3(mu, mu + spread * sqrt((1.0 - q) / q), mu - spread * sqrt(q / (1.0 - q)));
  weights = vec3(1.0 - blend, blend * q, blend * (1.0 - q));
  variances = vec3(max(var, minVariance), lobeVariance, lobeVariance);
  return 3;
}
