#version 450
// One level of the 2D OR hierarchy (seed 000 Listing 4.44): level l + 1 texel (x, y) = OR of the
// level-l texels (2x + {0,1}, 2y + {0,1}); all 128 slices kept. Reads level l and writes level
// l + 1 as two separate image bindings (no sampling of the level being rendered: the thesis'
// render-into-l+1-while-sampling-l is a feedback loop, undefined in GL 4.5 section 9.3).
layout(local_size_x = 8, local_size_y = 8) in;
layout(rgba32ui, binding = 0) uniform readonly uimage2D u_fine;
layout(rgba32ui, binding = 1) uniform writeonly uimage2D u_coarse;
layout(r32ui, binding = 2) uniform writeonly uimage2D u_popcount;
uniform int u_coarseRes;

void main() {
  ivec2 c = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(c, ivec2(u_coarseRes)))) return;
  uvec4 m = imageLoad(u_fine, 2 * c) | imageLoad(u_fine, 2 * c + ivec2(1, 0)) |
            imageLoad(u_fine, 2 * c + ivec2(0, 1)) | imageLoad(u_fine, 2 * c + ivec2(1, 1));
  imageStore(u_coarse, c, m);
  ivec4 n = bitCount(m);
  imageStore(u_popcount, c, uvec4(uint(n.x + n.y + n.z + n.w)));
}
