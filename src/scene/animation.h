// Node animation: what the loader keeps of a glTF file's animations so that the scene can be posed
// at any time t (poseScene in scene/scene.h). glTF animates a node's translation, rotation and
// scale through samplers: key times (seconds, strictly increasing) and values, interpolated
// LINEAR (rotations by spherical interpolation), STEP (the value of the last key at or before t)
// or CUBICSPLINE (Hermite, with an in-tangent and an out-tangent stored around every value).
// Before the first key a sampler holds its first value, after the last key its last value.
//
// The loaded scene is flat (world-space triangles), so the animation keeps the hierarchy it was
// flattened from: one placement per visit of a node (a node instanced twice is placed twice),
// parents before children, and, for every vertex range placed by a node that moves (one an
// animation targets, or one below it), the range's vertices in that node's own space. Lights and
// cameras remember their placement too.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace voxlab {

struct Scene;
class GpuScene;

enum class AnimationPath { Translation, Rotation, Scale };
enum class Interpolation { Linear, Step, CubicSpline };
const char* animationPathName(AnimationPath path);        // "translation", "rotation", "scale"
const char* interpolationName(Interpolation interpolation);  // "LINEAR", "STEP", "CUBICSPLINE"

struct AnimationSampler {
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> times;  // seconds, strictly increasing, at least one
  // One value per key; CUBICSPLINE: three per key (in-tangent, value, out-tangent). xyz holds a
  // translation or scale (w = 0), xyzw a rotation quaternion (glTF order: x, y, z, w).
  std::vector<glm::vec4> values;
};

// The sampler's value at time t for a channel of 'path' (rotations come back unit length).
glm::vec4 sampleAnimation(const AnimationSampler& sampler, AnimationPath path, float t);

struct AnimationChannel {
  int node = 0;     // glTF node index
  AnimationPath path = AnimationPath::Translation;
  int sampler = 0;  // index into SceneAnimation::samplers
};

// A node's local transform at rest (as in the file): its matrix, or translation, rotation, scale.
struct NodeRest {
  bool hasMatrix = false;
  glm::mat4 matrix{1.0f};
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // glm order: w, x, y, z
  glm::vec3 scale{1.0f};
};

struct NodePlacement {
  int node = 0;     // glTF node index
  int parent = -1;  // placement index of its parent, -1 = a root
  bool moves = false;  // it or a node above it is animated
};

// Vertices [first, first + count) of the scene, placed by a moving placement, in its space.
struct MovingVertices {
  int placement = 0;
  uint32_t first = 0, count = 0;
  std::vector<glm::vec3> localPositions;
  std::vector<glm::vec3> localNormals;
};

struct SceneAnimation {
  // Every animation of the file plays at once, from time 0 to 'duration' (seconds): the largest
  // key time of any sampler. 0 = the file has no animation.
  float duration = 0.0f;
  std::vector<std::string> names;  // the file's animations, in file order
  std::vector<AnimationSampler> samplers;
  std::vector<AnimationChannel> channels;
  std::vector<NodeRest> nodes;  // every glTF node
  std::vector<NodePlacement> placements;
  std::vector<MovingVertices> moving;
  std::vector<int> lightPlacement;   // per Scene::lights entry (-1 = not on a node: the default sun)
  std::vector<int> cameraPlacement;  // per Scene::cameras entry (-1 = the framing camera)

  bool animated() const { return !channels.empty(); }
  bool movesGeometry() const { return !moving.empty(); }
  // World matrix of every placement at time t.
  std::vector<glm::mat4> worldMatrices(float t) const;
};

// loadScene (scene/scene.h) that also hands back the file's animation. Every load reads the
// animations (malformed ones are errors), poses the scene at time 0 and gives it bounds that hold
// every moving vertex at every key time and between them, so the voxel volume stays put while
// objects move; this one keeps what posing it again needs.
Scene loadScene(const std::string& path, SceneAnimation& animation);

// What posing a scene at a new time changed.
struct ScenePoseChange {
  bool geometry = false;  // vertices moved (positions, normals)
  bool lights = false;    // a light on an animated node moved or turned
  bool cameras = false;   // a camera on an animated node moved or turned
  bool any() const { return geometry || lights || cameras; }
};

// Poses 'scene' (loaded with 'animation') at time t (seconds, clamped to [0, duration]): moves the
// vertices of animated nodes and the lights and cameras on them; bounds stay as loaded. Nothing
// changes for a still scene or a time that poses it as it is.
ScenePoseChange poseScene(Scene& scene, const SceneAnimation& animation, float t);

// Copies the posed vertices of the moving ranges into the GPU copy of 'scene' (the rest of its
// vertices, its indices, materials and textures stay).
void uploadPosedVertices(const GpuScene& gpuScene, const Scene& scene, const SceneAnimation& animation);

}  // namespace voxlab
