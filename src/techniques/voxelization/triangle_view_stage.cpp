// The triangle-view stage of the voxelization technique: one chosen triangle seen along its
// dominant axis, at the voxel resolution, showing what conservative rasterization adds.
//
// Drawn on the CPU from the same rules the raster pass uses (shaders/common/voxelize.geom.glsl):
// the projection plane of the dominant axis, the triangle grown by moving each edge out by half the
// pixel's extent along its normal (Hasselgren et al. 2005), and the bounding box grown by half a
// pixel that the fragment shader discards against. Pixels (voxel columns) are coloured:
//   blue    covered by plain rasterization (the pixel centre lies inside the triangle);
//   orange  covered only conservatively (the pixel square overlaps the triangle);
//   dark    not covered.
// Lines: the triangle (white), the grown triangle (yellow), the grown bounding box (magenta).
#include <algorithm>
#include <cmath>
#include <vector>

#include "gpu/resources.h"
#include "techniques/common/voxel_space.h"
#include "graph/scene_inputs.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/voxelization/stages.h"

namespace voxlab::vox {

namespace {

struct Canvas {
  int width, height, cell;  // image size; screen pixels per voxel pixel
  glm::vec2 origin;         // voxel-plane coordinates of the image's lower-left corner
  std::vector<glm::vec4> rgba;
  glm::vec2 toImage(glm::vec2 p) const { return (p - origin) * float(cell); }
  void put(int x, int y, glm::vec4 c) {
    if (x >= 0 && y >= 0 && x < width && y < height) rgba[size_t(y) * width + x] = c;
  }
  // A 2-pixel wide line between two voxel-plane points.
  void line(glm::vec2 a, glm::vec2 b, glm::vec4 c) {
    glm::vec2 p = toImage(a), q = toImage(b);
    int steps = int(std::ceil(std::max(std::abs(q.x - p.x), std::abs(q.y - p.y)))) + 1;
    for (int i = 0; i <= steps; ++i) {
      glm::vec2 s = p + (q - p) * (float(i) / float(steps));
      for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) put(int(s.x) + dx, int(s.y) + dy, c);
    }
  }
};

// Edge function of the directed edge a->b at p; >= 0 on the left (inside a counter-clockwise triangle).
float edge(glm::vec2 a, glm::vec2 b, glm::vec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

// Does the unit square with lower-left corner c overlap the counter-clockwise triangle t?
bool squareOverlaps(const glm::vec2 t[3], glm::vec2 c) {
  glm::vec2 lo = glm::min(t[0], glm::min(t[1], t[2])), hi = glm::max(t[0], glm::max(t[1], t[2]));
  if (hi.x < c.x || hi.y < c.y || lo.x > c.x + 1 || lo.y > c.y + 1) return false;
  for (int i = 0; i < 3; ++i) {
    glm::vec2 a = t[i], b = t[(i + 1) % 3];
    // The square corner furthest along the edge's inward normal must not be outside.
    glm::vec2 n(-(b.y - a.y), b.x - a.x);
    glm::vec2 corner(c.x + (n.x > 0 ? 1.0f : 0.0f), c.y + (n.y > 0 ? 1.0f : 0.0f));
    if (edge(a, b, corner) < 0) return false;
  }
  return true;
}

}  // namespace

void TriangleViewStage::declare(StageBuilder& b) const {
  b.read(kSceneGeometryInput);  // draws the scene's triangles in voxel space
  b.param(voxelResolutionParam());
  b.param(ParamDesc::integer("inspect.triangle", 0, 0, 16777215,
                             "index of the triangle shown by triangle-view (clamped to the scene's triangles)"));
  b.output("triangle-view", OutputKind::Image2D, Semantic::Color,
           "one triangle along its dominant axis: plain (blue) and conservative-only (orange) pixels, the grown "
           "triangle (yellow) and grown bounding box (magenta)");
}

void TriangleViewStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  const size_t count = ctx.scene.triangleCount();
  const size_t t = std::min<size_t>(size_t(ctx.params.getInt("inspect.triangle")), count - 1);
  glm::vec3 v[3];
  for (int k = 0; k < 3; ++k) v[k] = space.toVoxel(ctx.scene.positions[ctx.scene.indices[3 * t + k]]);
  glm::vec3 n = glm::cross(v[1] - v[0], v[2] - v[0]), an = glm::abs(n);
  int axis = (an.x >= an.y && an.x >= an.z) ? 0 : (an.y >= an.z ? 1 : 2);
  // The same swizzle as the geometry shader: the dominant axis becomes depth.
  glm::vec2 p[3];
  for (int k = 0; k < 3; ++k)
    p[k] = axis == 0 ? glm::vec2(v[k].y, v[k].z) : axis == 1 ? glm::vec2(v[k].z, v[k].x) : glm::vec2(v[k].x, v[k].y);
  if (edge(p[0], p[1], p[2]) < 0) std::swap(p[1], p[2]);

  // Grown triangle: each edge line moved out by half the pixel's extent along its normal.
  glm::vec3 lines[3];
  for (int i = 0; i < 3; ++i) {
    glm::vec3 l = glm::cross(glm::vec3(p[i], 1.0f), glm::vec3(p[(i + 1) % 3], 1.0f));
    l.z += 0.5f * (std::abs(l.x) + std::abs(l.y));
    lines[i] = l;
  }
  glm::vec2 grown[3];
  for (int i = 0; i < 3; ++i) {
    glm::vec3 q = glm::cross(lines[(i + 2) % 3], lines[i]);
    grown[i] = std::abs(q.z) > 1e-12f ? glm::vec2(q) / q.z : p[i];
  }
  glm::vec2 lo = glm::min(p[0], glm::min(p[1], p[2])), hi = glm::max(p[0], glm::max(p[1], p[2]));
  glm::vec2 boxLo = lo - 0.5f, boxHi = hi + 0.5f;

  // The region shown: the grown box plus one pixel, at most 96 pixels across (centred on the triangle).
  glm::ivec2 a = glm::ivec2(glm::floor(boxLo)) - 1, b = glm::ivec2(glm::ceil(boxHi)) + 1;
  glm::ivec2 extent = glm::min(b - a, glm::ivec2(96));
  glm::ivec2 centre = (a + b) / 2;
  a = glm::max(a, centre - extent / 2);
  Canvas canvas;
  canvas.cell = std::clamp(512 / std::max(extent.x, extent.y), 4, 32);
  canvas.width = extent.x * canvas.cell;
  canvas.height = extent.y * canvas.cell;
  canvas.origin = glm::vec2(a);
  canvas.rgba.assign(size_t(canvas.width) * canvas.height, glm::vec4(0.02f, 0.02f, 0.025f, 1.0f));
  int plain = 0, conservative = 0;
  for (int y = 0; y < extent.y; ++y)
    for (int x = 0; x < extent.x; ++x) {
      glm::vec2 c = glm::vec2(a) + glm::vec2(x, y);
      glm::vec2 centreP = c + 0.5f;
      bool inPlain = edge(p[0], p[1], centreP) >= 0 && edge(p[1], p[2], centreP) >= 0 && edge(p[2], p[0], centreP) >= 0;
      bool inCons = squareOverlaps(p, c);
      plain += inPlain;
      conservative += inCons;
      glm::vec4 colour = inPlain ? glm::vec4(0.05f, 0.25f, 0.85f, 1) : inCons ? glm::vec4(0.85f, 0.3f, 0.03f, 1)
                                                                             : glm::vec4(0.01f, 0.01f, 0.012f, 1);
      for (int sy = 1; sy < canvas.cell; ++sy)  // leave a one-pixel grid line
        for (int sx = 1; sx < canvas.cell; ++sx) canvas.put(x * canvas.cell + sx, y * canvas.cell + sy, colour);
    }
  const glm::vec4 white(1, 1, 1, 1), yellow(1, 0.85f, 0.05f, 1), magenta(0.9f, 0.1f, 0.8f, 1);
  glm::vec2 box[4] = {boxLo, {boxHi.x, boxLo.y}, boxHi, {boxLo.x, boxHi.y}};
  for (int i = 0; i < 4; ++i) canvas.line(box[i], box[(i + 1) % 4], magenta);
  for (int i = 0; i < 3; ++i) canvas.line(grown[i], grown[(i + 1) % 3], yellow);
  for (int i = 0; i < 3; ++i) canvas.line(p[i], p[(i + 1) % 3], white);

  TextureDesc d;
  d.format = GL_RGBA8;
  d.size = {canvas.width, canvas.height, 1};
  d.minFilter = d.magFilter = GL_NEAREST;
  Texture& tex = ctx.board.ensureTexture("triangle-view", d);
  glTextureSubImage2D(tex.id(), 0, 0, 0, canvas.width, canvas.height, GL_RGBA, GL_FLOAT, canvas.rgba.data());
  ctx.stats["triangle"] = double(t);
  ctx.stats["axis"] = axis;
  ctx.stats["area_voxels2"] = 0.5 * double(edge(p[0], p[1], p[2]));
  ctx.stats["pixels_plain"] = plain;
  ctx.stats["pixels_conservative"] = conservative;
}

}  // namespace voxlab::vox
