// The stages of svo after the shared voxelize / shadow-map stages (see svo.cpp for the overview).
#pragma once
#include <vector>

#include "graph/stage.h"
#include "svo/svo_shared.h"

namespace voxlab::svo {

// Semantics of the octree's buffers (octree-nodes, -descent and -picked-node have visualisers in
// src/techniques/svo/views/octree.cpp; octree-levels, a small table, uses the generic buffer view).
inline constexpr Semantic kOctreeNodes{"octree-nodes"};
inline constexpr Semantic kOctreeLevels{"octree-levels"};
inline constexpr Semantic kOctreeDescent{"octree-descent"};
inline constexpr Semantic kOctreePickedNode{"octree-picked-node"};

// Octree depth D = log2(voxel.resolution): levels 0 (root) .. D (voxels).
int octreeDepth(const ParamSet& params);
// The level table as the GPU wrote it (D + 1 records).
std::vector<SvoLevel> readLevels(Blackboard& board);
// Nodes written so far: the end of the last level with nodes.
uint32_t nodeCount(const std::vector<SvoLevel>& levels);

class BuildStage : public Stage {
 public:
  const char* id() const override { return "svo-build"; }
  const char* title() const override { return "Build the octree, one level per iteration"; }
  const char* summary() const override {
    return "Top down from the root: flag the nodes of this level that hold fragments (and, with dilation, "
           "their neighbours), count them, size the pool for the next level from that count, and give every "
           "flagged node a 2x2x2 tile of children from an atomic counter.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override { return octreeDepth(params) + 1; }
  void execute(StageContext& ctx) override;
};

class NeighboursStage : public Stage {
 public:
  const char* id() const override { return "svo-neighbours"; }
  const char* title() const override { return "Link every node to its face neighbours"; }
  const char* summary() const override {
    return "For every node, the same-level nodes across its six faces (up to the closest common ancestor and down "
           "again), or none: the links a border transfer or a neighbour walk follows.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class LeavesStage : public Stage {
 public:
  const char* id() const override { return "svo-leaves"; }
  const char* title() const override { return "Light the leaves"; }
  const char* summary() const override {
    return "Light every voxel fragment with the shadow-mapped direct light (as vct-grid's inject) and average "
           "the fragments of each leaf with exact integer sums.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class MipmapStage : public Stage {
 public:
  const char* id() const override { return "svo-mipmap"; }
  const char* title() const override { return "Filter the octree bottom up, one level per iteration"; }
  const char* summary() const override {
    return "Each node with children gets the average of its 8 children (the box filter of vct-grid's mips); "
           "the dense view resamples each finished level into a mip of a 3D texture.";
  }
  void declare(StageBuilder& b) const override;
  int iterations(const ParamSet& params) const override { return octreeDepth(params); }
  void execute(StageContext& ctx) override;
};

class BricksStage : public Stage {
 public:
  const char* id() const override { return "svo-bricks"; }
  const char* title() const override { return "Fill the 3x3x3 bricks"; }
  const char* summary() const override {
    return "Give every flagged node a brick in a 3D texture: its centre value and 26 border texels, each the "
           "mean of the same-level nodes sharing that point, so hardware trilinear filtering inside a node "
           "equals the dense grid's.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class PickStage : public Stage {
 public:
  const char* id() const override { return "svo-pick"; }
  const char* title() const override { return "Pick a node"; }
  const char* summary() const override {
    return "The node under a click on the octree's structure volume: its box, children, neighbour links and its "
           "brick's 27 values.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

class ConeTraceStage : public Stage {
 public:
  const char* id() const override { return "svo-cone-trace"; }
  const char* title() const override { return "Trace cones through the octree"; }
  const char* summary() const override {
    return "vct-grid's cones (diffuse + AO, specular, soft shadow), each sample descending the octree to the "
           "level of its diameter and blending two levels; the probed pixel's samples and descents are recorded.";
  }
  void declare(StageBuilder& b) const override;
  void execute(StageContext& ctx) override;
};

}  // namespace voxlab::svo
