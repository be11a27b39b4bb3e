// Viewer logic without a window: lesson parsing and validation, the viewer's script format, the
// `voxlab run` line that reproduces a viewer state, slice display mapping and cone-sample decoding.
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <set>

#include <gtest/gtest.h>

#include "common/shared.h"
#include "core/error.h"
#include "core/paths.h"
#include "graph/technique.h"
#include "run/session.h"
#include "inspect/inspect_logic.h"
#include "inspect/visualisers/cone_samples.h"
#include "lesson/lesson.h"
#include "test_support.h"

namespace voxlab {
namespace {

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Lesson, ShippedLessonCoversEveryVctGridStage) {
  Lesson l = loadLesson(projectPath("lessons/01-voxel-cone-tracing.md"));
  auto t = createTechnique("vct-grid");
  std::set<std::string> seen;
  for (const auto& s : l.steps) {
    EXPECT_EQ(s.technique, "vct-grid");
    EXPECT_FALSE(s.narrative.empty()) << "step at line " << s.line << " has no narrative";
    EXPECT_FALSE(s.output.empty());
    seen.insert(s.stage);
  }
  // A stage without outputs (the shared light stage, which only writes the light for later
  // stages) has nothing to show; every other stage must appear.
  for (int i = 0; i < t->stageCount(); ++i)
    if (!t->decl(i).outputs.empty())
      EXPECT_TRUE(seen.count(t->stage(i).id())) << "lesson never shows stage " << t->stage(i).id();
}

// Every lesson shipped in lessons/ (all *.md but the authors' README) parses and validates, so a
// new lesson is checked with no test code.
TEST(Lesson, EveryShippedLessonIsValid) {
  size_t lessons = 0;
  for (const auto& e : std::filesystem::directory_iterator(projectPath("lessons"))) {
    if (e.path().extension() != ".md" || e.path().filename() == "README.md") continue;
    EXPECT_NO_THROW(loadLesson(e.path().string())) << e.path();
    ++lessons;
  }
  EXPECT_GE(lessons, 2u);
}

TEST(Lesson, StepsCarryTechniqueAndSceneAndDefaultTheOutput) {
  Lesson l = parseLesson(
      "# T\nintro\n```voxlab-step\n{\"technique\":\"vct-grid\",\"stage\":\"mipmap\",\"level\":2,"
      "\"set\":{\"mipmap.mode\":\"anisotropic\",\"voxel.resolution\":64}}\n```\nsecond\n"
      "```voxlab-step\n{\"stage\":\"composite\",\"output\":\"final\"}\n```\nthe end\n",
      "mem.md");
  ASSERT_EQ(l.steps.size(), 2u);
  EXPECT_EQ(l.title, "T");
  EXPECT_EQ(l.steps[0].line, 3);
  EXPECT_EQ(l.steps[0].output, "radiance");  // first output of the stage
  EXPECT_EQ(l.steps[0].level, 2);
  ASSERT_EQ(l.steps[0].sets.size(), 2u);
  EXPECT_EQ(l.steps[0].sets[1].second, "64");
  EXPECT_EQ(l.steps[1].technique, "vct-grid");
  EXPECT_EQ(l.steps[1].scene, "cornell-box");
  EXPECT_EQ(l.steps[1].narrative, "second");
  EXPECT_EQ(l.epilogue, "the end");
}

TEST(Lesson, ErrorsNameFileAndLine) {
  auto bad = [](const std::string& json) {
    return errorOf([&] { parseLesson("# x\n\n```voxlab-step\n" + json + "\n```\n", "l.md"); });
  };
  EXPECT_NE(bad("{\"technique\":\"no-such\",\"stage\":\"a\"}").find("l.md:3: unknown technique"), std::string::npos)
      << bad("{\"technique\":\"no-such\",\"stage\":\"a\"}");
  EXPECT_NE(bad("{\"technique\":\"vct-grid\",\"stage\":\"nope\"}").find("l.md:3:"), std::string::npos);
  EXPECT_NE(bad("{\"technique\":\"vct-grid\",\"stage\":\"mipmap\",\"output\":\"x\"}").find("l.md:3:"), std::string::npos);
  std::string p = bad("{\"technique\":\"vct-grid\",\"stage\":\"mipmap\",\"set\":{\"cone.count\":99}}");
  EXPECT_NE(p.find("l.md:3:"), std::string::npos) << p;
  EXPECT_NE(p.find("cone.count"), std::string::npos) << p;
  EXPECT_NE(bad("{\"technique\":\"vct-grid\",\"stage\":\"mipmap\",\"set\":{\"nope.x\":1}}").find("unknown parameter"),
            std::string::npos);
  EXPECT_NE(bad("{\"technique\":\"vct-grid\",\"stage\":\"mipmap\",\"colour\":1}").find("unknown key 'colour'"),
            std::string::npos);
  // Iterations only on iterative stages and within their count (mipmap at 128^3: 7 levels to build).
  std::string it = bad("{\"technique\":\"vct-grid\",\"stage\":\"gbuffer\",\"iterations\":2}");
  EXPECT_NE(it.find("l.md:3: iterations: stage gbuffer is not iterative"), std::string::npos) << it;
  it = bad("{\"technique\":\"vct-grid\",\"stage\":\"mipmap\",\"iterations\":8}");
  EXPECT_NE(it.find("iterations must be 1..7 for mipmap, got 8"), std::string::npos) << it;
  // Overlays name a volume output, with an optional level.
  std::string ov = bad("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"overlay\":\"gbuffer/normal@0\"}");
  EXPECT_NE(ov.find("overlay gbuffer/normal@0 is a image2d; overlays show volumes"), std::string::npos) << ov;
  ov = bad("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"overlay\":\"mipmap/glow\"}");
  EXPECT_NE(ov.find("overlay: vct-grid/mipmap has no output 'glow'"), std::string::npos) << ov;
  EXPECT_EQ(bad("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"overlay\":\"mipmap/radiance@2\",\"bounds\":true}"), "");
  // "beside": "reference" needs an image output that declares a reference mode, camera 0 and a
  // reference image of that mode for the scene.
  std::string bs = bad("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"output\":\"final\",\"beside\":\"reference\"}");
  EXPECT_NE(bs.find("l.md:3: beside: output final declares no reference mode to show beside it; outputs of composite "
                    "that do: direct, combined"),
            std::string::npos)
      << bs;
  bs = bad("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"output\":\"combined\",\"beside\":\"truth\"}");
  EXPECT_NE(bs.find("'beside' must be \"reference\", got \"truth\""), std::string::npos) << bs;
  bs = bad("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"output\":\"combined\",\"camera\":1,"
           "\"beside\":\"reference\"}");
  EXPECT_NE(bs.find("rendered from camera 0"), std::string::npos) << bs;
  bs = bad("{\"technique\":\"vct-grid\",\"scene\":\"tests/data/scenes/huge-triangles.gltf\",\"stage\":\"composite\","
           "\"output\":\"combined\",\"beside\":\"reference\"}");
  EXPECT_NE(bs.find("has no reference image for mode full"), std::string::npos) << bs;
  Lesson beside = parseLesson("# b\n```voxlab-step\n{\"technique\":\"voxel-path-tracing\",\"stage\":\"filter\","
                              "\"output\":\"indirect-filtered\",\"set\":{\"paths.bounces\":4},\"beside\":\"reference\"}\n```\n",
                              "b.md");
  EXPECT_EQ(beside.steps[0].referenceMode, "indirect-4");  // the mode follows the step's parameters
  EXPECT_NE(beside.steps[0].referenceImage.find("tests/golden/reference/cornell-box/indirect-4.exr"), std::string::npos);
  // A JSON syntax error names the line inside the block.
  std::string j = errorOf([] { parseLesson("a\n```voxlab-step\n{\"technique\": \"vct-grid\",\n \"stage\" \"x\"}\n```\n", "j.md"); });
  EXPECT_EQ(j.rfind("j.md:4:", 0), 0u) << j;
  EXPECT_NE(errorOf([] { parseLesson("no steps here\n", "e.md"); }).find("no ```voxlab-step"), std::string::npos);
  EXPECT_NE(errorOf([] { parseLesson("```voxlab-step\n{}\n", "u.md"); }).find("u.md:1: voxlab-step block is never closed"),
            std::string::npos);
}

// A step's sweep: validated with the step (one line naming it), and run with the step's state less
// the swept parameter, then "sweep_set", at the lesson sweep size.
TEST(Lesson, StepSweepIsValidatedAndCarriesTheStepsState) {
  auto parse = [](const std::string& json) { return parseLesson("# x\n\n```voxlab-step\n" + json + "\n```\n", "l.md"); };
  auto bad = [&](const std::string& json) { return errorOf([&] { parse(json); }); };
  const Lesson lesson = parse(
      "{\"technique\":\"vct-grid\",\"stage\":\"cone-trace\",\"set\":{\"cone.aperture\":60,\"cone.count\":9},"
      "\"sweep\":\"cone.aperture=30:60:3\",\"sweep_set\":{\"voxel.resolution\":32}}");
  ASSERT_EQ(lesson.steps.size(), 1u);
  EXPECT_EQ(lesson.steps[0].sweep, "cone.aperture=30:60:3");
  const SweepRequest request = lessonSweepRequest(lesson.steps[0]);
  EXPECT_EQ(request.technique, "vct-grid");
  EXPECT_EQ(request.width, kLessonSweepSize);
  EXPECT_EQ(request.params, std::vector<std::string>{"cone.aperture=30:60:3"});
  EXPECT_EQ(request.sets, (std::vector<std::string>{"cone.count=9", "voxel.resolution=32"}));
  EXPECT_EQ(sweepValueTexts("vct-grid", "cone.aperture=30:60:3"), (std::vector<std::string>{"30", "45", "60"}));
  std::string e = bad("{\"technique\":\"vct-grid\",\"stage\":\"cone-trace\",\"sweep\":\"cone.nope=1,2\"}");
  EXPECT_EQ(e.rfind("l.md:3: sweep: unknown parameter 'cone.nope'", 0), 0u) << e;
  e = bad("{\"technique\":\"vct-grid\",\"stage\":\"cone-trace\",\"sweep\":\"cone.aperture=30\"}");
  EXPECT_NE(e.find("a sweep needs at least two values"), std::string::npos) << e;
  e = bad("{\"technique\":\"vct-grid\",\"stage\":\"cone-trace\",\"sweep_set\":{\"voxel.resolution\":32}}");
  EXPECT_NE(e.find("l.md:3: 'sweep_set' needs a 'sweep' in the same step"), std::string::npos) << e;
  e = bad("{\"technique\":\"vct-grid\",\"stage\":\"cone-trace\",\"sweep\":\"cone.aperture=30,60\","
          "\"sweep_set\":{\"voxel.resolution\":33}}");
  EXPECT_NE(e.find("l.md:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("voxel.resolution"), std::string::npos) << e;
}

// A step's frames: its count and animations validated with the step, each problem one line naming
// the step's line and what would be valid.
TEST(Lesson, StepFramesAreValidatedInOneLine) {
  auto parse = [](const std::string& json) { return parseLesson("# x\n\n```voxlab-step\n" + json + "\n```\n", "l.md"); };
  auto bad = [&](const std::string& frames) {
    return errorOf([&] { parse("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"frames\":" + frames + "}"); });
  };
  const Lesson lesson = parse("{\"technique\":\"vct-grid\",\"stage\":\"composite\",\"frames\":{\"count\":4,"
                              "\"animate\":[\"light.0.elevation=90:60\",\"cone.aperture=30:60\"]}}");
  ASSERT_EQ(lesson.steps.size(), 1u);
  EXPECT_EQ(lesson.steps[0].frameCount, 4);
  ASSERT_EQ(lesson.steps[0].frameAnimations.size(), 2u);
  EXPECT_EQ(lesson.steps[0].frameAnimations[0].name, "light.0.elevation");
  EXPECT_EQ(lesson.steps[0].frameAnimations[0].from, 90.0);
  EXPECT_EQ(lesson.steps[0].frameAnimations[1].to, 60.0);
  // The values the viewer and `voxlab run --frames` give frame 2 of 4: a third of the way back.
  const FrameValues f = animatedFrame(createTechnique("vct-grid")->defaultParams(), lesson.steps[0].frameAnimations, 1, 4);
  ASSERT_EQ(f.params.size(), 2u);
  EXPECT_DOUBLE_EQ(f.params[0].second, 80.0);
  EXPECT_DOUBLE_EQ(f.params[1].second, 40.0);
  EXPECT_EQ(bad("3"), "l.md:3: 'frames' must be {\"count\": N, \"animate\": [\"NAME=FROM:TO\", ...]}");
  EXPECT_EQ(bad("{\"count\":4,\"animate\":[\"cone.aperture=30:60\"],\"loop\":true}"),
            "l.md:3: frames: unknown key 'loop'; valid keys: count, animate");
  EXPECT_EQ(bad("{\"count\":1,\"animate\":[\"cone.aperture=30:60\"]}").rfind("l.md:3: frames: 'count' must be 2..64, got 1", 0), 0u);
  EXPECT_EQ(bad("{\"count\":0,\"animate\":[\"cone.aperture=30:60\"]}").rfind("l.md:3: frames: 'count' must be 2..64", 0), 0u);
  EXPECT_NE(bad("{\"count\":4}").find("l.md:3: frames: 'animate' must be a non-empty list"), std::string::npos);
  EXPECT_NE(bad("{\"count\":4,\"animate\":[3]}").find("l.md:3: frames: every 'animate' entry must be a string"),
            std::string::npos);
  std::string e = bad("{\"count\":4,\"animate\":[\"cone.nope=1:2\"]}");
  EXPECT_EQ(e.rfind("l.md:3: frames: unknown parameter 'cone.nope'", 0), 0u) << e;
  e = bad("{\"count\":4,\"animate\":[\"cone.aperture=30\"]}");
  EXPECT_NE(e.find("l.md:3: frames: --animate 'cone.aperture=30': expected NAME=FROM:TO"), std::string::npos) << e;
  e = bad("{\"count\":4,\"animate\":[\"light.0.elevation=0:200\"]}");
  EXPECT_EQ(e.rfind("l.md:3: frames: ", 0), 0u) << e;
  EXPECT_NE(e.find("light.0.elevation"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;
}

TEST(Script, ParsesVerbsCommentsAndEnvironment) {
  setenv("VOXLAB_TEST_DIR", "/tmp/x", 1);
  auto a = parseScript("# comment\nstage mipmap\n\nlevel 2 # trailing\nscreenshot ${VOXLAB_TEST_DIR}/a.png\n", "s.txt");
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0].verb, "stage");
  EXPECT_EQ(a[1].line, 4);
  EXPECT_EQ(a[2].args.at(0), "/tmp/x/a.png");
  EXPECT_EQ(errorOf([] { parseScript("stage\n", "s.txt"); }).rfind("s.txt:1: wrong arguments; usage: stage ID", 0), 0u);
  EXPECT_EQ(errorOf([] { parseScript("run\nsoar away\n", "s.txt"); }).rfind("s.txt:2: unknown action 'soar'", 0), 0u);
  EXPECT_NE(errorOf([] { parseScript("lesson ${VOXLAB_NOT_SET_ANYWHERE}\n", "s.txt"); }).find("VOXLAB_NOT_SET_ANYWHERE is not set"),
            std::string::npos);
}

TEST(Presenter, NarrativeBlocksJoinParagraphsAndDropMarkup) {
  const std::string md =
      "## Step 2: the **dominant** axis\n"
      "A triangle seen `edge-on`\n"
      "covers *no* pixels; see [the paper](https://example.org/p.pdf).\n"
      "\n"
      "1. `classify`: per triangle\n"
      "   its axis;\n"
      "- a bullet\n"
      "```glsl\n"
      "# not a heading inside code\n"
      "```\n"
      "Last words.\n";
  auto b = narrativeBlocks(md);
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b[0].kind, NarrativeBlock::Kind::Heading);
  EXPECT_EQ(b[0].text, "Step 2: the dominant axis");
  EXPECT_EQ(b[1].kind, NarrativeBlock::Kind::Paragraph);
  EXPECT_EQ(b[1].text, "A triangle seen edge-on covers no pixels; see the paper.");
  EXPECT_EQ(b[2].kind, NarrativeBlock::Kind::Item);
  EXPECT_EQ(b[2].text, "1. classify: per triangle its axis;");
  EXPECT_EQ(b[3].text, "\xE2\x80\xA2 a bullet");
  EXPECT_EQ(b[4].kind, NarrativeBlock::Kind::Paragraph);
  EXPECT_EQ(b[4].text, "Last words.");
}

// A vector parameter (NAME.x/.y/.z declared, NAME not): "X,Y,Z" sets the three components, all
// or none; a wrong count or a bad component is one line naming the form. Through the ParamSet
// (--set, lessons, scripts) and the StepCursor's text setter alike.
TEST(Params, VectorParameterSetsItsThreeComponents) {
  auto t = createTechnique("clipmap");
  ParamSet p = t->defaultParams();
  EXPECT_EQ(p.vectorComponents("clipmap.path-step"),
            (std::vector<std::string>{"clipmap.path-step.x", "clipmap.path-step.y", "clipmap.path-step.z"}));
  EXPECT_TRUE(p.vectorComponents("clipmap.path-step.x").empty());  // a parameter itself
  EXPECT_TRUE(p.vectorComponents("clipmap.path").empty());         // no components
  p.setAssignment("clipmap.path-step=1.5,0,-2");
  EXPECT_EQ(p.value("clipmap.path-step.x"), 1.5);
  EXPECT_EQ(p.value("clipmap.path-step.y"), 0.0);
  EXPECT_EQ(p.value("clipmap.path-step.z"), -2.0);
  const std::string form = "; valid: three comma-separated values X,Y,Z (e.g. clipmap.path-step=1.5,0,-2) for "
                           "clipmap.path-step.x/.y/.z, each -1e+06..1e+06 m";
  EXPECT_EQ(errorOf([&] { p.setAssignment("clipmap.path-step=1,2"); }),
            "parameter clipmap.path-step='1,2' has 2 values" + form);
  EXPECT_EQ(errorOf([&] { p.setAssignment("clipmap.path-step=1"); }), "parameter clipmap.path-step='1' has 1 value" + form);
  EXPECT_EQ(errorOf([&] { p.setAssignment("clipmap.path-step=1,2,3,4"); }),
            "parameter clipmap.path-step='1,2,3,4' has 4 values" + form);
  EXPECT_EQ(errorOf([&] { p.setAssignment("clipmap.path-step=1,up,3"); }),
            "parameter clipmap.path-step='1,up,3': 'up' is not a valid clipmap.path-step.y" + form);
  EXPECT_EQ(errorOf([&] { p.setAssignment("clipmap.path-step=1,2,"); }),
            "parameter clipmap.path-step='1,2,': '' is not a valid clipmap.path-step.z" + form);
  EXPECT_EQ(errorOf([&] { p.setAssignment("clipmap.path-step=0,0,2e6"); }),
            "parameter clipmap.path-step='0,0,2e6': '2e6' is not a valid clipmap.path-step.z" + form);
  // Nothing was set by the refused assignments.
  EXPECT_EQ(p.value("clipmap.path-step.x"), 1.5);
  EXPECT_EQ(p.value("clipmap.path-step.z"), -2.0);
  // An unknown name stays an unknown parameter.
  EXPECT_NE(errorOf([&] { p.setAssignment("clipmap.path-stride=1,2,3"); }).find("unknown parameter 'clipmap.path-stride'"),
            std::string::npos);
}

TEST(Reproduce, ListsOnlyChangedParameters) {
  auto t = createTechnique("vct-grid");
  ParamSet d = t->defaultParams(), p = d;
  EXPECT_EQ(reproduceCommand("vct-grid", "cornell-box", p, d, 512, 512, 0, ""),
            "voxlab run --technique vct-grid --scene cornell-box --size 512x512 --out out");
  p.setText("cone.count", "4");
  p.setText("mipmap.mode", "isotropic");
  EXPECT_EQ(reproduceCommand("vct-grid", "my scene.gltf", p, d, 640, 360, 1, "mipmap"),
            "voxlab run --technique vct-grid --scene 'my scene.gltf' --set cone.count=4 --set mipmap.mode=isotropic "
            "--size 640x360 --camera 1 --until mipmap --out out");
  Camera c;
  c.position = {0.25f, 1.0f, 3.5f};
  c.forward = glm::normalize(glm::vec3(0.0f, 0.0f, -1.0f));
  EXPECT_EQ(reproduceCommand("vct-grid", "cornell-box", d, d, 512, 512, 0, "", "o", &c),
            "voxlab run --technique vct-grid --scene cornell-box --size 512x512 --look-from 0.25,1,3.5 "
            "--look-at 0.25,1,2.5 --out o");
}

// The free camera a copied command names must be the camera the viewer used: rebuilt from the
// Cornell box camera's position and a point one metre along its view, it matches to float precision.
TEST(Reproduce, FreeCameraRebuildsTheSceneCamera) {
  Scene scene = loadScene(resolveScenePath("cornell-box"));
  const Camera& c = scene.cameras.at(0);
  RunRequest r;
  r.lookFrom = c.position;
  r.lookAt = c.position + c.forward;
  Camera f = requestCamera(scene, r);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(f.position[i], c.position[i], 1e-6f);
    EXPECT_NEAR(f.forward[i], c.forward[i], 1e-6f);
    EXPECT_NEAR(f.up[i], c.up[i], 1e-6f);
  }
  EXPECT_EQ(f.yfov, c.yfov);
  r.lookAt = c.position;
  EXPECT_THROW(requestCamera(scene, r), Error);
}

// Orbit keeps the distance to the target and looks at it; look turns about the eye; fly moves
// along the camera's own axes; neither rolls the camera (up stays in the forward/+y plane).
TEST(CameraMoves, OrbitLookFly) {
  Camera c;
  c.position = {0.0f, 1.0f, 4.0f};
  c.forward = {0.0f, 0.0f, -1.0f};
  const glm::vec3 target(0.0f, 1.0f, 0.0f);
  Camera o = orbitCamera(c, target, 90.0f, 0.0f);
  EXPECT_NEAR(glm::length(o.position - target), 4.0f, 1e-5f);
  EXPECT_NEAR(glm::dot(o.forward, glm::normalize(target - o.position)), 1.0f, 1e-5f);
  EXPECT_NEAR(std::abs(o.position.x), 4.0f, 1e-4f);  // a quarter turn about +y
  Camera o4 = c;
  for (int i = 0; i < 4; ++i) o4 = orbitCamera(o4, target, 90.0f, 0.0f);
  EXPECT_NEAR(glm::length(o4.position - c.position), 0.0f, 1e-4f);
  Camera up = orbitCamera(c, target, 0.0f, 200.0f);  // clamped at 85 degrees
  EXPECT_NEAR(std::asin(-up.forward.y), glm::radians(85.0f), 1e-4f);
  EXPECT_NEAR(glm::length(up.position - target), 4.0f, 1e-5f);
  // A camera looking past the target turns rigidly: there and back again is where it started.
  Camera off = lookCamera(c, 20.0f, -10.0f);
  Camera back = orbitCamera(orbitCamera(off, target, 35.0f, 12.0f), target, 0.0f, -12.0f);
  back = orbitCamera(back, target, -35.0f, 0.0f);
  EXPECT_NEAR(glm::length(back.position - off.position), 0.0f, 1e-4f);
  EXPECT_NEAR(glm::length(back.forward - off.forward), 0.0f, 1e-4f);

  Camera l = lookCamera(c, 0.0f, 30.0f);
  EXPECT_EQ(l.position, c.position);
  EXPECT_NEAR(l.forward.y, std::sin(glm::radians(30.0f)), 1e-5f);
  EXPECT_NEAR(glm::dot(glm::cross(l.forward, l.up), glm::vec3(0, 1, 0)), 0.0f, 1e-5f);  // no roll
  Camera l2 = lookCamera(lookCamera(c, 40.0f, 0.0f), -40.0f, 0.0f);
  EXPECT_NEAR(glm::length(l2.forward - c.forward), 0.0f, 1e-5f);

  Camera f = flyCamera(c, 0.5f, 0.25f, 2.0f);
  EXPECT_NEAR(glm::length(f.position - glm::vec3(0.5f, 1.25f, 2.0f)), 0.0f, 1e-5f);
  EXPECT_EQ(f.forward, c.forward);
}

// An image is shown whole whatever slice axis the volume views left selected (a regression: images
// were once shown as their x = 0 column); a volume's default slice is the middle one.
TEST(Display, ImagesShowWholeVolumesTheirMiddleSlice) {
  LevelData img;
  img.size = {64, 32, 1};
  img.channels = 4;
  img.values.assign(64 * 32 * 4, 0.5f);
  for (int axis = 0; axis < 3; ++axis) {
    SliceImage s = mapSlice(img, Semantic::Color, sliceToShow(img, SliceSpec{axis, -1}), DisplaySettings{});
    EXPECT_EQ(s.width, 64) << "axis " << axis;
    EXPECT_EQ(s.height, 32) << "axis " << axis;
  }
  LevelData vol;
  vol.size = {8, 16, 4};
  EXPECT_EQ(sliceToShow(vol, SliceSpec{0, -1}).index, 4);
  EXPECT_EQ(sliceToShow(vol, SliceSpec{1, -1}).index, 8);
  EXPECT_EQ(sliceToShow(vol, SliceSpec{2, -1}).index, 2);
  EXPECT_EQ(sliceToShow(vol, SliceSpec{2, 3}).index, 3);
}

TEST(Display, SlicesVolumesAlongEachAxis) {
  LevelData v;
  v.size = {4, 3, 2};
  v.channels = 1;
  for (int z = 0; z < 2; ++z)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) v.values.push_back(float(x + 10 * y + 100 * z));
  // z slice: top-left pixel is (x 0, y top, z index).
  SliceSpec s{2, 1};
  EXPECT_EQ(sliceExtent(v, s), glm::ivec2(4, 3));
  EXPECT_EQ(sliceTexel(v, s, 0, 0), glm::ivec3(0, 2, 1));
  SliceSpec sx{0, 3};
  EXPECT_EQ(sliceExtent(v, sx), glm::ivec2(2, 3));
  EXPECT_EQ(sliceTexel(v, sx, 1, 2), glm::ivec3(3, 0, 1));
  SliceSpec sy{1, 5};  // index clamped to the extent
  EXPECT_EQ(sliceTexel(v, sy, 2, 0), glm::ivec3(2, 2, 1));
  // Scalar semantic: channel 0 in grey when selected, normalised over the level.
  DisplaySettings ds;
  ds.channel = 0;
  SliceImage img = mapSlice(v, Semantic::Scalar, s, ds);
  ASSERT_EQ(img.rgba.size(), 4u * 3 * 4);
  EXPECT_EQ(img.rgba[(2 * 4 + 0) * 4], uint8_t(std::lround(100.0 / 123.0 * 255)));  // bottom-left of z=1: 100
  // Colour with exposure 2 saturates 0.5 to white.
  LevelData c;
  c.size = {1, 1, 1};
  c.channels = 4;
  c.values = {0.5f, 0.25f, 0.0f, 1.0f};
  DisplaySettings e;
  e.exposure = 2.0f;
  SliceImage ci = mapSlice(c, Semantic::Color, SliceSpec{}, e);
  EXPECT_EQ(ci.rgba[0], 255);
  EXPECT_EQ(ci.rgba[2], 0);
}

// Cone sample records as a tracer appends them: (cone, distance, sample alpha, accumulated opacity).
CapturedOutput coneSampleRecords(const std::vector<std::array<float, 4>>& samples) {
  CapturedOutput out;
  out.desc.semantic = Semantic::ConeSamples;
  out.desc.layout.stride = sizeof(gpu::ConeSample);
  for (const auto& [cone, dist, alpha, opacity] : samples) {
    gpu::ConeSample s{};
    s.info = glm::vec4(cone, dist, dist * 2.0f, alpha);
    s.accumulated = glm::vec4(1.0f, 1.0f, 1.0f, opacity);
    size_t at = out.records.size();
    out.records.resize(at + sizeof s);
    std::memcpy(&out.records[at], &s, sizeof s);
    ++out.recordCount;
  }
  return out;
}

TEST(ConeSamples, DecodesPerConeSortedByDistance) {
  // Appended out of order: decoding groups by cone and sorts by distance.
  auto cones = decodeConeSamples(coneSampleRecords({{1, 0.2f, 0.375f, 0.5f}, {0, 0.1f, 0.1f, 0.1f}, {1, 0.1f, 0.2f, 0.2f}}));
  ASSERT_EQ(cones.size(), 2u);
  EXPECT_EQ(cones[1].cone, 1);
  EXPECT_FLOAT_EQ(cones[1].opacity[0], 0.2f);
  EXPECT_FLOAT_EQ(cones[1].lod[1], 0.4f);
  EXPECT_FLOAT_EQ(cones[1].sampleAlpha[1], 0.375f);
  EXPECT_FLOAT_EQ(cones[0].luminance[0], 1.0f);
}

// The check must pass correct front-to-back compositing and fail every wrong rule that still
// never decreases (the old check, "opacity non-decreasing", held for all of them).
TEST(ConeSamples, CheckFailsOnCompositingThatIsNotFrontToBack) {
  const float alphas[4] = {0.3f, 0.5f, 0.2f, 0.6f};
  auto series = [&](auto rule) {
    std::vector<std::array<float, 4>> s;
    float op = 0.0f;
    for (int i = 0; i < 4; ++i) {
      op = rule(op, alphas[i], i);
      s.push_back({0.0f, 0.1f * float(i + 1), alphas[i], op});
    }
    return decodeConeSamples(coneSampleRecords(s));
  };
  auto frontToBack = [](float op, float a, int) { return op + (1.0f - op) * a; };
  EXPECT_EQ(checkFrontToBackCompositing(series(frontToBack)), "");
  // Adding alphas (clamped), taking the maximum, recording one sample late: all never decrease.
  auto sum = [](float op, float a, int) { return std::min(1.0f, op + a); };
  auto maximum = [](float op, float a, int) { return std::max(op, a); };
  // The opacity recorded before the sample is composited (one sample late).
  float late = 0.0f;
  auto recordedBefore = [&](float op, float a, int) {
    const float shown = late;
    late = late + (1.0f - late) * a;
    return shown + 0.0f * op;
  };
  for (auto cones : {series(sum), series(maximum), series(recordedBefore)}) {
    bool rising = true;
    for (size_t i = 1; i < cones[0].opacity.size(); ++i) rising = rising && cones[0].opacity[i] >= cones[0].opacity[i - 1];
    EXPECT_TRUE(rising);
    const std::string e = checkFrontToBackCompositing(cones);
    EXPECT_NE(e.find("cone 0, sample"), std::string::npos) << e;
    EXPECT_NE(e.find("composited front to back"), std::string::npos) << e;
  }
  // A falling opacity, an alpha outside 0..1, a repeated distance.
  std::string e = checkFrontToBackCompositing(decodeConeSamples(coneSampleRecords({{1, 0.1f, 0.5f, 0.5f}, {1, 0.2f, 0.0f, 0.4f}})));
  EXPECT_NE(e.find("cone 1, sample 1"), std::string::npos) << e;
  e = checkFrontToBackCompositing(decodeConeSamples(coneSampleRecords({{2, 0.1f, 1.5f, 1.0f}})));
  EXPECT_NE(e.find("sample alpha 1.5 is outside 0..1"), std::string::npos) << e;
  e = checkFrontToBackCompositing(decodeConeSamples(coneSampleRecords({{3, 0.1f, 0.5f, 0.5f}, {3, 0.1f, 0.0f, 0.5f}})));
  EXPECT_NE(e.find("distance does not increase"), std::string::npos) << e;
  // One sample off by more than the tolerance, one by rounding only (measured 3e-8; see cone_samples.h).
  e = checkFrontToBackCompositing(decodeConeSamples(coneSampleRecords({{4, 0.1f, 0.5f, 0.5f + 3 * kCompositingTolerance}})));
  EXPECT_NE(e.find("cone 4, sample 0"), std::string::npos) << e;
  EXPECT_EQ(checkFrontToBackCompositing(decodeConeSamples(coneSampleRecords({{4, 0.1f, 0.5f, 0.5f + 2e-7f}}))), "");
}

// Every cone-sample probe record any technique declares (found from the declarations: a screen
// probe on a stage with a ConeSamples probe-record output), recorded on the Cornell box floor and
// a wall, passes the compositing check; prints the largest rounding deviation it saw.
TEST(ConeSamples, EveryTechniquesRecordsAreCompositedFrontToBack) {
  int checked = 0;
  for (const auto& entry : techniqueRegistry()) {
    auto t = createTechnique(entry.id);
    for (int i = 0; i < t->stageCount(); ++i) {
      const auto& decl = t->decl(i);
      for (const auto& probe : decl.probes) {
        if (probe.space != ProbeSpace::Screen) continue;
        for (const auto& out : decl.outputs) {
          if (!out.probeRecord || out.semantic != Semantic::ConeSamples) continue;
          for (const auto& at : {std::pair<double, double>{0.5, 0.85}, {0.2, 0.4}}) {
            SCOPED_TRACE(entry.id + "/" + t->stage(i).id() + "/" + out.name + " at " + std::to_string(at.first) + ", " +
                         std::to_string(at.second));
            RunRequest r;
            r.technique = entry.id;
            r.width = r.height = 64;
            r.until = t->stage(i).id();
            const ParamSet defaults = t->defaultParams();
            const ParamDesc& px = defaults.desc(probe.x);
            const ParamDesc& py = defaults.desc(probe.y);
            r.sets = {probe.x + "=" + px.format(px.minValue + at.first * (px.maxValue - px.minValue)),
                      probe.y + "=" + py.format(py.minValue + at.second * (py.maxValue - py.minValue))};
            CapturedOutput c = testing_support::capture(testing_support::session(r), t->stage(i).id(), out.name);
            auto cones = decodeConeSamples(c);
            size_t samples = 0;
            double worst = 0.0;
            for (const auto& cone : cones) {
              float before = 0.0f;
              for (size_t k = 0; k < cone.opacity.size(); ++k, ++samples) {
                worst = std::max(worst, double(std::fabs(cone.opacity[k] - (before + (1.0f - before) * cone.sampleAlpha[k]))));
                before = cone.opacity[k];
              }
            }
            EXPECT_GT(samples, 10u);
            EXPECT_EQ(checkFrontToBackCompositing(cones), "");
            std::printf("%s/%s: %zu cones, %zu samples, largest compositing deviation %.3g\n", entry.id.c_str(),
                        out.name.c_str(), cones.size(), samples, worst);
            ++checked;
          }
        }
      }
    }
  }
  EXPECT_GE(checked, 6) << "vct-grid, svo and lrsm record cone samples";
}

// expect-images-differ MIN_FRACTION counts pixels, not bytes, and a single changed byte is far
// below any fraction the scripts ask for.
TEST(ScriptChecks, ImageDifferenceCountsPixelsAndSizes) {
  const int w = 64, h = 32;
  std::vector<uint8_t> a(size_t(w) * h * 3, 40), b = a;
  EXPECT_EQ(imageDifference(a, w, h, b, w, h).differing, 0u);
  b[5] = 41;  // one byte of pixel 1: the check's deliberately wrong input
  ImageDifference d = imageDifference(a, w, h, b, w, h);
  EXPECT_EQ(d.differing, 1u);
  EXPECT_EQ(d.pixels, size_t(w) * h);
  EXPECT_LT(d.fraction(), 0.001);  // 1/2048: fails the smallest MIN_FRACTION used (0.001)
  for (int i = 0; i < w * h / 4; ++i) b[size_t(i) * 3 + 1] = 0;  // a quarter of the pixels, one channel each
  EXPECT_NEAR(imageDifference(a, w, h, b, w, h).fraction(), 0.25, 1e-12);
  // Other size or channel count: different everywhere.
  EXPECT_EQ(imageDifference(a, w, h, std::vector<uint8_t>(size_t(w) * h * 4, 40), w, h).fraction(), 1.0);
  EXPECT_EQ(imageDifference(a, w, h, std::vector<uint8_t>(size_t(h) * w * 3, 40), h, w).fraction(), 1.0);
}

// expect-view-nonempty MIN_FRACTION MIN_SPREAD: content is what is neither background nor frame,
// and a view whose content is one flat colour (a silhouette) fails the spread.
TEST(ScriptChecks, ViewContentNeedsCoverageAndSpread) {
  const uint8_t bg[3] = {28, 28, 33}, frame[3] = {217, 191, 89};
  const int n = 100 * 100;
  std::vector<uint8_t> px(size_t(n) * 4, 255);
  for (int i = 0; i < n; ++i) std::copy(bg, bg + 3, &px[size_t(i) * 4]);
  ViewContent c = viewContent(px, bg, frame);
  EXPECT_EQ(c.content, 0u);
  for (int i = 0; i < 400; ++i) std::copy(frame, frame + 3, &px[size_t(i) * 4]);  // the bounds only
  px[2] = uint8_t(frame[2] + 2);  // within 2 of the frame colour: still frame
  EXPECT_EQ(viewContent(px, bg, frame).content, 0u);
  // A flat silhouette: 30 % of the pixels black (exposure 0), no spread.
  for (int i = 1000; i < 4000; ++i) std::fill(&px[size_t(i) * 4], &px[size_t(i) * 4] + 3, 0);
  c = viewContent(px, bg, frame);
  EXPECT_EQ(c.content, 3000u);
  EXPECT_NEAR(c.fraction(), 0.3, 1e-12);
  EXPECT_LT(c.lumaStdDev, 1e-6);
  // Half of them mid grey: luma 0 and 128 in equal parts, standard deviation 64.
  for (int i = 1000; i < 2500; ++i) std::fill(&px[size_t(i) * 4], &px[size_t(i) * 4] + 3, 128);
  EXPECT_NEAR(viewContent(px, bg, frame).lumaStdDev, 64.0, 1e-9);
}

TEST(Inspect3D, MapVolumeUsesAlphaAsOpacityOrNonEmpty) {
  LevelData L;
  L.size = {2, 1, 1};
  L.channels = 4;
  L.values = {1, 0, 0, 0.5f, 0.3f, 0.3f, 0.3f, 0};
  VolumeRGBA v = mapVolume(L, Semantic::Color, DisplaySettings{});
  ASSERT_EQ(v.rgba.size(), 8u);
  EXPECT_EQ(v.nonEmpty, 1u);
  EXPECT_EQ(v.rgba[0], 255);  // linear 1 -> sRGB 255
  EXPECT_EQ(v.rgba[3], 128);  // alpha 0.5 is the opacity
  EXPECT_EQ(v.rgba[7], 0);    // alpha 0: empty although rgb is not
  // Occupancy: any non-zero channel is an opaque texel.
  VolumeRGBA o = mapVolume(L, Semantic::Occupancy, DisplaySettings{});
  EXPECT_EQ(o.nonEmpty, 2u);
  EXPECT_EQ(o.rgba[3], 255);
  EXPECT_EQ(o.rgba[7], 255);
}

TEST(Inspect3D, OrbitCameraLooksAtItsTarget) {
  OrbitCamera c;
  c.target = {10, 20, 30};
  c.radius = 5;
  c.lookAlong({0, 0, -1});
  EXPECT_NEAR(c.yaw, 0.0f, 1e-5f);
  EXPECT_NEAR(c.pitch, 0.0f, 1e-5f);
  glm::vec4 p = c.projection(1.0f) * c.view() * glm::vec4(c.target, 1.0f);
  EXPECT_NEAR(p.x / p.w, 0.0f, 1e-4f);
  EXPECT_NEAR(p.y / p.w, 0.0f, 1e-4f);
  EXPECT_GT(p.z / p.w, -1.0f);
  EXPECT_LT(p.z / p.w, 1.0f);
  c.rotate(90, 200);  // pitch clamps below 90 degrees
  EXPECT_LT(c.pitch, 1.5f);
  EXPECT_NEAR(glm::length(c.eye() - c.target), c.distance * c.radius, 1e-3f);
}

}  // namespace
}  // namespace voxlab
