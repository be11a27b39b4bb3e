// Phase functions of the volumetric technique (1/sr). mu is the cosine of the scattering angle
// between the light's direction of travel and the direction towards the camera, i.e.
// dot(view ray direction, unit vector towards the light).
const float VOL_PI = 3.14159265358979;

// Henyey-Greenstein, normalised over the sphere: (1 - g^2) / (4 pi (1 + g^2 - 2 g mu)^1.5).
// mu is clamped (a dot product of unit vectors can exceed 1 by rounding) and the base kept
// positive, so g near 1 gives a large finite value, never pow(negative, 1.5).
float phaseHenyeyGreenstein(float mu, float g) {
  mu = clamp(mu, -1.0, 1.0);
  float base = max(1.0 + g * g - 2.0 * g * mu, 1e-6);
  return (1.0 - g * g) / (4.0 * VOL_PI * base * sqrt(base));
}

// Seed 000, Eq. 1 and Listing 4.53: (1 - g)^2 in the numerator. It integrates to (1 - g)/(1 + g)
// over the sphere, not 1. Kept only so the lesson and the tests can show the error.
float phaseThesis(float mu, float g) {
  mu = clamp(mu, -1.0, 1.0);
  float base = max(1.0 + g * g - 2.0 * g * mu, 1e-6);
  return (1.0 - g) * (1.0 - g) / (4.0 * VOL_PI * base * sqrt(base));
}
