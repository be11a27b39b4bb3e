// Volumes: the image visualiser's slice view, controls and files (levels.h), plus the 3D view of
// one level: ray-marched front to back, or one cube per non-empty texel (View3D).
#include <cstdio>

#include "inspect/view3d.h"
#include "inspect/visualisers/levels.h"

namespace voxlab {

Content3D VolumeVisualiser::build3D(const VisualiserContext& ctx, View3D& view) const {
  Content3D c;
  const LevelData* L = shownLevel(ctx);
  if (!L) return c;
  VolumeRGBA vol = mapVolume(*L, ctx.out.desc.semantic, ctx.view.display);
  c.hi = glm::vec3(ctx.out.levels[0].size);  // view units: level-0 texels
  view.setVolume(vol, c.hi, 1.0f);
  char buf[160];
  std::snprintf(buf, sizeof buf, "level %d: %dx%dx%d, %zu non-empty texels", ctx.view.level, L->size.x, L->size.y,
                L->size.z, vol.nonEmpty);
  c.info = buf;
  return c;
}

VOXLAB_REGISTER_VISUALISER(VolumeVisualiser, OutputKind::Volume3D, kAnySemantic);

}  // namespace voxlab
