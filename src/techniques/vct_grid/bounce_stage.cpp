// More than one indirect bounce: the bounce stage (vct-grid/bounce, one iteration per bounce).
//
// The mip stage's grid holds the direct light the voxels reflect (and their emission): cones that
// gather it give one indirect bounce. For bounce k+1 (bounces >= 2), every voxel fragment gathers
// the bounce-k grid with bounce.cone-count diffuse cones around its own normal (the same layout as
// the cone-trace stage's ring, cosine weights summing to 1) and reflects it with its albedo,
// albedo * sum_i w_i L_i, exactly what cone-trace computes for a pixel. The fragments of a voxel are
// averaged with exact fixed-point sums and a count (as inject.average=exact-sum does: order
// independent), added to the injected radiance (radiance-opaque) and mipmapped with the mip stage's
// own code (buildMipLevel): that is the bounce-(k+1) grid. In a closed white furnace (every voxel
// injecting L, albedo rho) grid k then holds L (1 + rho + ... + rho^(k-1)), the geometric series
// of the path tracer's reflection counts (tests/unit/test_vct_bounces.cpp).
//
// Per fragment, not per voxel: a voxel holding both faces of a thin wall, or a corner, has
// fragments with different normals, and each gathers around its own (an averaged normal would
// cancel on a wall's two faces). The voxels store what every other grid stores (voxel.format): with
// RGBA8 a sum above 1 is clamped, with RGBA16F above 64, so no bounce can run away.
//
// The cones start bounce.start-offset voxels from the voxel centre along the fragment's normal and
// take their first sample one voxel further (the cone-trace stage's 1.75 and 1: at level 0 that
// sample's trilinear footprint reaches voxels 2 and 3 away, never the voxel's own surface), take steps of half the sample diameter, read level log2(diameter / voxel) - 1 and reach up to 1.75
// volume edges (the cone-trace stage's defaults); they see the sky where they leave the volume.
#include <algorithm>
#include <vector>

#include "common/shared.h"
#include "gpu/shader_library.h"
#include "techniques/common/cone_layout.h"
#include "techniques/common/sky.h"
#include "techniques/common/voxel_space.h"
#include "techniques/common/voxelize_stage.h"
#include "techniques/vct_grid/stages.h"

namespace voxlab::vct {

static constexpr float kDegrees = 3.14159265358979f / 180.0f;
static constexpr float kStepScale = 0.5f;    // step = half the sample diameter (cone.step's default)
static constexpr float kLodBias = -1.0f;     // filter support = diameter (cone.lod-bias's default)
static constexpr float kMaxDistance = 1.75f;  // volume edges (cone.max-distance's default)

ParamDesc bouncesParam() {
  return ParamDesc::integer("bounces", 1, 1, kMaxBounces,
                            "indirect bounces the cones gather: 1 = the direct-lit voxels; each more one adds a "
                            "voxel-to-voxel diffuse gather (stage bounce, one iteration per bounce)",
                            "bounces");
}

std::string bounceGridName(int bounce) { return bounce <= 1 ? "radiance" : "radiance-bounce" + std::to_string(bounce); }

std::string bounceDirectionalName(int bounce, int direction) {
  const std::string suffix = std::string(kDirectionalVolumes[direction]).substr(std::string("radiance").size());
  return bounceGridName(bounce) + suffix;
}

void declareGatheredGridReads(StageBuilder& b) {
  b.param(bouncesParam());
  b.read(kSolidOpacity);
  for (int k = 1; k <= kMaxBounces; ++k) {
    b.read(bounceGridName(k));
    for (int d = 0; d < 6; ++d) b.read(bounceDirectionalName(k, d));
  }
}

TextureDesc packedDirectionalDesc(int edge, GLenum format) {
  TextureDesc d = radianceGridDesc(edge, 0, format);
  d.size.z = 2 * edge;
  d.levels = 1;
  while ((edge >> d.levels) > 0) ++d.levels;  // the directional volumes' levels, not one more
  // Read one level at a time (directionalLevel, integer lods): a linear mip filter would blend in a
  // second level with weight 0 at the cost of a second trilinear lookup.
  d.minFilter = d.levels == 1 ? GL_LINEAR : GL_LINEAR_MIPMAP_NEAREST;
  return d;
}

static TextureDesc packedDirectionalDesc(const ParamSet& p) { return packedDirectionalDesc(directionalSize(p), gridFormat(p)); }

void declarePackedDirectional(StageBuilder& b) {
  for (const char* axis : {"x", "y", "z"})
    b.texture(kPackedDirectionalPrefix + std::string(axis),
              [](const ParamSet& p, const ViewState&) { return packedDirectionalDesc(p); });
}

void packDirectionalPair(const Texture& positive, const Texture& negative, Texture& packed) {
  for (int side = 0; side < 2; ++side) {
    const Texture& volume = side == 0 ? positive : negative;
    for (int level = 0; level < packed.levels() && level < volume.levels(); ++level) {
      const glm::ivec3 n = volume.levelSize(level);
      glCopyImageSubData(volume.id(), GL_TEXTURE_3D, level, 0, 0, 0, packed.id(), GL_TEXTURE_3D, level, 0, 0,
                         side * n.z, n.x, n.y, n.z);
    }
  }
}

void bindRadianceGrid(StageContext& ctx, int bounce) {
  glBindTextureUnit(0, ctx.board.texture(bounceGridName(bounce)).id());
  // Why packed: a sample reads, per axis, the volume of the sign of the cone's direction, which
  // differs between the pixels of a SIMD row; llvmpipe then fetches from both volumes for every
  // lane. From one texture the sign is an offset in z and one lookup per level serves every lane
  // (common/cone_trace.glsl, directionalLookup). The copies are exact (glCopyImageSubData).
  const TextureDesc desc = packedDirectionalDesc(ctx.params);
  const char* const axes[3] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a) {
    Texture& packed = ctx.board.ensureTexture(kPackedDirectionalPrefix + std::string(axes[a]), desc);
    packDirectionalPair(ctx.board.texture(bounceDirectionalName(bounce, 2 * a)),
                        ctx.board.texture(bounceDirectionalName(bounce, 2 * a + 1)), packed);
    glBindTextureUnit(8 + a, packed.id());
  }
  glBindTextureUnit(11, ctx.board.texture(kSolidOpacity).id());
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

// --- The stage -----------------------------------------------------------------------------------

static const char* const kBounceSums[4] = {"bounce-sum-r", "bounce-sum-g", "bounce-sum-b", "bounce-fragment-count"};

static int bounces(const ParamSet& p) { return p.getInt("bounces"); }
static bool anisotropic(const ParamSet& p) { return p.getChoice("mipmap.mode") == "anisotropic"; }

std::string coneVolumeDefines(const ParamSet& p) {
  return std::string("#define CONE_ANISOTROPIC ") + (anisotropic(p) ? "1" : "0") + "\n#define CONE_CLASSIC_DIRECTIONAL " +
         (p.getBool("mipmap.fronts") ? "0" : "1") + "\n";
}

// A bounce's grid is real when that bounce is gathered, else one empty texel.
static TextureDesc bounceGridDesc(const ParamSet& p, int bounce) {
  return radianceGridDesc(bounce <= bounces(p) ? p.getInt("voxel.resolution") : 1, 0, gridFormat(p));
}
static TextureDesc bounceDirectionalDesc(const ParamSet& p, int bounce) {
  const bool real = bounce <= bounces(p) && anisotropic(p);
  return radianceGridDesc(real ? std::max(p.getInt("voxel.resolution") / 2, 1) : 1, 0, gridFormat(p));
}
static TextureDesc bounceSumsDesc(const ParamSet& p) {
  TextureDesc d;
  d.target = GL_TEXTURE_3D;
  d.format = GL_R32UI;
  d.size = glm::ivec3(bounces(p) >= 2 ? p.getInt("voxel.resolution") : 1);
  d.minFilter = d.magFilter = GL_NEAREST;
  return d;
}

void BounceStage::declare(StageBuilder& b) const {
  b.param(voxelResolutionParam());
  b.param(mipmapModeParam());
  b.param(mipmapFrontsParam());
  b.param(voxelFormatParam());
  b.param(bouncesParam());
  b.param(ParamDesc::integer("bounce.cone-count", 6, 1, VOXLAB_MAX_CONES,
                             "diffuse cones each voxel fragment gathers the previous bounce with (ring layout, "
                             "cosine weights)",
                             "cones"));
  b.param(ParamDesc::real("bounce.cone-aperture", 45.0, 5.0, 120.0, "full opening angle of each bounce cone",
                          "degrees"));
  b.param(ParamDesc::real("bounce.start-offset", 1.75, 0.0, 8.0,
                          "bounce cones start this far from the voxel centre along the fragment's normal", "voxels"));
  declareSky(b);
  b.read("fragments");
  b.read("fragments.count");
  b.read("radiance-opaque");
  b.read(kVoxelFacing);
  b.read(kSolidOpacity);
  b.read("radiance");
  for (const char* name : kDirectionalVolumes) b.read(name);
  for (const char* name : kBounceSums) {
    b.write(name);
    b.texture(name, [](const ParamSet& p, const ViewState&) { return bounceSumsDesc(p); });
  }
  b.write("bounce.counts");
  b.buffer("bounce.counts", [](const ParamSet&, const ViewState&) { return size_t(8); });
  declarePackedDirectional(b);
  for (int k = 2; k <= kMaxBounces; ++k) {
    b.output(bounceGridName(k), OutputKind::Volume3D, Semantic::Color,
             "radiance after " + std::to_string(k) + " bounces: the injected radiance plus albedo x the cones' "
             "gather of bounce " + std::to_string(k - 1) + ", mipmapped (one empty texel unless bounces >= " +
             std::to_string(k) + ")")
        .placeholderUnless = "bounces>=" + std::to_string(k);
    b.texture(bounceGridName(k), [k](const ParamSet& p, const ViewState&) { return bounceGridDesc(p, k); });
    for (int d = 0; d < 6; ++d) {
      b.write(bounceDirectionalName(k, d));
      b.texture(bounceDirectionalName(k, d),
                [k](const ParamSet& p, const ViewState&) { return bounceDirectionalDesc(p, k); });
    }
  }
}

int BounceStage::iterations(const ParamSet& params) const { return std::max(bounces(params) - 1, 1); }

void BounceStage::execute(StageContext& ctx) {
  const int res = ctx.params.getInt("voxel.resolution");
  const int n = bounces(ctx.params);
  Texture* grids[kMaxBounces + 1] = {};
  Texture* dirs[kMaxBounces + 1][6] = {};
  for (int k = 2; k <= kMaxBounces; ++k) {
    grids[k] = &ctx.board.ensureTexture(bounceGridName(k), bounceGridDesc(ctx.params, k));
    for (int d = 0; d < 6; ++d)
      dirs[k][d] = &ctx.board.ensureTexture(bounceDirectionalName(k, d), bounceDirectionalDesc(ctx.params, k));
  }
  Texture* sums[4];
  for (int c = 0; c < 4; ++c) sums[c] = &ctx.board.ensureTexture(kBounceSums[c], bounceSumsDesc(ctx.params));
  Buffer& counts = ctx.board.ensureBuffer("bounce.counts", 8);
  const uint8_t zero[4] = {0, 0, 0, 0};
  if (ctx.iteration == 0) {
    // Start empty, so a stepped run shows exactly the bounces gathered so far.
    for (int k = 2; k <= kMaxBounces; ++k) {
      for (int level = 0; level < grids[k]->levels(); ++level)
        glClearTexImage(grids[k]->id(), level, GL_RGBA, GL_UNSIGNED_BYTE, zero);
      for (Texture* t : dirs[k])
        for (int level = 0; level < t->levels(); ++level) glClearTexImage(t->id(), level, GL_RGBA, GL_UNSIGNED_BYTE, zero);
    }
    const uint32_t none[2] = {0, 0};
    counts.upload(none, sizeof(none));
  }
  ctx.stats["bounces"] = n;
  if (n < 2) return;  // one bounce: the cones read the mip stage's grid

  const int bounce = ctx.iteration + 2;  // the grid this iteration makes, from grid bounce - 1
  VoxelSpace space = VoxelSpace::fromScene(ctx.scene, res);
  const uint32_t count = voxelFragmentCount(ctx.board);
  const uint32_t none = 0;
  for (Texture* t : sums) glClearTexImage(t->id(), 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);

  // Gather: per fragment, albedo x the cones' radiance, added into its voxel's fixed-point sums.
  const float aperture = ctx.params.getFloat("bounce.cone-aperture") * kDegrees;
  auto cones = diffuseCones(ctx.params.getInt("bounce.cone-count"), aperture, "ring", "cosine");
  std::vector<glm::vec4> packed;
  for (const auto& c : cones) packed.push_back(glm::vec4(c.direction, c.weight));
  GLuint gather = ctx.shaders.program({"vct_grid/bounce_gather.comp.glsl"}, coneVolumeDefines(ctx.params));
  space.setUniforms(gather);
  glProgramUniform4fv(gather, glGetUniformLocation(gather, "u_cones"), GLsizei(packed.size()), &packed[0].x);
  setUniform(gather, "u_coneCount", int(cones.size()));
  setUniform(gather, "u_aperture", aperture);
  setUniform(gather, "u_startOffset", ctx.params.getFloat("bounce.start-offset") * space.voxelSize);
  setUniform(gather, "u_maxDistance", kMaxDistance * space.edge());
  setUniform(gather, "u_stepScale", kStepScale);
  setUniform(gather, "u_lodBias", kLodBias);
  setUniform(gather, "u_maxSteps", 512);
  setUniform(gather, "u_fragmentCount", unsigned(count));
  setUniform(gather, "u_maxRadiance", gridMaxRadiance(ctx.params));
  setSkyUniforms(gather, ctx.params, ctx.scene);
  glUseProgram(gather);
  bindRadianceGrid(ctx, bounce - 1);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_FRAGMENTS, ctx.board.buffer("fragments").id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, VOXLAB_BINDING_CONE_TRACE_COUNTS, counts.id());
  for (int c = 0; c < 4; ++c) glBindImageTexture(1 + c, sums[c]->id(), 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);
  dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);

  // Resolve: level 0 of this bounce's grid = injected radiance + the voxel's mean gathered light.
  GLuint resolve = ctx.shaders.program({"vct_grid/bounce_resolve.comp.glsl"}, gridFormatDefines(ctx.params));
  setUniform(resolve, "u_fragmentCount", unsigned(count));
  setUniform(resolve, "u_maxRadiance", gridMaxRadiance(ctx.params));
  glUseProgram(resolve);
  glBindTextureUnit(0, ctx.board.texture("radiance-opaque").id());
  for (int c = 0; c < 4; ++c) glBindImageTexture(1 + c, sums[c]->id(), 0, GL_TRUE, 0, GL_READ_ONLY, GL_R32UI);
  glBindImageTexture(0, grids[bounce]->id(), 0, GL_TRUE, 0, GL_WRITE_ONLY, grids[bounce]->desc().format);
  dispatchCompute({int(count), 1, 1}, {64, 1, 1});
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  glBindImageTexture(0, 0, 0, GL_TRUE, 0, GL_WRITE_ONLY, grids[bounce]->desc().format);
  for (int c = 0; c < 4; ++c) glBindImageTexture(1 + c, 0, 0, GL_TRUE, 0, GL_READ_WRITE, GL_R32UI);

  // Re-mip with the mip stage's code: level 0 is already in place.
  for (int k = 0; k < std::max(grids[bounce]->levels() - 1, 1); ++k) buildMipLevel(ctx, *grids[bounce], *grids[bounce], dirs[bounce], k, false);

  uint32_t totals[2] = {0, 0};
  glGetNamedBufferSubData(counts.id(), 0, sizeof(totals), totals);
  ctx.stats["bounces_gathered"] = bounce - 1;
  ctx.stats["fragments_gathering"] = count;
  ctx.stats["bounce_cones"] = double(cones.size());
  ctx.stats["samples"] = totals[0];  // over the bounces gathered so far
  ctx.stats["volume_fetches"] = totals[1];
  ctx.stats["samples_per_cone"] = totals[0] / std::max(1.0, double(count) * cones.size() * (bounce - 1));
  ctx.stats["fetches_per_sample"] = totals[1] / std::max(1.0, double(totals[0]));
}

}  // namespace voxlab::vct
