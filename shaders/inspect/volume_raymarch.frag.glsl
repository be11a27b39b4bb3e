#version 450
// The viewer's 3D view of one volume level: each pixel's ray walks the level's texels in order
// (3D DDA, so every texel it crosses is visited once and nearest texels stay crisp) and composites
// front to back: C += (1 - A) a rgb, A += (1 - A) a, with the texel's opacity corrected to the
// length of the ray inside it (a = 1 - (1 - alpha)^length, length in texels). Faces the ray
// enters through are shaded by axis so that opaque surfaces read as 3D. Writes the depth where A
// first reaches 0.5 so lines drawn afterwards are hidden behind opaque voxels.
in vec2 v_ndc;
layout(location = 0) out vec4 outColor;
uniform sampler3D u_volume;     // RGBA8: display rgb, opacity
uniform ivec3 u_volumeSize;     // texels of the level
uniform vec3 u_boxMax;          // the volume spans [0, u_boxMax] in view units (level-0 voxels)
uniform mat4 u_invViewProj;
uniform mat4 u_viewProj;
uniform vec3 u_eye;
uniform float u_opacityScale;   // < 1 shows the volume as translucent context
uniform vec3 u_background;

void main() {
  vec4 nearP = u_invViewProj * vec4(v_ndc, -1.0, 1.0);
  vec4 farP = u_invViewProj * vec4(v_ndc, 1.0, 1.0);
  vec3 dirView = normalize(farP.xyz / farP.w - nearP.xyz / nearP.w);
  // Texel space of the level: p_tex = p_view * scale.
  vec3 scale = vec3(u_volumeSize) / u_boxMax;
  vec3 o = u_eye * scale, d = dirView * scale;
  vec3 size = vec3(u_volumeSize);
  vec3 invD = 1.0 / max(abs(d), vec3(1e-8)) * sign(d + vec3(1e-12));
  vec3 t0 = (vec3(0.0) - o) * invD, t1 = (size - o) * invD;
  vec3 tmin = min(t0, t1), tmax = max(t0, t1);
  float tEnter = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
  float tLeave = min(min(tmax.x, tmax.y), tmax.z);
  gl_FragDepth = 1.0;
  if (tEnter >= tLeave) {
    outColor = vec4(u_background, 1.0);
    return;
  }
  int axis = tmin.x >= tmin.y && tmin.x >= tmin.z ? 0 : (tmin.y >= tmin.z ? 1 : 2);
  float t = tEnter;
  vec3 p = o + d * (t + 1e-4);
  ivec3 cell = clamp(ivec3(floor(p)), ivec3(0), u_volumeSize - 1);
  ivec3 stepDir = ivec3(sign(d));
  vec3 tNext = (vec3(cell) + step(vec3(0.0), d) - o) * invD;
  vec3 tDelta = abs(invD);
  float dLen = length(d);  // texels per view unit along the ray
  const float shade[3] = float[3](0.72, 1.0, 0.86);
  vec3 C = vec3(0.0);
  float A = 0.0, depthT = -1.0;
  int maxSteps = u_volumeSize.x + u_volumeSize.y + u_volumeSize.z + 3;
  for (int i = 0; i < maxSteps; ++i) {
    float tExit = min(min(tNext.x, tNext.y), tNext.z);
    vec4 s = texelFetch(u_volume, cell, 0);
    if (s.a > 0.0) {
      float alpha = clamp(s.a * u_opacityScale, 0.0, 1.0);
      float len = max(tExit - t, 0.0) * dLen;
      float a = alpha >= 0.999 ? 1.0 : 1.0 - pow(1.0 - alpha, len);
      C += (1.0 - A) * a * s.rgb * shade[axis];
      if (A < 0.5 && A + (1.0 - A) * a >= 0.5) depthT = t;
      A += (1.0 - A) * a;
      if (A > 0.995) break;
    }
    t = tExit;
    if (tNext.x <= tNext.y && tNext.x <= tNext.z) {
      cell.x += stepDir.x; tNext.x += tDelta.x; axis = 0;
    } else if (tNext.y <= tNext.z) {
      cell.y += stepDir.y; tNext.y += tDelta.y; axis = 1;
    } else {
      cell.z += stepDir.z; tNext.z += tDelta.z; axis = 2;
    }
    if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, u_volumeSize)) || t >= tLeave) break;
  }
  if (depthT >= 0.0) {
    vec4 clip = u_viewProj * vec4(u_eye + dirView * depthT, 1.0);
    gl_FragDepth = clamp(clip.z / clip.w * 0.5 + 0.5, 0.0, 1.0);
  }
  outColor = vec4(C + (1.0 - A) * u_background, 1.0);
}
