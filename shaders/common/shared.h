// Structs and binding points shared by C++ (src/) and GLSL (shaders/). Included by both, so the
// two sides cannot disagree on a layout. Every struct is std430-compatible: vec4 or scalar
// members only, sizes multiples of 16 bytes.
#ifndef VOXLAB_SHARED_H
#define VOXLAB_SHARED_H

#ifdef __cplusplus
#include <cstdint>
#include <glm/glm.hpp>
namespace voxlab::gpu {
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using uint = uint32_t;
#endif

// --- Binding points ------------------------------------------------------------------------------
#define VOXLAB_BINDING_MATERIALS 0        // SSBO: GpuMaterial[]
#define VOXLAB_BINDING_FRAGMENTS 1        // SSBO: VoxelFragment[]
#define VOXLAB_BINDING_FRAGMENT_COUNT 0   // atomic counter: number of voxel fragments appended
#define VOXLAB_BINDING_CONE_SAMPLES 2     // SSBO: ConeSample[] of the probed pixel
#define VOXLAB_BINDING_AXIS_COUNTS 3      // SSBO: uint[4] triangles per dominant axis (x, y, z, unused)
#define VOXLAB_BINDING_CONE_SAMPLE_COUNT 4  // SSBO: uint number of ConeSample records written
#define VOXLAB_BINDING_SCENE_VERTICES 5   // SSBO: the scene's vertices, 8 floats each (position, normal, uv)
#define VOXLAB_BINDING_SCENE_INDICES 6    // SSBO: the scene's triangle indices, 3 uints per triangle
#define VOXLAB_BINDING_TRIANGLE_INFO 7    // SSBO: uint per triangle: material (bits 0-23), class (bit 31: 1 = small)
#define VOXLAB_BINDING_TRIANGLE_LIST 8    // SSBO: uint indices of the triangles a compute voxelizer visits
#define VOXLAB_BINDING_CLASS_COUNTS 9     // SSBO: uint[8] counters of the triangle classification
#define VOXLAB_BINDING_COVERAGE_BITS 10   // SSBO: uint[] alpha coverage pyramids, 32 bits per word (scene/alpha_coverage.h)
#define VOXLAB_BINDING_COVERAGE_LEVELS 11 // SSBO: uvec4[] per pyramid level: first bit, width, height, unused
#define VOXLAB_BINDING_CONE_TRACE_COUNTS 12  // SSBO: uint[5] of a cone-trace pass: samples (diffuse, specular, shadow), volume fetches, pixels shaded
#define VOXLAB_BINDING_PROBE_CHAIN 13     // SSBO: vec4[PROBE_CHAIN_SLOTS], the composite's record of the probed pixel
#define VOXLAB_BINDING_MIP_BLOCKS 14      // SSBO: uint[] packed texels of a mip level that can be non-empty (vct-grid)
#define VOXLAB_BINDING_MIP_BLOCK_COUNT 15 // SSBO: uint, how many a pass appended
#define VOXLAB_BINDING_VOXEL_SUMS 16      // SSBO: per voxel slot, the exact sums of its fragments (vct_grid/voxel_sums.glsl)
#define VOXLAB_BINDING_VOXEL_LIST 17      // SSBO: uint count, then uint[] the slots of the occupied voxels (vct_grid/voxel_sums.glsl)

#define VOXLAB_UNIFORM_LIGHT 0            // UBO: GpuLight of the scene's shadow-casting light

// Texture units
#define VOXLAB_UNIT_ALBEDO 0
#define VOXLAB_UNIT_EMISSIVE 1

// Vertex attribute locations of the scene's vertex buffer.
#define VOXLAB_ATTR_POSITION 0
#define VOXLAB_ATTR_NORMAL 1
#define VOXLAB_ATTR_UV 2

// --- Structs -------------------------------------------------------------------------------------

struct GpuMaterial {
  vec4 baseColor;  // linear RGBA factor
  vec4 emissive;   // rgb: linear emitted radiance; a: 1 when an emissive texture multiplies it
  vec4 alpha;      // x: alphaCutoff, y: 1 = alphaMode MASK (else opaque), z: first coverage level,
                   // w: coverage levels (voxelization's alpha test, scene/alpha_coverage.h)
};

// One voxel fragment: a surface sample produced by voxelization.
struct VoxelFragment {
  uint position;   // voxel coordinates packed 10:10:10 (x bits 0-9, y 10-19, z 20-29)
  uint albedo;     // RGBA8 unorm (packUnorm4x8), linear
  uint normal;     // packSnorm4x8 of the geometric normal (w unused)
  uint emission;   // RGBA8 unorm, linear emitted radiance clamped to [0,1]
};

// Cone samples of one probed pixel (written when probing is enabled).
#define VOXLAB_MAX_CONES 16
#define VOXLAB_MAX_SAMPLES_PER_CONE 64
struct ConeSample {
  vec4 position;     // xyz: world position of the sample centre, w: diameter (world units)
  vec4 accumulated;  // rgb: accumulated radiance after this sample, a: accumulated opacity
  vec4 info;         // x: cone index, y: distance along the cone, z: mip level (LOD), w: sample alpha
};

// The probe chain: what the composite computed for the probed pixel, one vec4 per slot, from the
// surface through the direct light and each indirect term to the displayed value. The composite
// stage (src/techniques/common/composite_stage.cpp) declares a named field for each, with its unit.
#define PROBE_CHAIN_PIXEL 0       // xy: the pixel (rows from the top, as clicked), z: 1 = a surface (0: the sky)
#define PROBE_CHAIN_POSITION 1    // xyz: world position (m)
#define PROBE_CHAIN_NORMAL 2      // xyz: unit normal
#define PROBE_CHAIN_ALBEDO 3      // rgb: diffuse albedo
#define PROBE_CHAIN_EMISSION 4    // rgb: emitted radiance
#define PROBE_CHAIN_TO_LIGHT 5    // xyz: unit direction to the light, w: distance (m; 1e30 for a sun)
#define PROBE_CHAIN_IRRADIANCE 6  // rgb: irradiance on a surface facing the light, w: n.l clamped at 0
#define PROBE_CHAIN_SHADOW 7      // x: receiver depth, y: map depth (centre tap), z: lit taps of 9, w: visibility used
#define PROBE_CHAIN_REFLECTED 8   // rgb: albedo / pi * irradiance * n.l * visibility (the sky where no surface)
#define PROBE_CHAIN_TERMS 9       // two slots per indirect term: rgb the term, w its weight; then rgb weight * term
#define PROBE_CHAIN_COMBINED 17   // rgb: reflected + emission + the weighted terms, w: exposure
#define PROBE_CHAIN_EXPOSED 18    // rgb: exposure * combined
#define PROBE_CHAIN_TONEMAPPED 19 // rgb: x / (1 + x) of the exposed value
#define PROBE_CHAIN_STORED 20     // rgb: the tonemapped value as the 8-bit final image stores it
#define PROBE_CHAIN_SLOTS 21

// The light every technique shades with (the scene's first light), std140-compatible.
#define VOXLAB_LIGHT_DIRECTIONAL 0.0
#define VOXLAB_LIGHT_POINT 1.0
#define VOXLAB_LIGHT_SPOT 2.0
struct GpuLight {
  mat4 shadowViewProj;  // world -> light clip space of the shadow map
  vec4 positionType;    // xyz: position (world), w: VOXLAB_LIGHT_*
  vec4 directionRange;  // xyz: unit direction the light travels, w: range (0 = infinite)
  vec4 radiance;        // rgb: colour * intensity (W/sr, or W/m^2 when directional)
  vec4 spot;            // x: cos(inner cone), y: cos(outer cone), z: normal offset per unit clip w (m), w: 1 = shadow map valid
  // Point lights: the shadow map and the RSM are atlases of six cube faces, +x -x +y -y +z -z in
  // tiles of 3 columns and 2 rows (common/lights.glsl: lightMapFace, lightMapTile); world -> clip
  // space of each face's 90-degree view. Unused for spot and directional lights (shadowViewProj).
  mat4 faceViewProj[6];
};

#ifdef __cplusplus
}  // namespace voxlab::gpu
#endif
#endif  // VOXLAB_SHARED_H
