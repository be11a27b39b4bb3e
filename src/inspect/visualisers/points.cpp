// Point lists (Semantic::Points: voxel fragments and other records with a position): the buffer
// visualiser's views and files; the records are appended by atomics in no fixed order, so the
// snapshot suite compares them exactly as sorted sets.
#include "inspect/visualisers/buffer.h"

namespace voxlab {

class PointsVisualiser : public BufferVisualiser {
 public:
  const char* name() const override { return "points"; }
  CaptureTier defaultTier(const OutputDesc&) const override { return CaptureTier::Exact; }
};

VOXLAB_REGISTER_VISUALISER(PointsVisualiser, OutputKind::Buffer, Semantic::Points.name());

}  // namespace voxlab
