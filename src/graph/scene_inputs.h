// Scene inputs: what a stage reads from outside the technique, named like blackboard resources so
// that the same declarations carry the dependency. No stage writes them; a stage that reads one
// goes stale when it changes, so a frame of an animation re-runs only the stages that read what
// moved (and every stage reading what those wrote).
//
//   "@view"      the camera and the output size (kViewResource, graph/stage.h; StepCursor marks
//                its readers itself when the view changes)
//   "@geometry"  the scene's triangles: positions and normals (a stage that rasterizes, voxelizes
//                or walks them all)
//   "@static-geometry"   the triangles no animation moves (Scene::triangleMoves false): a stage
//                that builds something from them alone keeps it while animated nodes move
//   "@dynamic-geometry"  the triangles animations move (Scene::movingVertices)
//   "@lights"    the scene's lights (Scene::lights)
//
// Posing an animated scene changes "@geometry" and "@dynamic-geometry" (invalidateMovedGeometry);
// a change of every triangle (a reload, or geometry marked moved as a whole) all three
// (invalidateAllGeometry).
#pragma once
#include <string>

namespace voxlab {

class StepCursor;

inline constexpr const char* kSceneGeometryInput = "@geometry";
inline constexpr const char* kSceneStaticGeometryInput = "@static-geometry";
inline constexpr const char* kSceneDynamicGeometryInput = "@dynamic-geometry";
inline constexpr const char* kSceneLightsInput = "@lights";

// Whether 'resource' is a scene input (its name starts with '@'), not a blackboard resource.
inline bool isSceneInput(const std::string& resource) { return !resource.empty() && resource[0] == '@'; }

// Makes every stage that reads the scene input 'input' stale, with every stage reading what they
// wrote, and has those readers forget what they held between runs (Stage::forgetHeldResults: what
// they kept was built from the input as it was). Returns how many stages read it.
int invalidateSceneInput(StepCursor& cursor, const std::string& input);

// The animated nodes' triangles moved: "@geometry" and "@dynamic-geometry" change, the static
// part stays. Returns how many stages read either.
int invalidateMovedGeometry(StepCursor& cursor);
// Every triangle may have moved: all three geometry inputs change.
int invalidateAllGeometry(StepCursor& cursor);

}  // namespace voxlab
