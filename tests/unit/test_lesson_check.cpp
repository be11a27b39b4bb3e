// The lesson check's text rules (src/lesson/lesson_check.h): each rule fails on a lesson that
// breaks it and passes on one that keeps it; the blank-picture measure; the viewer's keys.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/paths.h"
#include "lesson/lesson.h"
#include "lesson/lesson_check.h"

namespace voxlab {
namespace {

const char* kStep = "```voxlab-step\n{\"technique\": \"vct-grid\", \"stage\": \"mipmap\"}\n```\n";

// The problems of a lesson whose steps' narratives are 'narratives' (one block after each) and
// whose epilogue is 'epilogue'; the lesson lives in lessons/ so that links resolve as a shipped one's.
std::vector<std::string> problemsOf(const std::vector<std::string>& narratives, const std::string& epilogue = "") {
  std::string text = "# Title\n\n";
  for (const auto& n : narratives) text += n + "\n\n" + kStep + "\n";
  text += epilogue;
  Lesson lesson = parseLesson(text, projectPath("lessons/test.md"));
  return lessonTextProblems(lesson, text);
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + "\n";
  return s;
}

TEST(LessonCheck, HeadingsFollowTheStepBlocks) {
  EXPECT_TRUE(problemsOf({"## Step 1: a", "## Step 2: b"}).empty());
  auto p = problemsOf({"## Step 1: a", "## Step 3: b"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("heading \"Step 3\" is step 2 of 2"), std::string::npos) << p[0];
  p = problemsOf({"## Step 1: a", "## Step 2b: b"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("\"Step 2b\""), std::string::npos);
  p = problemsOf({"## Step 1: a", "more text, no heading"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("step 2 has no \"## Step 2: title\" heading"), std::string::npos) << p[0];
  p = problemsOf({"## Step 1: a\n\n## Step 1: again"});
  ASSERT_FALSE(p.empty());
  EXPECT_NE(joined(p).find("second \"## Step\" heading"), std::string::npos) << joined(p);
}

TEST(LessonCheck, NamedStepsExist) {
  EXPECT_TRUE(problemsOf({"## Step 1: a", "## Step 2: b\n\nas in step 1"}).empty());
  auto p = problemsOf({"## Step 1: a", "## Step 2: b\n\nas steps 1-3 show"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("names step 3, but the lesson has steps 1..2"), std::string::npos) << p[0];
  EXPECT_TRUE(problemsOf({"## Step 1: a\n\nsee `--set step 9`"}).empty()) << "code spans are not prose";
  EXPECT_TRUE(problemsOf({"## Step 1: a\n\nas lesson 01, step 15 measures"}).empty()) << "another lesson's step";
}

TEST(LessonCheck, NamedFilesExist) {
  EXPECT_TRUE(problemsOf({"## Step 1: see `shaders/common/voxelize.*.glsl` and `src/techniques/`"}).empty());
  auto p = problemsOf({"## Step 1: see `shaders/vct_grid/voxelize.*.glsl`"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("`shaders/vct_grid/voxelize.*.glsl` is not in the repository"), std::string::npos) << p[0];
  EXPECT_TRUE(problemsOf({"## Step 1: [the viewer](../docs/viewer.md#presenter)"}).empty());
  p = problemsOf({"## Step 1: [notes](../docs/no-such-page.md)"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("link target ../docs/no-such-page.md does not exist"), std::string::npos) << p[0];
  p = problemsOf({"## Step 1: the note (../../shared/guide/techniques/svo.md) says more"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("../../shared/guide/techniques/svo.md lies outside the repository"), std::string::npos) << p[0];
}

TEST(LessonCheck, NamedOutputsExist) {
  EXPECT_TRUE(problemsOf({"## Step 1: `mipmap/radiance` and `lpv/gi/cascade-blend`, a ratio `n/d`"}).empty());
  auto p = problemsOf({"## Step 1: `mipmap/radiance-sparkle`"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("radiance-sparkle"), std::string::npos) << p[0];
  p = problemsOf({"## Step 1: `lpv/no-such-stage/light`"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("lpv has no stage no-such-stage"), std::string::npos) << p[0];
}

TEST(LessonCheck, NamedKeysAreTheViewers) {
  EXPECT_TRUE(problemsOf({"## Step 1: press F5, key I, then Page Down; the key trick"}).empty());
  auto p = problemsOf({"## Step 1: press F7"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("the viewer has no key F7"), std::string::npos) << p[0];
  p = problemsOf({"## Step 1: press Enter"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
}

TEST(LessonCheck, NoPrivateSourceNumbering) {
  auto p = problemsOf({"## Step 1: as in seed 000, section 4.5"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("\"seed\""), std::string::npos);
  EXPECT_TRUE(problemsOf({"## Step 1: as in Gomes' thesis, section 4.5"}).empty());
}

TEST(LessonCheck, ProblemsNameTheirLine) {
  auto p = problemsOf({"## Step 1: a\n\nline four names `src/none.cpp`"});
  ASSERT_EQ(p.size(), 1u) << joined(p);
  EXPECT_NE(p[0].find("lessons/test.md:5:"), std::string::npos) << p[0];
}

// Every letter, function and named key a lesson may name is one the viewer's sources handle.
TEST(LessonCheck, ViewerKeyNamesAreHandledByTheViewer) {
  std::string sources;
  for (const char* f : {"src/inspect/viewer.cpp", "src/inspect/panel_presenter.cpp", "src/inspect/panel_view.cpp"})
    sources += readTextFile(projectPath(f));
  for (std::string key : viewerKeyNames()) {
    std::string token;
    if (key == "Shift") token = "KeyShift";
    else if (key == "Ctrl") token = "KeyCtrl";
    else if (key.size() == 1 && key[0] >= '2' && key[0] <= '8') token = "GLFW_KEY_1";  // the range 1..9
    else {
      for (char& c : key) c = c == ' ' ? '_' : char(std::toupper(static_cast<unsigned char>(c)));
      token = "GLFW_KEY_" + key;
    }
    EXPECT_NE(sources.find(token), std::string::npos) << key << ": no " << token << " in the viewer's sources";
  }
}

DisplayImage uniform(int w, int h, uint8_t v) {
  DisplayImage d;
  d.width = w, d.height = h;
  d.rgb.assign(size_t(w) * h * 3, v);
  return d;
}

TEST(LessonCheck, PictureDetail) {
  EXPECT_EQ(pictureDetail(uniform(2, 2, 255)), 0.0);
  DisplayImage slice = uniform(32, 32, 10);  // one lit texel in a 32x32 slice: shown on purpose
  slice.rgb[(16 * 32 + 16) * 3] = 250;
  EXPECT_NEAR(pictureDetail(slice), 1.0 / 1024.0, 1e-12);
  EXPECT_GE(pictureDetail(slice), kBlankPictureDetail);
  DisplayImage points = uniform(512, 512, 24);  // forty 2x2-pixel points on a 512x512 page: blank
  for (int k = 0; k < 40; ++k)
    for (int d = 0; d < 4; ++d) points.rgb[(size_t(100 + 8 * k + d / 2) * 512 + 100 + 8 * k + d % 2) * 3 + 1] = 200;
  EXPECT_LT(pictureDetail(points), kBlankPictureDetail);
  DisplayImage noise = uniform(8, 8, 0);  // a small gradient is all detail
  for (size_t i = 0; i < noise.rgb.size(); ++i) noise.rgb[i] = uint8_t(i * 4 % 256);
  EXPECT_GT(pictureDetail(noise), 0.5);
}

}  // namespace
}  // namespace voxlab
