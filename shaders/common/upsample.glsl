// Surface-aware upsampling of an image traced at 1/scale of the G-buffer's resolution (one trace
// per scale x scale block, whose top-left G-buffer pixel it shaded). For full-resolution pixel px
// (position p, normal n): the four nearest traced pixels, bilinear weights times a similarity
// that is 1 on the same surface and falls to 0 across depth and normal edges:
//   similarity = max(0, 1 - |n . (q - p)| / planeDistance) * max(0, n . n_q)^8
// (q, n_q: the traced pixel's G-buffer position and normal), so light does not bleed from one
// surface onto another. Where no neighbour is similar at all, the most similar one is taken.
// Used by the composite (common/composite.comp.glsl); 'traced', 'position' and 'normal' are the
// caller's samplers (the traced image, the G-buffer position with w = 0 on the background,
// and normal).
vec4 upsampleAlongSurface(sampler2D traced, sampler2D position, sampler2D normal, ivec2 px, vec3 p, vec3 n,
                          int scale, float planeDistance) {
  if (scale == 1) return texelFetch(traced, px, 0);
  ivec2 lowSize = textureSize(traced, 0);
  vec2 f = (vec2(px) + 0.5) / float(scale) - 0.5;
  ivec2 base = ivec2(floor(f));
  vec2 fr = f - vec2(base);
  vec4 sum = vec4(0.0), best = vec4(0.0);
  float total = 0.0, bestSimilarity = -1.0;
  for (int i = 0; i < 4; ++i) {
    ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), lowSize - 1);
    ivec2 g = min(q * scale, textureSize(position, 0) - 1);
    vec4 qp = texelFetch(position, g, 0);
    if (qp.w == 0.0) continue;
    float similarity = max(0.0, 1.0 - abs(dot(n, qp.xyz - p)) / planeDistance) *
                       pow(max(dot(n, texelFetch(normal, g, 0).xyz), 0.0), 8.0);
    float wgt = ((i & 1) == 1 ? fr.x : 1.0 - fr.x) * ((i >> 1) == 1 ? fr.y : 1.0 - fr.y) * similarity;
    vec4 v = texelFetch(traced, q, 0);
    sum += wgt * v;
    total += wgt;
    if (similarity > bestSimilarity) { bestSimilarity = similarity; best = v; }
  }
  return total > 1e-4 ? sum / total : best;
}
