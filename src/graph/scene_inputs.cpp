#include "graph/scene_inputs.h"

#include <algorithm>

#include "graph/step_cursor.h"

namespace voxlab {

int invalidateSceneInput(StepCursor& cursor, const std::string& input) {
  Technique& technique = cursor.technique();
  int readers = 0;
  for (int i = 0; i < technique.stageCount(); ++i) {
    const auto& reads = technique.decl(i).reads;
    if (std::find(reads.begin(), reads.end(), input) == reads.end()) continue;
    technique.stage(i).forgetHeldResults();
    cursor.invalidate(i);
    ++readers;
  }
  return readers;
}

int invalidateMovedGeometry(StepCursor& cursor) {
  return invalidateSceneInput(cursor, kSceneGeometryInput) + invalidateSceneInput(cursor, kSceneDynamicGeometryInput);
}

int invalidateAllGeometry(StepCursor& cursor) {
  return invalidateMovedGeometry(cursor) + invalidateSceneInput(cursor, kSceneStaticGeometryInput);
}

}  // namespace voxlab
