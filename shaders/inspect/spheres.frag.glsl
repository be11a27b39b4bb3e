#version 450
// A translucent shaded disc with an opaque rim: overlapping cone samples stay readable.
in SphereData { vec2 uv; flat vec4 color; } fin;
layout(location = 0) out vec4 outColor;
void main() {
  float r2 = dot(fin.uv, fin.uv);
  if (r2 > 1.0) discard;
  float nz = sqrt(1.0 - r2);
  float r = sqrt(r2);
  if (r > 1.0 - 1.6 * fwidth(r)) {  // a rim about 1.5 pixels wide at any disc size
    outColor = vec4(fin.color.rgb, 0.95);
  } else {
    outColor = vec4(fin.color.rgb * (0.45 + 0.55 * nz), fin.color.a);
  }
}
