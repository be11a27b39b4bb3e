// Surface-aware upsampling of an image traced at 1/scale of the G-buffer's resolution (one trace
// per scale x scale block, whose top-left G-buffer pixel it shaded). For full-resolution pixel px
// (position p, normal n): the four nearest traced pixels, bilinear weights times a similarity
// that is 1 on the same surface and falls to 0 across depth and normal edges:
//   similarity = max(0, 1 - |n . (q - p)| / planeDistance) * max(0, n . n_q)^8
// (q, n_q: the traced pixel's G-buffer position and normal), so light does not bleed from one
// surface onto another. Where no neighbour is similar at all, the most similar one is taken.
// Used by the composite (common/composite.comp.glsl): the taps and their weights depend on the
// G-buffer only, so they are found once per pixel (upsampleTaps) and applied to every image traced
// at that scale (upsampleWith). 'position' and 'normal' are the caller's G-buffer samplers (w = 0
// on the background).
struct UpsampleTaps {
  ivec2 texel[4];  // the four nearest traced pixels
  vec4 weight;     // bilinear weight times similarity; 0 for a tap on the background
  bvec4 surface;   // the tap sees a surface
  float total;     // sum of the weights
  int best;        // the most similar tap that sees a surface; -1 where none does
};

// The taps of full-resolution pixel px (position p, normal n) into images traced at 1/scale of the
// G-buffer's resolution, of size tracedSize.
UpsampleTaps upsampleTaps(sampler2D position, sampler2D normal, ivec2 tracedSize, ivec2 px, vec3 p, vec3 n,
                          int scale, float planeDistance) {
  vec2 f = (vec2(px) + 0.5) / float(scale) - 0.5;
  ivec2 base = ivec2(floor(f));
  vec2 fr = f - vec2(base);
  UpsampleTaps taps;
  taps.weight = vec4(0.0);
  taps.surface = bvec4(false);
  taps.total = 0.0;
  taps.best = -1;
  float bestSimilarity = -1.0;
  for (int i = 0; i < 4; ++i) {
    ivec2 q = clamp(base + ivec2(i & 1, i >> 1), ivec2(0), tracedSize - 1);
    taps.texel[i] = q;
    ivec2 g = min(q * scale, textureSize(position, 0) - 1);
    vec4 qp = texelFetch(position, g, 0);
    if (qp.w == 0.0) continue;
    float similarity = max(0.0, 1.0 - abs(dot(n, qp.xyz - p)) / planeDistance) *
                       pow(max(dot(n, texelFetch(normal, g, 0).xyz), 0.0), 8.0);
    float wgt = ((i & 1) == 1 ? fr.x : 1.0 - fr.x) * ((i >> 1) == 1 ? fr.y : 1.0 - fr.y) * similarity;
    taps.weight[i] = wgt;
    taps.surface[i] = true;
    taps.total += wgt;
    if (similarity > bestSimilarity) { bestSimilarity = similarity; taps.best = i; }
  }
  return taps;
}

// A traced image at full-resolution pixel px: at scale 1 its own texel; else the taps' weighted
// average, or where their weights vanish the most similar tap (0 where none sees a surface).
vec4 upsampleWith(sampler2D traced, UpsampleTaps taps, int scale, ivec2 px) {
  if (scale == 1) return texelFetch(traced, px, 0);
  vec4 sum = vec4(0.0), best = vec4(0.0);
  for (int i = 0; i < 4; ++i) {
    vec4 v = texelFetch(traced, taps.texel[i], 0);
    if (taps.surface[i]) sum += taps.weight[i] * v;
    if (i == taps.best) best = v;
  }
  return taps.total > 1e-4 ? sum / taps.total : best;
}
