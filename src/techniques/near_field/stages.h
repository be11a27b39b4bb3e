// The stages of near-field after the shared ones (see near_field.cpp for the overview).
#pragma once
#include "graph/stage.h"
#include "techniques/common/atrous_filter_stage.h"
#include "techniques/common/composite_stage.h"
#include "techniques/near_field/near_field.h"

namespace voxlab::nearfield {

// The semantics of near-field's outputs; each picks its view in views/.
inline constexpr Semantic kRayCategory{"rsm-lookup-category"};  // R32UI per pixel: what the RSM lookup found
inline constexpr Semantic kTraversalSteps{"near-field-traversal"};  // hierarchy steps per ray
inline constexpr Semantic kProbeDda{"near-field-dda"};              // the probed ray's DDA steps
inline constexpr Semantic kProbeRay{"near-field-probe-ray"};        // the probed ray's walk and hit

class BitmaskTablesStage : public Stage {
 public:
  const char* id() const override { return "bitmask-tables"; }
  const char* title() const override { return "Bitmask tables"; }
  const char* summary() const override {
    return "OR[k] (slice k alone) and XOR[k] (slices k..127, with a 129th all-zero entry) on the CPU, then "
           "the 128x128 ray-mask table XOR[i] ^ XOR[j+1] (slices i..j) on the GPU.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class HierarchyStage : public Stage {
 public:
  const char* id() const override { return "hierarchy"; }
  const char* title() const override { return "2D OR mip hierarchy"; }
  const char* summary() const override {
    return "OR each 2x2 block of columns into the next level, keeping all 128 slices: a quadtree of full-depth "
           "columns. One level per iteration.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

class RaysStage : public Stage {
 public:
  const char* id() const override { return "rays"; }
  const char* title() const override { return "Near-field rays and RSM lookup"; }
  const char* summary() const override {
    return "Per pixel, one cosine-distributed ray per iteration walks the hierarchy to its first voxel; the hit is "
           "looked up in the reflective shadow map and, if the RSM sees that surface facing the receiver, its "
           "reflected radiance is added: (albedo / N) * sum.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;

 private:
  void recordProbeDda(StageContext& ctx, const BinaryGridGeometry& geo, Buffer& probe);
  void recordProbeSurface(StageContext& ctx, const BinaryGridGeometry& geo, Buffer& probe);
};

// Voxel path tracing (seed 000 section 3.2.4): the voxel attributes its path vertices need where
// the RSM does not see them, and the paths, one bounce of one path per iteration.
class VoxelAttributesStage : public Stage {
 public:
  const char* id() const override { return "voxel-attributes"; }
  const char* title() const override { return "Voxel albedo and normal"; }
  const char* summary() const override {
    return "One albedo and one normal per voxel of the fragment list (atomic max of the packed values), for path "
           "vertices the light's map does not see.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class PathsStage : public Stage {
 public:
  const char* id() const override { return "paths"; }
  const char* title() const override { return "Voxel path tracing"; }
  const char* summary() const override {
    return "Per pixel, paths of up to K diffuse bounces through the binary voxels; each hit the RSM sees lit adds "
           "its reflected radiance times the product of the albedos so far. One bounce of one path per iteration.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override;
  void execute(StageContext& ctx) override;
};

// The shared a-trous filter (techniques/common/atrous_filter_stage.h) over 'indirect', whose rays
// per pixel are 'raysParam' ("rays.count", "paths.count"), approximating 'referenceMode'
// ("indirect-1" for near-field's one bounce, "indirect-{paths.bounces}" for voxel path tracing's K).
AtrousFilterConfig filterConfig(const char* referenceMode, const char* raysParam);

// The terms of this technique's composite (techniques/common/composite_stage.h).
CompositeTerms compositeTerms();

}  // namespace voxlab::nearfield
