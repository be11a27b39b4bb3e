#version 450
// Writes the unreached cells of one level (src/techniques/clipmap/unreached_cells.h), found on the
// CPU from the level's isotropic face. One word per cell in logical order (x fastest): 0 leaves
// the cell alone; 1 empties it (a cell an earlier move filled that the camera's space reaches
// now); otherwise 2 + 8 * (the logical index of its surface cell) + the step out of that wall
// into the camera's space (0..5: +x -x +y -y +z -z; 7: none, a cell the camera's space runs
// inside). A filled cell shows the wall's light as the camera's space sees it (the wall's face
// for a cone travelling into it, else its mean light), opaque, on the isotropic face and on every
// directional face but the one of a cone leaving the wall: that cone's rays never pass behind it.
// The surface cells are read, never written, so the pass does not depend on the order of its
// invocations.
#include "clipmap/clipmap.glsl"
layout(local_size_x = 4, local_size_y = 4, local_size_z = 4) in;
layout(std430, binding = CLIPMAP_BINDING_FILL) readonly buffer Fill { uint fill[]; };
layout(CLIPMAP_ATLAS_FORMAT, binding = 0) uniform image3D u_atlas;
uniform int u_level;
uniform int u_faces;

void main() {
  ivec3 i = ivec3(gl_GlobalInvocationID);
  if (any(greaterThanEqual(i, ivec3(u_clipN)))) return;
  uint word = fill[(i.z * u_clipN + i.y) * u_clipN + i.x];
  if (word == 0u) return;
  ivec3 phys = toroidalAddress(u_clipOrigin[u_level] + i);
  if (word == 1u) {
    for (int f = 0; f < u_faces; ++f) imageStore(u_atlas, atlasTexel(f, u_level, phys), vec4(0.0));
    return;
  }
  uint source = (word - 2u) >> 3;
  int away = int((word - 2u) & 7u);  // the step out of the wall
  uint n = uint(u_clipN);
  ivec3 s = ivec3(source % n, (source / n) % n, source / (n * n));
  ivec3 sourcePhys = toroidalAddress(u_clipOrigin[u_level] + s);
  vec4 mean = imageLoad(u_atlas, atlasTexel(0, u_level, sourcePhys));  // premultiplied where filtered
  vec3 light = mean.a > 0.0 ? mean.rgb / mean.a : vec3(0.0);
  if (away < 6 && u_faces > 1) {
    vec4 seen = imageLoad(u_atlas, atlasTexel(1 + (away ^ 1), u_level, sourcePhys));
    if (seen.a > 0.0) light = seen.rgb / seen.a;
  }
  imageStore(u_atlas, atlasTexel(0, u_level, phys), vec4(light, 1.0));
  for (int f = 1; f < u_faces; ++f)
    imageStore(u_atlas, atlasTexel(f, u_level, phys), f - 1 == away ? vec4(0.0) : vec4(light, 1.0));
}
