#version 450
in AxisData { flat vec3 color; vec3 normal; } fin;
layout(location = 0) out vec4 outColor;
uniform vec3 u_viewDir;
void main() {
  // A little shading from the view direction so faces of one colour stay distinguishable.
  float shade = 0.55 + 0.45 * abs(dot(normalize(fin.normal), u_viewDir));
  outColor = vec4(fin.color * shade, 1.0);
}
