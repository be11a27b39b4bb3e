// Visualisers of buffers (arrays of records with a BufferLayout): the fallback for the Buffer
// kind. The inspector shows the record table; records with a Position field also get a point
// view (2D) and points or cubes in 3D. points.cpp and cone_samples.cpp derive from it.
#pragma once
#include "inspect/visualiser.h"

namespace voxlab {

class BufferVisualiser : public Visualiser {
 public:
  const char* name() const override { return "buffer"; }
  CaptureTier defaultTier(const OutputDesc& desc) const override { return CaptureTier::Tolerance; }
  nlohmann::json statistics(const CapturedOutput& out) const override;
  // JSON summary + raw .bin; a point view PNG when the records have a Position field.
  nlohmann::json writeFiles(const CapturedOutput& out, const std::string& dir, const std::string& prefix) const override;
  GoldenResult compareGolden(const CapturedOutput& out, const GoldenRequest& request) const override;

  SliceImage image2D(const VisualiserContext& ctx) const override;  // the point view, or none
  // A record picked in the point view: element.x is its index.
  std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& element) const override;
  std::string caption(const VisualiserContext& ctx) const override;
  bool has3D(const OutputDesc& desc) const override { return hasPositions(desc); }
  Content3D build3D(const VisualiserContext& ctx, View3D& view) const override;
  void drawInspector(const VisualiserContext& ctx) const override;

  static bool hasPositions(const OutputDesc& desc);
};

}  // namespace voxlab
