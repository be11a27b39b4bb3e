// Issue 20: the default sun, the light.0.* parameters ("scene" defaults) and what a change of
// them re-runs, for every technique in the registry that declares them.
#include <cmath>

#include <gtest/gtest.h>

#include "core/error.h"
#include "core/paths.h"
#include "graph/step_cursor.h"
#include "scene/scene.h"
#include "techniques/common/light_stage.h"
#include "test_support.h"

namespace voxlab {
namespace {

TEST(LightParams, SceneValueFormatsParsesAndValidates) {
  ParamDesc d = ParamDesc::fromScene("light.0.azimuth", 0.0, 360.0, "test", "degrees");
  EXPECT_TRUE(ParamDesc::isSceneValue(d.defaultValue));
  EXPECT_EQ(d.format(d.defaultValue), "scene");
  EXPECT_TRUE(ParamDesc::isSceneValue(d.parse("scene")));
  EXPECT_DOUBLE_EQ(d.parse("30"), 30.0);
  EXPECT_THROW(d.parse("400"), Error);
  EXPECT_THROW(d.parse("nan"), Error);  // only the word "scene" means the scene's value
  ParamDesc plain = ParamDesc::real("shadow.normal-offset", 0.01, 0.0, 0.2, "test");
  EXPECT_THROW(plain.parse("scene"), Error);
  ParamSet set;
  set.declare(d);
  set.declare(d);  // the same declaration twice is fine (NaN defaults compare equal)
  EXPECT_TRUE(ParamDesc::isSceneValue(set.value("light.0.azimuth")));
}

TEST(LightParams, SunAnglesRoundTripAndDefaultSun) {
  float az = 0, el = 0;
  sunAngles(sunDirection(123.0f, 40.0f), az, el);
  EXPECT_NEAR(az, 123.0f, 1e-3f);
  EXPECT_NEAR(el, 40.0f, 1e-3f);
  // Azimuth 90, elevation 0: the sun stands at +x, so its light travels along -x.
  glm::vec3 d = sunDirection(90.0f, 0.0f);
  EXPECT_NEAR(d.x, -1.0f, 1e-6f);
  EXPECT_NEAR(d.y, 0.0f, 1e-6f);
  // Straight up: the azimuth must not flip the (zero) horizontal part's sign.
  sunAngles(sunDirection(123.0f, 89.0f), az, el);
  EXPECT_NEAR(az, 123.0f, 1e-2f);
  Light sun = defaultSun();
  EXPECT_EQ(sun.type, LightType::Directional);
  sunAngles(sun.direction, az, el);
  EXPECT_NEAR(az, 30.0f, 1e-3f);
  EXPECT_NEAR(el, 60.0f, 1e-3f);
  EXPECT_LT(sun.direction.y, 0.0f);  // from above
}

TEST(LightParams, OverridesApplyOnlyWhereNotScene) {
  auto t = createTechnique("vct-grid");  // any technique with the light stage declares the same set
  ParamSet p = t->defaultParams();
  Light spot;
  spot.type = LightType::Spot;
  spot.position = glm::vec3(1, 2, 3);
  spot.direction = glm::vec3(0, -1, 0);
  spot.intensity = 7.0f;
  Light same = applyLightParams(spot, p);
  EXPECT_EQ(same.position, spot.position);
  EXPECT_EQ(same.direction, spot.direction);  // untouched while azimuth and elevation are "scene"
  EXPECT_EQ(same.intensity, 7.0f);
  p.setAssignment("light.0.elevation=0");
  p.setAssignment("light.0.y=5");
  p.setAssignment("light.0.intensity=2");
  Light moved = applyLightParams(spot, p);
  EXPECT_NEAR(moved.direction.y, 0.0f, 1e-6f);
  EXPECT_EQ(moved.position, glm::vec3(1, 5, 3));
  EXPECT_EQ(moved.intensity, 2.0f);
}

TEST(LightParams, SceneWithoutLightGetsTheDefaultSun) {
  Scene s = loadScene(projectPath("tests/data/scenes/no-light-blocks.gltf"));
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_EQ(s.lights[0].name, kDefaultSunName);
  ASSERT_EQ(s.cameras.size(), 1u);
  EXPECT_EQ(s.cameras[0].name, kFramingCameraName);
  // frameBounds' pose, renamed only.
  const Camera framed = frameBounds(s.bounds, Camera{}.yfov);
  EXPECT_EQ(s.cameras[0].position, framed.position);
  EXPECT_EQ(s.cameras[0].forward, framed.forward);
  Scene cornell = loadScene(resolveScenePath("cornell-box"));
  ASSERT_EQ(cornell.lights.size(), 1u);
  EXPECT_NE(cornell.lights[0].name, kDefaultSunName);
  ASSERT_FALSE(cornell.cameras.empty());
  EXPECT_NE(cornell.cameras[0].name, kFramingCameraName);
}

// Changing light.0.* marks the light stage, the shadow map (the stage that writes "light") and the
// final stage stale; every stage before the light stage (the voxelization) stays done.
TEST(LightParams, ChangingTheLightReRunsFromTheLightStageOnly) {
  int checked = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    ParamSet defaults = t->defaultParams();
    if (!defaults.has(kLightAzimuth)) continue;
    RunRequest r;
    r.technique = entry.id;
    r.width = r.height = 32;
    if (defaults.has("voxel.resolution")) r.sets.push_back("voxel.resolution=32");
    r.sets.push_back("light.0.intensity=1");  // a request of its own: this test changes the session
    HeadlessSession& s = testing_support::session(r);
    StepCursor& c = s.cursor();
    c.runAll();
    const int lightStage = c.technique().stageIndex("light");
    const int shadowStage = c.technique().writerOf("light", c.stageCount());
    const int finalStage = c.technique().stageIndex(c.technique().finalStage());
    ASSERT_GE(shadowStage, 0) << entry.id;
    c.setParam(kLightAzimuth, 123.0);
    c.setParam(kLightElevation, 45.0);  // a spot pointing straight down has no azimuth
    for (int i = 0; i < lightStage; ++i)
      EXPECT_EQ(c.record(i).state, StageState::Done) << entry.id << "/" << c.technique().stage(i).id();
    EXPECT_EQ(c.record(lightStage).state, StageState::Stale) << entry.id;
    EXPECT_EQ(c.record(shadowStage).state, StageState::Stale) << entry.id;
    EXPECT_EQ(c.record(finalStage).state, StageState::Stale) << entry.id;
    c.runAll();
    EXPECT_NEAR(c.record(lightStage).stats.at("azimuth_deg"), 123.0, 1e-3) << entry.id;
    EXPECT_NEAR(c.record(lightStage).stats.at("elevation_deg"), 45.0, 1e-3) << entry.id;
    ++checked;
  }
  EXPECT_GE(checked, 1);
}

}  // namespace
}  // namespace voxlab
