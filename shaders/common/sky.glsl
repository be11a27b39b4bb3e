// The constant sky (sky.radiance, src/techniques/common/sky.h): an environment radiance L,
// W/(m^2 sr), grey, 0 by default. Written once and included by every tracer and composite, so
// every technique applies the same rules:
//  - a cone or ray that escapes sees L through the transmittance it has left: skyThrough(T) is
//    added to what it gathered;
//  - it escapes when its march stops because its sample has wholly left the volume it traces
//    (nothing beyond is known), or when it ends (its full length, a ray's radius) with its axis
//    outside the scene's bounds: the bounds are a box, convex, so a ray outside them never comes
//    back to any geometry. A cone or ray that ends inside the bounds (at its full length, out of
//    steps), that hits something, or whose opacity saturates sees no sky;
//  - a camera pixel that sees no surface shows L (skyBackground) in the direct and combined
//    images, tonemapped as every other pixel: the reference tracer's camera rays that miss.
// With L = 0 every term is exactly 0, so images without a sky are unchanged.
#ifndef VOXLAB_SKY_GLSL
#define VOXLAB_SKY_GLSL

uniform vec3 u_skyRadiance;  // (L, L, L)
uniform vec3 u_skySceneMin;  // the scene's bounds (world): beyond them nothing occludes
uniform vec3 u_skySceneMax;

// Is there a sky? (A uniform branch: without one, tracers skip the sky's writes.)
bool skyOn() { return any(greaterThan(u_skyRadiance, vec3(0.0))); }

bool outsideScene(vec3 p) { return any(lessThan(p, u_skySceneMin)) || any(greaterThan(p, u_skySceneMax)); }

// The escape rule. leftVolume: the march stopped because its sample lay wholly outside the traced
// volume; ended: it stopped at its full length with its axis at 'end' (world).
bool skyEscaped(bool leftVolume, bool ended, vec3 end) { return leftVolume || (ended && outsideScene(end)); }

// The sky seen through the transmittance a cone or ray has left.
vec3 skyThrough(float transmittance) { return transmittance * u_skyRadiance; }

// What a cone adds at the end of its march: the sky through its transmittance if it escaped.
vec3 coneSky(bool leftVolume, bool ended, vec3 end, float opacity) {
  return skyEscaped(leftVolume, ended, end) ? skyThrough(1.0 - opacity) : vec3(0.0);
}

// The radiance of a camera pixel that sees no surface.
vec3 skyBackground() { return u_skyRadiance; }

#endif
