// Instances of the viewer's 3D views (cubes, points, spheres): one record each, 32 bytes.
struct ViewInstance {
  vec4 positionSize;  // xyz: minimum corner (cubes) or centre (points, spheres); w: edge or radius
  vec4 color;         // rgb (display-encoded), a: opacity (cubes: mask of the faces to draw)
};
layout(std430, binding = 0) readonly buffer ViewInstances { ViewInstance u_instances[]; };
