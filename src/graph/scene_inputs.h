// Scene inputs: what a stage reads from outside the technique, named like blackboard resources so
// that the same declarations carry the dependency. No stage writes them; a stage that reads one
// goes stale when it changes, so a frame of an animation re-runs only the stages that read what
// moved (and every stage reading what those wrote).
//
//   "@view"      the camera and the output size (kViewResource, graph/stage.h; StepCursor marks
//                its readers itself when the view changes)
//   "@geometry"  the scene's triangles: positions and normals (a stage that rasterizes, voxelizes
//                or walks them)
//   "@lights"    the scene's lights (Scene::lights)
#pragma once
#include <string>

namespace voxlab {

class StepCursor;

inline constexpr const char* kSceneGeometryInput = "@geometry";
inline constexpr const char* kSceneLightsInput = "@lights";

// Whether 'resource' is a scene input (its name starts with '@'), not a blackboard resource.
inline bool isSceneInput(const std::string& resource) { return !resource.empty() && resource[0] == '@'; }

// Makes every stage that reads the scene input 'input' stale, with every stage reading what they
// wrote, and has those readers forget what they held between runs (Stage::forgetHeldResults: what
// they kept was built from the input as it was). Returns how many stages read it.
int invalidateSceneInput(StepCursor& cursor, const std::string& input);

}  // namespace voxlab
