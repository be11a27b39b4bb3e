// Ray set-up and RSM lookup shared by the near-field rays and the voxel path tracer.
// Needs common/lights.glsl (u_light) before it.
#include "near_field/near_field_shared.h"

layout(binding = 6) uniform sampler2D u_rsmPosition; // xyz, w = footprint (0 = empty)
layout(binding = 7) uniform sampler2D u_rsmNormal;
layout(binding = 8) uniform sampler2D u_rsmRadiance;
uniform int u_normalCheck, u_planeTest;
uniform float u_voxelDiagonal, u_epsilonScale;
const float PI = 3.14159265358979;

// Hammersley point i of n: ((i + 0.5) / n, radical inverse of i).
vec2 hammersley(int i, int n) {
  return vec2((float(i) + 0.5) / float(n), float(bitfieldReverse(uint(i))) * 2.3283064365386963e-10);
}
// A hash of a 2D cell to a point of [0, 1)^2 (white noise: neighbouring cells are unrelated).
vec2 hashedPoint(ivec2 cell) {
  uint h = uint(cell.x) * 1973u + uint(cell.y) * 9277u + 26699u;
  h = (h ^ 61u) ^ (h >> 16u); h *= 9u; h ^= h >> 4u; h *= 0x27d4eb2du; h ^= h >> 15u;
  uint g = h * 747796405u + 2891336453u;
  g = ((g >> ((g >> 28u) + 4u)) ^ g) * 277803737u; g = (g >> 22u) ^ g;
  return vec2(float(h >> 8u), float(g >> 8u)) / 16777216.0;
}

// Point j of the 2D Sobol (0,2)-sequence: (radical inverse of j, its second dimension). Every
// aligned block of 2^m consecutive points has one point in each of the 2^m elementary boxes.
vec2 sobolPoint(uint j) {
  float first = float(bitfieldReverse(j)) * 2.3283064365386963e-10;
  uint second = 0u;
  for (uint v = 1u << 31; j != 0u; j >>= 1, v ^= v >> 1)
    if ((j & 1u) != 0u) second ^= v;
  return vec2(first, float(second) * 2.3283064365386963e-10);
}

// Sample i of pixel px's n directions, 'salt' choosing an independent pattern (a path's bounce).
// The 16 pixels of a 4 x 4 tile share one Sobol (0,2)-sequence: pixel j of the tile (row by row)
// takes its points j n .. j n + n - 1, so each pixel's n points are stratified on their own (an
// aligned block of a (0,2)-sequence when n is a power of 2) and the tile's 16 n points together are
// too; the tile shifts them all by one hashed offset (Cranley-Patterson rotation, which keeps
// that stratification on the torus). The filter, which averages a tile and more, then averages a
// well-spread set of 16 n directions instead of 16 unrelated sets (white noise per pixel blurs into
// blotches of the filter's size).
vec2 samplePoint(int i, int n, ivec2 px, int salt) {
  ivec2 tile = (px >> 2) + ivec2(7919, 104729) * salt;
  uint j = uint((px.x & 3) + 4 * (px.y & 3));
  return fract(hashedPoint(tile) + sobolPoint(j * uint(n) + uint(i)));
}

// Cosine-distributed direction around n within the part of the hemisphere 'spread' keeps
// (sin^2 theta = u.x * spread, phi = 2 pi u.y).
vec3 cosineDirection(vec3 n, vec2 u, float spread, out float cosTheta) {
  float sin2 = u.x * spread;
  cosTheta = sqrt(max(1.0 - sin2, 0.0));
  float sinTheta = sqrt(sin2), phi = 2.0 * PI * u.y;
  vec3 t = normalize(abs(n.x) > 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
  vec3 b = cross(n, t);
  return normalize(t * (sinTheta * cos(phi)) + b * (sinTheta * sin(phi)) + n * cosTheta);
}

struct RsmLookup {
  uint category;   // NF_CAT_VALID, NF_CAT_NOT_IN_RSM, NF_CAT_TOO_FAR or NF_CAT_WRONG_FACING
  vec3 radiance;   // reflected radiance of the sender (valid only)
  vec3 normal;     // sender's lit-side normal (when the texel is covered)
  vec4 position;   // the RSM texel's position (xyz) and footprint (w; 0 = empty texel)
  vec2 texel;      // RSM texel (-1 outside)
  float dist, epsilon, facing;
};

// Is the RSM's surface at the hit's texel the surface that was hit, lit on the receiver's side?
RsmLookup lookupRsm(vec3 hit, vec3 receiver) {
  RsmLookup r;
  r.category = NF_CAT_NOT_IN_RSM;
  r.radiance = vec3(0.0);
  r.normal = vec3(0.0);
  r.position = vec4(0.0);
  r.texel = vec2(-1.0);
  r.dist = 0.0; r.epsilon = 0.0; r.facing = 0.0;
  // The texel that sees the hit: one view, or the cube face of a point light that looks at it.
  const ivec2 rsmSize = textureSize(u_rsmPosition, 0);
  vec3 uvz;
  if (u_light.spot.w > 0.5 && lightMapCoord(hit, lightMapFace(hit), rsmSize, uvz) && all(lessThan(uvz.xy, vec2(1.0)))) {
    ivec2 texel = ivec2(uvz.xy * vec2(rsmSize));
    r.texel = vec2(texel);
    vec4 sender = texelFetch(u_rsmPosition, texel, 0);
    r.position = sender;
    if (sender.w > 0.0) {
      vec3 ns = texelFetch(u_rsmNormal, texel, 0).xyz;
      r.normal = ns;
      // Paper: |hit - sender| < epsilon = max(voxel diagonal, texel footprint) (its max(v,
      // s/cos a * z/znear): the footprint includes 1/cos a and the distance), capped at 4
      // diagonals (GP3). Plane test: the hit lies within a voxel diagonal of the sender's
      // plane (its distance along the plane is at most the footprint plus the cap).
      if (u_planeTest != 0) {
        r.dist = abs(dot(ns, hit - sender.xyz));
        r.epsilon = u_voxelDiagonal;
        if (length(hit - sender.xyz) > 4.0 * u_voxelDiagonal + sender.w * u_epsilonScale) r.dist = 1e30;
      } else {
        r.dist = length(hit - sender.xyz);
        r.epsilon = min(4.0 * u_voxelDiagonal, max(u_voxelDiagonal, sender.w * u_epsilonScale));
      }
      r.facing = dot(ns, normalize(receiver - hit));
      if (r.dist > r.epsilon) r.category = NF_CAT_TOO_FAR;
      else if (u_normalCheck != 0 && r.facing < 0.0) r.category = NF_CAT_WRONG_FACING;
      else {
        r.category = NF_CAT_VALID;
        r.radiance = texelFetch(u_rsmRadiance, texel, 0).rgb;
      }
    }
  }
  return r;
}
