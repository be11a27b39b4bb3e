// Distance from the camera to the visible surface of G-buffer pixel g, or -1 where no surface
// was drawn (the bilateral weights treat "no surface" as its own side of every edge).
float surfaceDistance(sampler2D positions, ivec2 g, vec3 cameraPos) {
  vec4 p = texelFetch(positions, g, 0);
  return p.w != 0.0 ? length(p.xyz - cameraPos) : -1.0;
}

// Bilateral weight of a sample at distance dq for a pixel at distance dp: a Gaussian in the
// relative distance difference (sigma u_depthSigma, e.g. 0.02 = 2 %), 1 between two pixels without
// a surface, 0 between a surface and no surface.
float depthWeight(float dp, float dq, float sigma) {
  if (dp < 0.0 || dq < 0.0) return (dp < 0.0 && dq < 0.0) ? 1.0 : 0.0;
  float r = (dq - dp) / (sigma * dp);
  return exp(-r * r);
}
