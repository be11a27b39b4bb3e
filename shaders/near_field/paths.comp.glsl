#version 450
// Voxel path tracing (seed 000 section 3.2.4, after Thiedemann et al. 2011), one bounce of one
// path per dispatch: from the path's current vertex a cosine-distributed ray walks the binary
// hierarchy to its first voxel; where the RSM sees that surface lit toward the vertex, the
// reflected radiance L~ is added with the path's weight; the next vertex takes its normal from the
// RSM when the lookup is valid, else from the voxel normal grid (turned toward the ray), and its
// albedo from the voxel albedo grid. Weight W_k = rho_0 ... rho_{k-1} (cosine sampling of a
// Lambertian BRDF cancels cos / pdf), so a path adds sum_k W_k L~_k: the same sum as the thesis'
// backward propagation L_k = L~_k + rho_k L_{k+1}, accumulated forward. A path whose ray crosses
// the volume without a hit ends in the sky (common/sky.glsl): it adds the weight so far (the
// albedos of its vertices, this one's included) times L_sky.
#include "common/shared.h"
#include "common/lights.glsl"
#include "near_field/traversal.glsl"
#include "near_field/ray_common.glsl"
#include "common/sky.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 1) uniform sampler2D u_position;
layout(binding = 2) uniform sampler2D u_normal;
layout(binding = 3) uniform sampler2D u_albedo;
layout(binding = 9) uniform sampler3D u_voxelAlbedo;
layout(binding = 10) uniform sampler3D u_voxelNormal;
layout(rgba32f, binding = 0) uniform image2D u_indirect;    // running (1/P) sum over paths of sum_k W_k L~_k
layout(rgba32f, binding = 1) uniform image2D u_vertex;      // xyz: current vertex, w: 1 alive
layout(rgba32f, binding = 2) uniform image2D u_vertexNormal;
layout(rgba32f, binding = 3) uniform image2D u_weight;      // rgb: W, the product of albedos so far

uniform int u_path, u_pathCount, u_bounce, u_traceScale;
uniform float u_normalOffset, u_rayOffset, u_maxLength;
uniform vec3 u_volumeOrigin;
uniform float u_volumeEdge;
uniform int u_budget;

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy);
  ivec2 traced = imageSize(u_indirect);
  if (any(greaterThanEqual(px, traced))) return;
  vec3 p, n, weight;
  if (u_bounce == 0) {
    ivec2 g = min(px * u_traceScale, textureSize(u_position, 0) - 1);
    vec4 pos = texelFetch(u_position, g, 0);
    if (pos.w == 0.0) { imageStore(u_vertex, px, vec4(0.0)); return; }
    p = pos.xyz;
    n = normalize(texelFetch(u_normal, g, 0).xyz);
    weight = texelFetch(u_albedo, g, 0).rgb;
  } else {
    vec4 v = imageLoad(u_vertex, px);
    if (v.w == 0.0) return;
    p = v.xyz;
    n = imageLoad(u_vertexNormal, px).xyz;
    weight = imageLoad(u_weight, px).rgb;
  }
  // Path j, bounce k: sample j of P of the pixel's tile pattern for bounce k (bounce 0 as
  // near-field's rays, so one bounce of P paths is near-field's P rays).
  vec2 u = samplePoint(u_path, u_pathCount, px, u_bounce);
  float cosTheta;
  vec3 dir = cosineDirection(n, u, 1.0, cosTheta);
  float along = u_rayOffset * u_voxelDiagonal / max(cosTheta, 1e-3);
  vec3 origin = p + n * (u_normalOffset * u_voxelDiagonal) + dir * along;
  vec3 o = (origin - u_volumeOrigin) / u_volumeEdge;
  vec3 e = (origin + dir * u_maxLength - u_volumeOrigin) / u_volumeEdge;
  Walk w = traverse(o, e, u_budget, false);
  if (w.end != NF_END_HIT) {
    if (skyOn() && skyEscaped(false, w.end == NF_END_LEFT, origin + dir * u_maxLength)) {
      vec4 sum = imageLoad(u_indirect, px);
      imageStore(u_indirect, px, vec4(sum.rgb + weight * skyThrough(1.0) / float(u_pathCount), 1.0));
    }
    imageStore(u_vertex, px, vec4(0.0));
    return;
  }
  vec3 hit = u_volumeOrigin + u_volumeEdge * (o + w.tHit * (e - o));
  RsmLookup look = lookupRsm(hit, p);
  if (look.category == NF_CAT_VALID) {
    vec4 sum = imageLoad(u_indirect, px);
    imageStore(u_indirect, px, vec4(sum.rgb + weight * look.radiance / float(u_pathCount), 1.0));
  }
  // The next vertex: the voxel's attributes (slice k of the column lies in voxel z = k * res / 128).
  vec3 uvw = (vec3(w.voxel.xy, float(w.voxel.z * u_gridRes / NF_SLICES)) + 0.5) / float(u_gridRes);
  vec3 albedo = texture(u_voxelAlbedo, uvw).rgb;
  vec3 nh = look.category == NF_CAT_VALID ? look.normal : texture(u_voxelNormal, uvw).xyz * 2.0 - 1.0;
  nh = normalize(nh);
  if (dot(nh, dir) > 0.0) nh = -nh;  // the side the ray arrived from
  imageStore(u_vertex, px, vec4(hit, 1.0));
  imageStore(u_vertexNormal, px, vec4(nh, 0.0));
  imageStore(u_weight, px, vec4(weight * albedo, 0.0));
}
