// Punctual lights, evaluated exactly as src/scene/light_model.h does on the CPU (the reference
// path tracer): KHR_lights_punctual smooth spot falloff t^2, range window (1-(d/r)^4)^2, 1/d^2.
#include "common/shared.h"

layout(std140, binding = VOXLAB_UNIFORM_LIGHT) uniform LightBlock { GpuLight u_light; };

// The light's type (VOXLAB_LIGHT_*). A program built for one type (lightKindDefines in
// techniques/common/light_stage.h defines VOXLAB_LIGHT_KIND) has it as a constant, so the code of
// the other types is compiled out (llvmpipe runs both sides of every branch).
float lightType() {
#ifdef VOXLAB_LIGHT_KIND
  return VOXLAB_LIGHT_KIND;
#else
  return u_light.positionType.w;
#endif
}

// Direction to the light (unit) and its distance (1e30 for directional lights).
void lightDirection(vec3 p, out vec3 toLight, out float dist) {
  if (lightType() == VOXLAB_LIGHT_DIRECTIONAL) {
    toLight = -u_light.directionRange.xyz;
    dist = 1e30;
    return;
  }
  vec3 d = u_light.positionType.xyz - p;
  dist = max(length(d), 1e-4);
  toLight = d / dist;
}

// Irradiance a surface facing the light receives at p, before the cosine and visibility.
vec3 lightIrradiance(vec3 p) {
  vec3 toLight; float dist;
  lightDirection(p, toLight, dist);
  if (lightType() == VOXLAB_LIGHT_DIRECTIONAL) return u_light.radiance.rgb;
  float falloff = 1.0 / max(dist * dist, 1e-8);
  float range = u_light.directionRange.w;
  if (range > 0.0) {
    float r = dist / range;
    float w = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    falloff *= w * w;
  }
  if (lightType() == VOXLAB_LIGHT_SPOT) {
    float cosA = dot(u_light.directionRange.xyz, -toLight);
    float t = clamp((cosA - u_light.spot.y) / max(u_light.spot.x - u_light.spot.y, 1e-4), 0.0, 1.0);
    falloff *= t * t;
  }
  return u_light.radiance.rgb * falloff;
}

// True when the shadow map decides the visibility of a point at map coordinates uvz (xy texture
// coordinates, z depth). Inside the map's box it does. A directional light's map is fitted to the
// scene's bounds in light space (techniques/common/shadow_map_stage.cpp), not to the whole voxel
// volume: no geometry lies beside that box or between it and the light, so a point there is lit
// without a lookup (false); a point beyond the far plane lies behind everything in its column and
// compares at depth 1. The reference tracer's shadow rays see the same geometry, so the points of
// a medium anywhere in the volume get the visibility the tracer gives them (the volumetric march
// uses it). A spot's map covers its cone; outside it the caller decides.
bool shadowMapDecides(inout vec3 uvz) {
  if (!(any(lessThan(uvz, vec3(0.0))) || any(greaterThan(uvz, vec3(1.0))))) return true;
  if (lightType() != VOXLAB_LIGHT_DIRECTIONAL) return false;
  if (any(lessThan(uvz, vec3(0.0))) || any(greaterThan(uvz.xy, vec2(1.0)))) return false;
  uvz.z = 1.0;
  return true;
}

// The light's maps (shadow map, RSM) for a point light are atlases of six cube faces: the face
// that sees p is the major axis of p - light (0..5: +x -x +y -y +z -z); -1 for spot and
// directional lights, whose map is one view (shadowViewProj).
int lightMapFace(vec3 p) {
  if (lightType() != VOXLAB_LIGHT_POINT) return -1;
  vec3 d = p - u_light.positionType.xyz, a = abs(d);
  if (a.x >= a.y && a.x >= a.z) return d.x >= 0.0 ? 0 : 1;
  if (a.y >= a.z) return d.y >= 0.0 ? 2 : 3;
  return d.z >= 0.0 ? 4 : 5;
}

mat4 lightMapViewProj(int face) { return face < 0 ? u_light.shadowViewProj : u_light.faceViewProj[face]; }

// The part of a map of 'size' texels a face covers, in texture coordinates (xy min, zw max): the
// whole map for one view; for a point light face f the tile (f mod 3, f / 3) of floor(size.x / 3)
// by size.y / 2 texels (techniques/common/shadow_map_stage.cpp renders the faces there).
vec4 lightMapTile(int face, ivec2 size) {
  if (face < 0) return vec4(0.0, 0.0, 1.0, 1.0);
  vec2 tile = vec2(size.x / 3, size.y / 2);
  vec2 lo = vec2(face % 3, face / 3) * tile;
  return vec4(lo / vec2(size), (lo + tile) / vec2(size));
}

// Map coordinates of p: xy in the map texture (inside the face's tile), z its depth from the light;
// false when p lies outside the face's view (beside a spot's map, behind the light).
bool lightMapCoord(vec3 p, int face, ivec2 size, out vec3 uvz) {
  vec4 clip = lightMapViewProj(face) * vec4(p, 1.0);
  uvz = clip.xyz / clip.w * 0.5 + 0.5;
  vec4 tile = lightMapTile(face, size);
  bool inside = clip.w > 0.0 && all(greaterThanEqual(uvz, vec3(0.0))) && all(lessThanEqual(uvz, vec3(1.0)));
  uvz.xy = mix(tile.xy, tile.zw, uvz.xy);
  return inside;
}

// The shadow-map test of one receiver, with what decided it (the probe chain records it).
struct ShadowTest {
  float visibility;     // lit taps / 9
  float receiverDepth;  // the offset receiver's depth in the map (0 near .. 1 far); -1 when the map does not decide
  float mapDepth;       // the depth the map stores at the centre tap; -1 when the map does not decide
  float litTaps;        // taps of the 3x3 PCF that see the light
};

// The 3x3 PCF shadow test of p with normal n (shadowVisibility's visibility is its result).
ShadowTest shadowTest(sampler2D shadowMap, vec3 p, vec3 n) {
  ShadowTest r = ShadowTest(1.0, -1.0, -1.0, 9.0);
  if (u_light.spot.w < 0.5) return r;
  // Normal offset keeps the receiver from shadowing itself: shadow.normal-offset texels of the
  // map at the receiver (spot.z is per unit of clip w: 1 for a sun's orthographic map, the view
  // depth for a perspective one), so it scales with the scene and the map's resolution. A point
  // light's face is the one that sees the offset receiver.
  float w = (lightMapViewProj(lightMapFace(p)) * vec4(p, 1.0)).w;
  vec3 q = p + n * (u_light.spot.z * w);
  int face = lightMapFace(q);
  ivec2 size = textureSize(shadowMap, 0);
  vec3 uvz;
  // Surfaces lie inside the map's box (it is fitted to them); a receiver that its normal offset
  // moves out of the box is lit (measured: one Sponza pixel at 128x128 would change otherwise).
  if (!lightMapCoord(q, face, size, uvz)) return r;
  // The taps stay inside the face's tile: a point light's neighbouring tile is another view.
  vec4 tile = lightMapTile(face, size);
  vec2 texel = 1.0 / vec2(size);
  float lit = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) {
      vec2 uv = clamp(uvz.xy + vec2(x, y) * texel, tile.xy + 0.5 * texel, tile.zw - 0.5 * texel);
      lit += (texture(shadowMap, uv).r >= uvz.z - 1e-4) ? 1.0 : 0.0;
    }
  vec2 centre = clamp(uvz.xy, tile.xy + 0.5 * texel, tile.zw - 0.5 * texel);
  return ShadowTest(lit / 9.0, uvz.z, texture(shadowMap, centre).r, lit);
}

// 1 when p is lit according to the shadow map (PCF over 3x3 texels), 0 when in shadow.
float shadowVisibility(sampler2D shadowMap, vec3 p, vec3 n) { return shadowTest(shadowMap, p, n).visibility; }

// Where a cone toward a light at distance dist must end so that its samples stay clear of the
// light's own surroundings. A point light sits on or just under a fixture (the Cornell box's spot
// is 1 cm below the ceiling, against its panel), voxelized like any wall. A cone marched all the
// way to the light ends inside that fixture, and as the number of whole steps changes with the
// distance its last samples take in more or less of it: the soft shadow showed concentric rings
// over every wall. A sample at distance s has the diameter D = 2 s tanHalf and reads mip level
// lod = log2(D / voxel) + lodBias, blended with the next coarser level, whose texels are up to
// 2^(lodBias + 1) D wide; a lookup reaches 1.5 texels from the sample, 6 * 2^lodBias * s * tanHalf.
// The march ends where that reach plus 1.5 voxels (a level-0 texel's reach) falls short of the
// light. (Measured on the
// Cornell box's soft-shadow output at lodBias -1: a reach of 1 or 2 radii, s tanHalf or 2 s
// tanHalf, still left faint rings; 3, this bound, none.) Light occluded in the last stretch before
// the light, 17 % of the distance for an 8-degree cone at lodBias -1, is not seen; the shadow map
// has no such gap.
float shadowConeEnd(float dist, float tanHalf, float lodBias, float voxelSize) {
  return max((dist - 1.5 * voxelSize) / (1.0 + 6.0 * exp2(lodBias) * tanHalf), 0.0);
}
