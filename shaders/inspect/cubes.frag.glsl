#version 450
// Flat cube faces shaded by axis (as the ray-marched view) with darkened edges, so single voxels
// stay distinguishable inside a wall of equal colour when they are large enough on screen.
in CubeData { flat vec3 color; flat int axis; vec3 local; } fin;
uniform float u_alpha = 1.0;      // below 1 in overlays over an image
uniform int u_edgesOnly = 0;      // 1: only the cube edges (the overlay's x-ray lattice)
layout(location = 0) out vec4 outColor;
void main() {
  const float shade[3] = float[3](0.72, 1.0, 0.86);
  vec3 l = fin.local;
  vec2 f = fin.axis == 0 ? l.yz : fin.axis == 1 ? l.xz : l.xy;
  float edge = min(min(f.x, 1.0 - f.x), min(f.y, 1.0 - f.y));
  // Edges only where a cube is several pixels wide (fwidth: local units per pixel); at a few pixels
  // per cube the lines would alias into moire.
  float w = max(fwidth(f.x), fwidth(f.y));
  if (u_edgesOnly != 0) {
    // About one pixel wide whatever the distance; the voxel's own colour, brightened to read on
    // dark surfaces.
    if (edge > 0.6 * w) discard;
    outColor = vec4(mix(fin.color, vec3(1.0), 0.35), 1.0);
    return;
  }
  float k = (w < 0.2 && edge < max(0.06, w)) ? 0.6 : 1.0;
  outColor = vec4(fin.color * shade[fin.axis] * k, k < 1.0 ? max(u_alpha, 0.85) : u_alpha);
}
