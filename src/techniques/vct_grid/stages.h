// The stages of vct-grid after voxelization and the shadow map (see vct_grid.cpp for the overview).
#pragma once
#include <string>

#include "graph/stage.h"
#include "techniques/common/composite_stage.h"

namespace voxlab::vct {

// Names of the six anisotropic volumes (+x -x +y -y +z -z) and the parameter that enables them.
extern const char* const kDirectionalVolumes[6];
ParamDesc mipmapModeParam();
ParamDesc mipmapFrontsParam();  // mipmap.fronts: the directional volumes show fronts only (default)

// A radiance volume of res^3 voxels (levels 0: the whole mip chain), RGBA8 unless 'format'.
TextureDesc radianceGridDesc(int res, int levels, GLenum format = GL_RGBA8);

// What the radiance grids store (voxel.format): RGBA8, radiance clamped to [0,1] (the default), or
// RGBA16F, radiance up to kHdrMaxRadiance (HDR voxels: a bright spot's footprint, the sun, a bounce
// added to an emitter). The grid shaders take the image format from VOXLAB_GRID_FORMAT.
ParamDesc voxelFormatParam();
inline constexpr float kHdrMaxRadiance = 64.0f;  // W/(m^2 sr); keeps the exact sums' uint32 safe
GLenum gridFormat(const ParamSet& p);             // GL_RGBA8 or GL_RGBA16F
std::string gridFormatDefines(const ParamSet& p); // "" or "#define VOXLAB_GRID_FORMAT rgba16f\n"
float gridMaxRadiance(const ParamSet& p);         // 1 or kHdrMaxRadiance

// Iteration k of the mip pyramid (MipmapStage; the bounce stage re-mips each bounce's grid with
// it): k = 0 copies 'src' into level 0 of 'grid' (unless they are the same texture) and clears the
// coarser levels and the six directional volumes; then level k+1 of 'grid' is built from level k,
// and with mipmap.mode=anisotropic level k of 'dirs' (built from level 0 of 'src' when k = 0,
// each leaf seen per direction as its facing code in kVoxelFacing says) and, when
// 'writeOpacity', level k of the solid-opacity volume (kSolidOpacity; a bounce's
// grid has the mip stage's geometry, so it reads them). Level 0 of 'src' must be empty outside the
// voxel fragments' voxels: each level visits only the texels with a fragment's voxel under them
// (shaders/vct_grid/mip_blocks.glsl) and leaves the others as cleared.
void buildMipLevel(StageContext& ctx, Texture& src, Texture& grid, Texture* const dirs[6], int k, bool writeOpacity);
// The inject stage's R32UI volume: per voxel, the facing code of its fragments' normals
// (shaders/common/facing.glsl): per travel direction, how much of its surfaces' fronts is seen.
inline constexpr const char* kVoxelFacing = "voxel-facing";
// The mip stage's solid opacity (RGBA8, the directional volumes' size and levels): the opacity of
// the voxels as solid cubes seen along x, y, z in r, g, b. One volume serves both travel directions
// of an axis: opacity alone composited front to back, 1 - (1 - a0)(1 - a1), does not depend on
// which child is in front. The directional volumes' alpha is the coverage of the surfaces' fronts
// only (mipmap_anisotropic.comp.glsl).
inline constexpr const char* kSolidOpacity = "solid-opacity";

// Indirect bounces (bounce_stage.cpp): the parameter, the volumes each bounce's grid is made of,
// and the grid the cones gather from (the mip stage's when bounces = 1, else the last bounce's).
ParamDesc bouncesParam();
inline constexpr int kMaxBounces = 3;
std::string bounceGridName(int bounce);                  // 1: "radiance"; k >= 2: "radiance-bounce<k>"
std::string bounceDirectionalName(int bounce, int direction);  // "radiance-dir+x", "radiance-bounce2-dir+x", ...
int directionalSize(const ParamSet& p);                 // edge of the directional volumes (1 unless anisotropic)
void declareGatheredGridReads(StageBuilder& b);         // reads every bounce's volumes, declares bounces
// The cone tracer reads the two directional volumes of an axis from one texture, the +a volume in
// its lower half along z and the -a volume in its upper half, level by level: a stage that traces
// cones declares the three packed textures (kPackedDirectionalPrefix + "x", "y", "z": scratch the
// bounce and cone-trace stages share) with declarePackedDirectional, and bindRadianceGrid fills
// them from a bounce's six volumes and binds texture units 0 and 8..10 of common/cone_trace.glsl.
inline const char* const kPackedDirectionalPrefix = "radiance-dir-packed-";
void declarePackedDirectional(StageBuilder& b);
void bindRadianceGrid(StageContext& ctx, int bounce);
// The defines of a program that includes common/cone_trace.glsl: which volumes a sample reads
// (mipmap.mode, mipmap.fronts), fixed per program rather than uniforms.
std::string coneVolumeDefines(const ParamSet& p);
TextureDesc packedDirectionalDesc(int edge, GLenum format);  // n x n x 2n, the volumes' levels
// Copies two directional volumes of edge n (full mip chains) into 'packed' (n x n x 2n, as many
// levels): level by level, 'positive' at z 0..n-1 and 'negative' at z n..2n-1 of that level.
void packDirectionalPair(const Texture& positive, const Texture& negative, Texture& packed);

class InjectStage : public Stage {
 public:
  const char* id() const override { return "inject"; }
  const char* title() const override { return "Inject direct light into the voxels"; }
  const char* summary() const override {
    return "Light each voxel fragment (Lambert, shadow-mapped, plus emission) and average the fragments "
           "of each voxel into an RGBA8 radiance grid: exact fixed-point sums with integer atomics, then one "
           "division (or, inject.average=compare-and-swap, a running average with an atomic compare-and-swap loop).";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class OcclusionFixStage : public Stage {
 public:
  const char* id() const override { return "occlusion-fix"; }
  const char* title() const override { return "Make occupied voxels opaque"; }
  const char* summary() const override {
    return "While averaging, alpha counted fragments; set it to 1 in every non-empty voxel so cones see solid voxels.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class MipmapStage : public Stage {
 public:
  const char* id() const override { return "mipmap"; }
  const char* title() const override { return "Prefilter the grid into mip levels"; }
  const char* summary() const override {
    return "Average each 2x2x2 block into the next level (our own compute pass per level), so a wide cone "
           "can read a whole region in one sample. One iteration per level: step them to watch the pyramid grow.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class BounceStage : public Stage {
 public:
  const char* id() const override { return "bounce"; }
  const char* title() const override { return "Bounce the light between the voxels"; }
  const char* summary() const override {
    return "For bounces above 1: every voxel fragment gathers the light of the previous bounce's grid with a few "
           "diffuse cones around its normal, times its albedo; the voxel's mean is added to the injected radiance and "
           "the sum mipmapped again, the grid of the next bounce. One iteration per bounce (bounce#k); at bounces=1 it "
           "does nothing and the cones read the mip stage's grid.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class ConeTraceStage : public Stage {
 public:
  const char* id() const override { return "cone-trace"; }
  const char* title() const override { return "Trace cones through the voxels"; }
  const char* summary() const override {
    return "Per pixel, march diffuse cones around the normal, a specular cone along the reflection and a "
           "shadow cone toward the light, sampling coarser mip levels as each cone widens. Traced in "
           "four bands of rows, one per iteration, so the viewer shows progress.";
  }
  static constexpr int kBands = 4;
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet&) const override { return kBands; }
  void execute(StageContext& ctx) override;
};

// The terms of this technique's composite (techniques/common/composite_stage.h).
CompositeTerms compositeTerms();

}  // namespace voxlab::vct
