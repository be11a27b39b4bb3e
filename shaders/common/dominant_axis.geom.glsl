#version 450
// Colours each triangle by the axis voxelization projects it along (x red, y green, z blue), as
// seen from the camera. Uses the same positional plane normal as voxelize.geom.glsl.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in VertexData { vec3 worldPos; vec3 normal; vec2 uv; } vin[];
out AxisData { flat vec3 color; vec3 normal; } vout;

void main() {
  vec3 n = cross(vin[1].worldPos - vin[0].worldPos, vin[2].worldPos - vin[0].worldPos);
  vec3 an = abs(n);
  int axis = (an.x >= an.y && an.x >= an.z) ? 0 : (an.y >= an.z ? 1 : 2);
  vec3 color = axis == 0 ? vec3(0.9, 0.2, 0.15) : (axis == 1 ? vec3(0.2, 0.8, 0.25) : vec3(0.2, 0.35, 0.95));
  for (int i = 0; i < 3; ++i) {
    gl_Position = gl_in[i].gl_Position;
    vout.color = color;
    vout.normal = normalize(n);
    EmitVertex();
  }
  EndPrimitive();
}
