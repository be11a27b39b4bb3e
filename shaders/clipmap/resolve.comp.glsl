#version 450
// Turns the fixed-point sums of one box of cells into texels of every face (RGBA8 or RGBA16F): the
// isotropic face holds radiance = sum / fragments, alpha 1 in every occupied cell (the cell's
// direct content, Direct_k); the six directional faces the fronts each direction sees.
#include "clipmap/clipmap.glsl"
#include "common/facing.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = CLIPMAP_BINDING_ACCUM) readonly buffer Accumulators { uint accum[]; };
layout(std430, binding = CLIPMAP_BINDING_COUNTERS) buffer Counters { uint counters[]; };
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform writeonly image3D u_atlas;
uniform ivec3 u_boxLo;
uniform ivec3 u_boxSize;
uniform int u_level;
uniform ivec3 u_skipLo;  // cells of [u_skipLo, u_skipHi) are left alone (a full build's covered block)
uniform ivec3 u_skipHi;
uniform int u_faces;

void main() {
  ivec3 g = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(g, u_boxSize))) return;
  ivec3 cell = u_boxLo + g;
  if (all(greaterThanEqual(cell, u_skipLo)) && all(lessThan(cell, u_skipHi))) return;
  ivec3 phys = toroidalAddress(cell);
  uint i = accumulatorIndex(u_level, phys);
  uint count = accum[i];
  // The stage cleared every face of the box's cells (update_stages.cpp, clearAtlasCells): an empty
  // cell, which no direction sees either, is zero already.
  if (count == 0u) {
    atomicAdd(counters[5 * u_level + 2], 1u);
    return;
  }
  // Integer division first: the same sums give the same texel on every run.
  uvec3 mean = uvec3(accum[i + 1u], accum[i + 2u], accum[i + 3u]) / count;
  vec4 value = vec4(vec3(mean) / u_fixedScale, 1.0);
  imageStore(u_atlas, atlasTexel(0, u_level, phys), value);
  // Six faces: face 1 + d shows a cone travelling along d the fronts it sees (common/facing.glsl):
  // the mean light of the fragments whose fronts d sees, covering the largest front weight among
  // them. Behind a surface or edge-on to it the face is empty, so a cell holding both faces of a
  // slab shows each side its own light (vct-grid builds its directional volumes from the same
  // leaves, vct_grid/mipmap_anisotropic.comp.glsl).
  uint code = accum[i + kClipFacingWord];
  for (int d = 0; d < u_faces - 1; ++d) {
    uint j = i + clipDirectionWord(d);
    uint seen = accum[j];
    vec4 leaf = vec4(0.0);
    if (seen > 0u) leaf = vec4(vec3(uvec3(accum[j + 1u], accum[j + 2u], accum[j + 3u]) / seen) / u_fixedScale, 1.0);
    imageStore(u_atlas, atlasTexel(1 + d, u_level, phys), facingLeaf(leaf, code, d));
  }
  atomicAdd(counters[5 * u_level + 2], 1u);
}
