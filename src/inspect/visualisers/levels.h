// Visualisers of images and volumes (one or more levels of texels): the fallbacks for the
// Image2D and Volume3D kinds, whatever their semantic (the semantic's TexelMapping colours them).
// image.cpp and volume.cpp register them; a visualiser for one semantic of levels derives from
// these and overrides what differs (tests/viewer/plugins/cell_index_visualiser.cpp does).
#pragma once
#include "inspect/visualiser.h"

namespace voxlab {

class LevelVisualiser : public Visualiser {
 public:
  CaptureTier defaultTier(const OutputDesc& desc) const override;
  nlohmann::json statistics(const CapturedOutput& out) const override;
  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override;
  GoldenResult compareGolden(const CapturedOutput& out, const GoldenRequest& request) const override;

  SliceImage image2D(const VisualiserContext& ctx) const override;
  bool elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const override;
  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& element) const override;
  void drawInspector(const VisualiserContext& ctx) const override;

 protected:
  // The level shown (the view's, clamped), or nullptr when there is none.
  static const LevelData* shownLevel(const VisualiserContext& ctx);
};

class ImageVisualiser : public LevelVisualiser {
 public:
  const char* name() const override { return "image"; }
};

class VolumeVisualiser : public LevelVisualiser {
 public:
  const char* name() const override { return "volume"; }
  bool has3D(const OutputDesc&) const override { return true; }
  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override;
};

}  // namespace voxlab
