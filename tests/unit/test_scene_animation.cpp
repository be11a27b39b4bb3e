// glTF node animations: each sampler (LINEAR, STEP, CUBICSPLINE with its tangents, rotations by
// spherical interpolation) against values worked out by hand, a loaded animation posing the
// scene's triangles, lights and bounds, one-line errors for each malformed animation, and the
// frame loop re-running only what a change invalidates (from the stages' declarations).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "graph/scene_inputs.h"
#include "graph/technique.h"
#include "run/frames.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "test_support.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;

// Every sampled value below is a few float operations on exact inputs: they agree with the hand
// values to within a few ulps; 1e-5 leaves room for the trigonometry of the rotation cases.
constexpr float kExact = 1e-5f;

AnimationSampler sampler(Interpolation mode, std::vector<float> times, std::vector<glm::vec4> values) {
  AnimationSampler s;
  s.interpolation = mode;
  s.times = std::move(times);
  s.values = std::move(values);
  return s;
}

TEST(SceneAnimation, LinearTranslationInterpolatesAndHoldsOutsideItsKeys) {
  const AnimationSampler s = sampler(Interpolation::Linear, {0.0f, 2.0f}, {{0, 0, 0, 0}, {4, 2, 0, 0}});
  const glm::vec4 quarter = sampleAnimation(s, AnimationPath::Translation, 0.5f);  // s = 0.25
  EXPECT_NEAR(quarter.x, 1.0f, kExact);
  EXPECT_NEAR(quarter.y, 0.5f, kExact);
  EXPECT_NEAR(sampleAnimation(s, AnimationPath::Translation, -1.0f).x, 0.0f, kExact);  // before: first key
  EXPECT_NEAR(sampleAnimation(s, AnimationPath::Translation, 3.0f).x, 4.0f, kExact);   // after: last key
}

TEST(SceneAnimation, StepHoldsTheLastKeyAtOrBeforeTheTime) {
  const AnimationSampler s = sampler(Interpolation::Step, {0.0f, 1.0f, 2.0f}, {{1, 0, 0, 0}, {5, 0, 0, 0}, {9, 0, 0, 0}});
  EXPECT_EQ(sampleAnimation(s, AnimationPath::Scale, 0.99f).x, 1.0f);
  EXPECT_EQ(sampleAnimation(s, AnimationPath::Scale, 1.0f).x, 5.0f);
  EXPECT_EQ(sampleAnimation(s, AnimationPath::Scale, 1.5f).x, 5.0f);
  EXPECT_EQ(sampleAnimation(s, AnimationPath::Scale, 2.5f).x, 9.0f);
}

TEST(SceneAnimation, LinearRotationIsSphericalAlongTheShorterArc) {
  const float h = glm::radians(45.0f);  // half of 90 degrees about +y
  const AnimationSampler s =
      sampler(Interpolation::Linear, {0.0f, 1.0f}, {{0, 0, 0, 1}, {0, std::sin(h), 0, std::cos(h)}});
  // Halfway: 45 degrees about +y, unit length (a chord would give 0.92 of it).
  const glm::vec4 q = sampleAnimation(s, AnimationPath::Rotation, 0.5f);
  EXPECT_NEAR(q.y, std::sin(glm::radians(22.5f)), kExact);
  EXPECT_NEAR(q.w, std::cos(glm::radians(22.5f)), kExact);
  // The same end key written negated (the same rotation) still turns the short way.
  const AnimationSampler negated =
      sampler(Interpolation::Linear, {0.0f, 1.0f}, {{0, 0, 0, 1}, {0, -std::sin(h), 0, -std::cos(h)}});
  const glm::vec4 n = sampleAnimation(negated, AnimationPath::Rotation, 0.5f);
  EXPECT_NEAR(std::abs(n.y), std::sin(glm::radians(22.5f)), kExact);
  EXPECT_NEAR(std::abs(n.w), std::cos(glm::radians(22.5f)), kExact);
}

TEST(SceneAnimation, CubicSplineUsesTheTangentsScaledByTheInterval) {
  // Keys at 0 s and 2 s: value 0 with out-tangent 1/s, then value 1 with in-tangent 2/s.
  // Hermite with dt = 2: p(s) = h01(s) + 2 h10(s) * 1 + 2 h11(s) * 2.
  //   t = 1.0 (s = 0.5):  h10 = 0.125, h01 = 0.5, h11 = -0.125      -> 0.25 + 0.5 - 0.5 = 0.25
  //   t = 1.5 (s = 0.75): h10 = 0.046875, h01 = 0.84375, h11 = -0.140625 -> 0.09375 + 0.84375 - 0.5625 = 0.375
  const AnimationSampler s = sampler(Interpolation::CubicSpline, {0.0f, 2.0f},
                                     {{0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0},    // key 0: in, value, out
                                      {2, 0, 0, 0}, {1, 0, 0, 0}, {0, 0, 0, 0}});  // key 1: in, value, out
  EXPECT_NEAR(sampleAnimation(s, AnimationPath::Translation, 1.0f).x, 0.25f, kExact);
  EXPECT_NEAR(sampleAnimation(s, AnimationPath::Translation, 1.5f).x, 0.375f, kExact);
  EXPECT_NEAR(sampleAnimation(s, AnimationPath::Translation, 2.0f).x, 1.0f, kExact);  // the key's value, not a tangent
}

// --- loading ---------------------------------------------------------------------------------------

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    uint32_t v = uint32_t(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
    if (i + 2 < bytes.size()) v |= bytes[i + 2];
    out += alphabet[(v >> 18) & 63];
    out += alphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? alphabet[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[v & 63] : '=';
  }
  return out;
}

struct AnimatedFile {
  std::vector<float> times{0.0f, 1.0f};
  std::vector<float> values{0, 0, 0, 2, 0, 0};  // flat components
  std::string outputType = "VEC3";
  std::string interpolation = "LINEAR";
  std::string path = "translation";
  int sampler = 0;
  int targetNode = 0;  // 0: the triangle; 1: the spot light's node
};

// One triangle (0,0,0) (1,0,0) (0,1,0) on node 0, a spot light on node 1 at (0,2,0) looking down
// -z, and one animation channel as 'f' describes.
std::string writeAnimated(const std::string& name, const AnimatedFile& f) {
  std::vector<float> floats{0, 0, 0, 1, 0, 0, 0, 1, 0};
  floats.insert(floats.end(), f.times.begin(), f.times.end());
  floats.insert(floats.end(), f.values.begin(), f.values.end());
  std::vector<uint8_t> bytes(floats.size() * 4);
  std::memcpy(bytes.data(), floats.data(), bytes.size());
  const size_t timesOffset = 36, valuesOffset = 36 + f.times.size() * 4;
  const size_t components = f.outputType == "VEC4" ? 4 : 3;
  const std::string text =
      R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0,1]}],)"
      R"("extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":[{"type":"spot","intensity":1,"spot":{"outerConeAngle":0.7}}]}},)"
      R"("nodes":[{"mesh":0},{"translation":[0,2,0],"extensions":{"KHR_lights_punctual":{"light":0}}}],)"
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},)"
      R"({"bufferView":1,"componentType":5126,"count":)" + std::to_string(f.times.size()) + R"(,"type":"SCALAR"},)"
      R"({"bufferView":2,"componentType":5126,"count":)" + std::to_string(f.values.size() / components) +
      R"(,"type":")" + f.outputType + R"("}],)"
      R"("bufferViews":[{"buffer":0,"byteLength":36},{"buffer":0,"byteOffset":)" + std::to_string(timesOffset) +
      R"(,"byteLength":)" + std::to_string(f.times.size() * 4) + R"(},{"buffer":0,"byteOffset":)" +
      std::to_string(valuesOffset) + R"(,"byteLength":)" + std::to_string(f.values.size() * 4) + R"(}],)"
      R"("animations":[{"samplers":[{"input":1,"output":2,"interpolation":")" + f.interpolation + R"("}],)"
      R"("channels":[{"sampler":)" + std::to_string(f.sampler) + R"(,"target":{"node":)" +
      std::to_string(f.targetNode) + R"(,"path":")" + f.path + R"("}}]}],)"
      R"("buffers":[{"byteLength":)" + std::to_string(bytes.size()) +
      R"(,"uri":"data:application/octet-stream;base64,)" + base64(bytes) + R"("}]})";
  const fs::path dir = fs::temp_directory_path() / ("voxlab-animation-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

TEST(SceneAnimation, ATranslatedTriangleMovesAndItsBoundsHoldTheWholePath) {
  SceneAnimation animation;
  Scene scene = loadScene(writeAnimated("moving-triangle.gltf", AnimatedFile{}), animation);
  ASSERT_TRUE(animation.animated());
  EXPECT_FLOAT_EQ(animation.duration, 1.0f);
  ASSERT_EQ(animation.moving.size(), 1u);
  // Posed at time 0 when loaded; the bounds reach the end of the path (x up to 1 + 2).
  EXPECT_FLOAT_EQ(scene.positions[1].x, 1.0f);
  EXPECT_FLOAT_EQ(scene.bounds.max.x, 3.0f);
  const ScenePoseChange half = poseScene(scene, animation, 0.5f);
  EXPECT_TRUE(half.geometry);
  EXPECT_FALSE(half.lights) << "the light's node does not move";
  EXPECT_NEAR(scene.positions[1].x, 2.0f, kExact);
  EXPECT_NEAR(scene.positions[0].x, 1.0f, kExact);
  EXPECT_FALSE(poseScene(scene, animation, 0.5f).any()) << "the same time again changes nothing";
  EXPECT_FLOAT_EQ(scene.bounds.max.x, 3.0f) << "bounds stay as loaded";
}

TEST(SceneAnimation, ALightOnAnAnimatedNodeTurnsWithIt) {
  AnimatedFile f;
  f.targetNode = 1;
  f.path = "rotation";
  f.outputType = "VEC4";
  const float h = glm::radians(45.0f);  // 90 degrees about +y: -z turns to -x
  f.values = {0, 0, 0, 1, 0, std::sin(h), 0, std::cos(h)};
  SceneAnimation animation;
  Scene scene = loadScene(writeAnimated("turning-light.gltf", f), animation);
  ASSERT_EQ(scene.lights.size(), 1u);
  EXPECT_NEAR(scene.lights[0].direction.z, -1.0f, kExact);
  const ScenePoseChange end = poseScene(scene, animation, 1.0f);
  EXPECT_TRUE(end.lights);
  EXPECT_FALSE(end.geometry);
  EXPECT_NEAR(scene.lights[0].direction.x, -1.0f, kExact);
  EXPECT_NEAR(scene.lights[0].position.y, 2.0f, kExact) << "turning in place";
}


TEST(SceneAnimation, MalformedAnimationsAreOneLineErrors) {
  AnimatedFile badSampler;
  badSampler.sampler = 3;
  testing_support::expectSceneRejected(writeAnimated("bad-sampler.gltf", badSampler), "channels[0].sampler = 3 is out of range");

  AnimatedFile countMismatch;
  countMismatch.values = {0, 0, 0, 1, 0, 0, 2, 0, 0};  // three values for two key times
  testing_support::expectSceneRejected(writeAnimated("count-mismatch.gltf", countMismatch), "output has 3 values for 2 key times");

  AnimatedFile cubicCount;
  cubicCount.interpolation = "CUBICSPLINE";  // needs in-tangent, value, out-tangent per key: 6
  testing_support::expectSceneRejected(writeAnimated("cubic-count.gltf", cubicCount), "CUBICSPLINE needs 3 per key time");

  AnimatedFile unknownPath;
  unknownPath.path = "colour";
  testing_support::expectSceneRejected(writeAnimated("unknown-path.gltf", unknownPath), "target.path 'colour' is unknown");

  AnimatedFile unknownMode;
  unknownMode.interpolation = "BEZIER";
  testing_support::expectSceneRejected(writeAnimated("unknown-interpolation.gltf", unknownMode), "interpolation 'BEZIER' is unknown");

  AnimatedFile notIncreasing;
  notIncreasing.times = {0.0f, 1.0f, 1.0f};
  notIncreasing.values = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  testing_support::expectSceneRejected(writeAnimated("times-not-increasing.gltf", notIncreasing), "input times are not increasing");

  AnimatedFile wrongType;
  wrongType.path = "rotation";  // a rotation needs VEC4 quaternions
  testing_support::expectSceneRejected(writeAnimated("wrong-output-type.gltf", wrongType), "has type VEC3, expected VEC4");
}

// --- frames ----------------------------------------------------------------------------------------

bool reads(const Technique& t, int stage, const std::string& input) {
  const auto& r = t.decl(stage).reads;
  return std::find(r.begin(), r.end(), input) != r.end();
}

// The frame loop makes stale exactly what a change invalidates, from the declarations: a moving
// object re-runs the stages reading the scene's geometry and what reads their results, a light
// move those reading the light, a held frame nothing.
TEST(SceneAnimation, AFramesSceneTimeSpansTheTimeRange) {
  const ParamSet params = createTechnique("vct-grid")->defaultParams();
  const std::vector<ParamAnimation> none;
  // Frame k of N: FROM + (TO - FROM) k / (N - 1), in double (exact for these binary fractions).
  EXPECT_EQ(animatedFrame(params, none, 0, 3, std::make_pair(0.5, 1.5)).sceneTime, 0.5);
  EXPECT_EQ(animatedFrame(params, none, 1, 3, std::make_pair(0.5, 1.5)).sceneTime, 1.0);
  EXPECT_EQ(animatedFrame(params, none, 2, 3, std::make_pair(0.5, 1.5)).sceneTime, 1.5);
  EXPECT_EQ(animatedFrame(params, none, 0, 1, std::make_pair(0.5, 1.5)).sceneTime, 0.5) << "one frame holds FROM";
  EXPECT_FALSE(animatedFrame(params, none, 1, 3).sceneTime.has_value()) << "a still scene has no time";
  // Parameters and scene time move together.
  const FrameValues both = animatedFrame(params, {{"light.0.elevation", 90.0, 60.0}}, 1, 3, std::make_pair(0.0, 2.0));
  ASSERT_EQ(both.params.size(), 1u);
  EXPECT_EQ(both.params[0].second, 75.0);
  EXPECT_EQ(both.sceneTime, 1.0);
}

TEST(SceneAnimation, AFrameReRunsOnlyWhatItsChangeInvalidates) {
  RunRequest r;
  r.technique = "vct-grid";
  r.scene = "cornell-box-moving";
  r.width = r.height = 64;
  HeadlessSession& session = testing_support::session(r);
  StepCursor& c = session.cursor();
  const Technique& t = c.technique();
  // The session read the animation with its scene: the same as loading the file again.
  const SceneAnimation& animation = session.animation();
  ASSERT_TRUE(animation.movesGeometry());
  SceneAnimation fromFile;
  loadScene(c.scene().path, fromFile);
  EXPECT_EQ(animation.duration, fromFile.duration);
  EXPECT_EQ(animation.moving.size(), fromFile.moving.size());
  const int voxelize = t.stageIndex("voxelize"), light = t.stageIndex("light");
  const int gbuffer = t.stageIndex("gbuffer");
  auto staleStages = [&] {
    std::vector<int> s;
    for (int i = 0; i < t.stageCount(); ++i)
      if (c.record(i).state != StageState::Done) s.push_back(i);
    return s;
  };
  session.run();
  ASSERT_TRUE(staleStages().empty());

  // Held frame: the time it is posed at already.
  EXPECT_FALSE(poseSessionScene(session, 0.0).any());
  EXPECT_TRUE(staleStages().empty()) << "a frame where nothing moved re-runs nothing";

  // The box moves: every geometry reader is stale, the light stage is not.
  // Only the cursor's own scene can be posed through it (a copy would leave the GPU copy behind).
  Scene copy = c.scene();
  EXPECT_THROW(poseCursorScene(c, copy, animation, 0.5, -1), Error);
  EXPECT_TRUE(staleStages().empty()) << "a refused pose changes nothing";
  EXPECT_TRUE(poseSessionScene(session, 0.5).geometry);
  const std::vector<int> afterMove = staleStages();
  for (int i = 0; i < t.stageCount(); ++i)
    if (reads(t, i, kSceneGeometryInput)) EXPECT_NE(c.record(i).state, StageState::Done) << t.stage(i).id();
  EXPECT_NE(c.record(voxelize).state, StageState::Done);
  EXPECT_NE(c.record(gbuffer).state, StageState::Done);
  EXPECT_EQ(c.record(light).state, StageState::Done) << "the light did not move";
  session.run();
  ASSERT_TRUE(staleStages().empty());

  // The light moves (as the scene's lights changing does): voxelize and the G-buffer stay.
  invalidateSceneInput(c, kSceneLightsInput);
  EXPECT_NE(c.record(light).state, StageState::Done);
  EXPECT_EQ(c.record(voxelize).state, StageState::Done) << "a light move does not re-voxelize";
  EXPECT_EQ(c.record(gbuffer).state, StageState::Done) << "a light move does not redraw the G-buffer";
  EXPECT_LT(staleStages().size(), afterMove.size()) << "a light move re-runs fewer stages than a moving object";
  session.run();
}

// --- the static and dynamic voxelization ------------------------------------------------------------

// The records of a fragment list, each 'stride' bytes, sorted: the list's content without the order
// its atomic appends happened to take.
std::vector<std::string> sortedRecords(const CapturedOutput& fragments) {
  const size_t stride = fragments.desc.layout.stride;
  std::vector<std::string> records;
  for (uint32_t i = 0; i < fragments.recordCount; ++i)
    records.emplace_back(reinterpret_cast<const char*>(&fragments.records[size_t(i) * stride]), stride);
  std::sort(records.begin(), records.end());
  return records;
}

std::vector<std::string> staleStageIds(const StepCursor& c) {
  std::vector<std::string> ids;
  for (int i = 0; i < c.technique().stageCount(); ++i)
    if (c.record(i).state != StageState::Done) ids.push_back(c.technique().stage(i).id());
  return ids;
}

// The static triangles voxelized once and the moving ones appended each frame give exactly the
// fragments of voxelizing every triangle at once (the voxelization technique's voxelize stage, one
// pass over the whole scene), record for record, at two times of the animation and with both exact
// methods (the compute pass, and the raster pass, which skips the other part in its geometry shader).
TEST(SceneAnimation, StaticAndDynamicVoxelsMergedEqualVoxelizingEveryTriangle) {
  SceneAnimation animation;
  const Scene still = loadScene(resolveScenePath("cornell-box-moving"), animation);
  ASSERT_TRUE(animation.movesGeometry());
  ASSERT_GT(still.movingTriangleCount(), 0u);
  ASSERT_LT(still.movingTriangleCount(), still.triangleCount()) << "the scene has still triangles too";
  const std::vector<double> times = {0.3 * animation.duration, 0.8 * animation.duration};
  for (const char* method : {"triangle-parallel", "fragment-parallel"}) {
    SCOPED_TRACE(method);
    auto request = [&](const char* technique) {
      RunRequest r;
      r.technique = technique;
      r.scene = "cornell-box-moving";
      r.until = "voxelize";
      r.width = r.height = 32;
      r.sets = {"voxel.resolution=64", std::string("voxelize.method=") + method};
      return r;
    };
    std::vector<std::vector<std::string>> merged;
    {
      HeadlessSession& s = testing_support::freshSession(request("vct-grid"));
      s.run();
      for (double t : times) {
        poseSessionScene(s, t);
        s.run();
        const StageStats& stats = s.cursor().record(s.cursor().technique().stageIndex("voxelize")).stats;
        EXPECT_GT(stats.at("fragments_dynamic"), 0.0) << "the moving block has voxels at t = " << t;
        EXPECT_GT(stats.at("fragments_static"), 0.0);
        merged.push_back(sortedRecords(testing_support::capture(s, "voxelize", "fragments")));
      }
    }
    EXPECT_NE(merged[0], merged[1]) << "the block moved between the two times";
    HeadlessSession& whole = testing_support::freshSession(request("voxelization"));
    whole.run();
    for (size_t k = 0; k < times.size(); ++k) {
      poseSessionScene(whole, times[k]);
      whole.run();
      const std::vector<std::string> once = sortedRecords(testing_support::capture(whole, "voxelize", "fragments"));
      EXPECT_EQ(merged[k].size(), once.size()) << "t = " << times[k];
      EXPECT_TRUE(merged[k] == once) << "t = " << times[k] << ": the merged list differs from one pass over every triangle";
    }
  }
}

// A frame where only the animated block moved re-runs the moving triangles' voxelization and what
// reads it (and the stages drawing every triangle), never the still triangles' voxelization; a
// camera move re-runs no voxelization at all.
TEST(SceneAnimation, AMovingObjectReVoxelizesOnlyItsTrianglesAndACameraMoveNone) {
  RunRequest r;
  r.technique = "vct-grid";
  r.scene = "cornell-box-moving";
  r.width = r.height = 32;
  r.sets = {"voxel.resolution=32"};
  HeadlessSession& session = testing_support::freshSession(r);
  StepCursor& c = session.cursor();
  SceneAnimation animation;
  loadScene(c.scene().path, animation);
  session.run();
  ASSERT_TRUE(staleStageIds(c).empty());

  EXPECT_TRUE(poseSessionScene(session, 0.5 * animation.duration).geometry);
  const std::vector<std::string> moved = {"voxelize", "triangle-axes", "shadow-map", "inject", "occlusion-fix",
                                          "mipmap", "bounce", "gbuffer", "cone-trace", "composite"};
  EXPECT_EQ(staleStageIds(c), moved) << "every stage but voxelize-static and light";
  session.run();

  Camera stepped = c.camera();
  stepped.position += glm::vec3(0.05f, 0.0f, 0.0f);
  c.setCamera(stepped);
  const std::vector<std::string> looked = {"triangle-axes", "gbuffer", "cone-trace", "composite"};
  EXPECT_EQ(staleStageIds(c), looked) << "only the stages drawing from the camera";
  session.run();
}

}  // namespace
}  // namespace voxlab
