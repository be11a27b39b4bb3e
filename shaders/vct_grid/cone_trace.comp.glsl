#version 450
// Cone tracing, one invocation per pixel of the G-buffer:
//  - N diffuse cones around the normal (directions and normalised weights from the CPU, see
//    src/techniques/common/cone_layout.cpp): indirect diffuse = albedo * sum_i w_i L_i, and
//    ambient occlusion = 1 - sum_i w_i A_i(range), the cosine-weighted visible fraction;
//  - one specular cone along the mirror direction, aperture from the roughness;
//  - one soft-shadow cone toward the light: visibility = 1 - accumulated opacity.
#include "common/shared.h"
#include "common/voxel_space.glsl"
#include "common/cone_setup.glsl"
#include "common/cone_trace.glsl"
#include "common/lights.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba16f, binding = 0) uniform writeonly image2D u_indirectDiffuse;
layout(rgba16f, binding = 1) uniform writeonly image2D u_indirectSpecular;
layout(r16f, binding = 2) uniform writeonly image2D u_ambientOcclusion;
layout(r16f, binding = 3) uniform writeonly image2D u_softShadow;
uniform int u_traceShadow;  // 0: the soft-shadow image is not wanted (outputs on demand)
uniform int u_traceSpecular;  // 0: the specular image is not wanted (composite.specular = 0 and no view of it)

// Totals over the pass: samples of the diffuse, specular and shadow cones, volume fetches, pixels
// shaded (the background traces nothing).
layout(std430, binding = VOXLAB_BINDING_CONE_TRACE_COUNTS) buffer ConeTraceCounts { uint coneTraceCounts[5]; };
uniform int u_firstRow;                  // the stage traces the image in bands of rows [u_firstRow,
uniform int u_endRow;                    // u_endRow), one band per iteration

void main() {
  ivec2 px = ivec2(gl_GlobalInvocationID.xy) + ivec2(0, u_firstRow);
  if (any(greaterThanEqual(px, imageSize(u_indirectDiffuse))) || px.y >= u_endRow) return;
  // At half resolution each traced pixel shades the top-left G-buffer pixel of its 2x2 block;
  // composite upsamples with weights that respect depth and normal edges.
  ivec2 g = min(px * u_scale, textureSize(u_position, 0) - 1);
  vec4 pos = texelFetch(u_position, g, 0);
  if (pos.w == 0.0) {
    imageStore(u_indirectDiffuse, px, vec4(0.0));
    if (u_traceSpecular != 0) imageStore(u_indirectSpecular, px, vec4(0.0));
    imageStore(u_ambientOcclusion, px, vec4(0.0));
    if (u_traceShadow != 0) imageStore(u_softShadow, px, vec4(0.0));
    return;
  }
  bool record = px == u_probePixel;
  vec3 n = normalize(texelFetch(u_normal, g, 0).xyz);
  vec3 albedo = texelFetch(u_albedo, g, 0).rgb;
  vec3 origin = pos.xyz + n * u_startOffset;
  float start = u_voxelSize;

  vec3 t = normalize(abs(n.y) < 0.9 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
  vec3 b = cross(n, t);
  vec3 incoming = vec3(0.0);
  float occlusion = 0.0;
  for (int i = 0; i < u_coneCount; ++i) {
    vec3 d = normalize(u_cones[i].x * t + u_cones[i].y * b + u_cones[i].z * n);
    ConeResult c = traceCone(origin, d, u_diffuseAperture, start, u_maxDistance, u_aoRange, i, record);
    incoming += u_cones[i].w * c.radiance;
    occlusion += u_cones[i].w * c.blockedAt;
  }
  uint diffuseSamples = g_samples;
  imageStore(u_indirectDiffuse, px, vec4(albedo * incoming, 1.0));
  imageStore(u_ambientOcclusion, px, vec4(1.0 - occlusion));

  // Without the specular image (outputs on demand) only the probed pixel traces it, for its record.
  if (u_traceSpecular != 0 || record) {
    vec3 view = normalize(pos.xyz - u_cameraPos);
    vec3 r = reflect(view, n);
    ConeResult spec = traceRadianceCone(origin, r, u_specularAperture, start, u_maxDistance, u_coneCount, record);
    if (u_traceSpecular != 0) imageStore(u_indirectSpecular, px, vec4(spec.radiance, 1.0));
  }
  uint specularSamples = g_samples - diffuseSamples;

  // Without the soft-shadow image (outputs on demand) only the probed pixel traces it, for its record.
  if (u_traceShadow != 0 || record) {
    vec3 toLight; float dist;
    lightDirection(pos.xyz, toLight, dist);
    float shadowVis = 0.0;
    if (dot(n, toLight) > 0.0) {
      float end = shadowConeEnd(dist, tan(0.5 * u_shadowAperture), u_lodBias, u_voxelSize);
      ConeResult sh = traceCone(origin, toLight, u_shadowAperture, start, min(end, u_maxDistance), 1e30, u_coneCount + 1, record);
      shadowVis = 1.0 - sh.blocked;
    }
    if (u_traceShadow != 0) imageStore(u_softShadow, px, vec4(shadowVis));
  }
  atomicAdd(coneTraceCounts[0], diffuseSamples);
  atomicAdd(coneTraceCounts[1], specularSamples);
  atomicAdd(coneTraceCounts[2], g_samples - diffuseSamples - specularSamples);
  atomicAdd(coneTraceCounts[3], g_fetches);
  atomicAdd(coneTraceCounts[4], 1u);
}
