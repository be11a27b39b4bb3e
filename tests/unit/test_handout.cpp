// Handout helpers without GL: Markdown through cmark, HTML escaping, the terminal progress bar,
// the lesson folder's order, and the overlay blend the viewer and the handout share.
#include <gtest/gtest.h>

#include "capture/capture.h"
#include "core/paths.h"
#include "core/progress.h"
#include "handout/handout.h"
#include "handout/step_picture.h"

namespace voxlab {
namespace {

TEST(Handout, MarkdownHeadingsListsCodeAndMathsAsText) {
  std::string html = markdownToHtml(
      "## Step 1: voxelize\n\nA *voxel* list:\n\n- one\n- two\n\n```glsl\nvec3 c = a < b ? x : y;\n```\n\n"
      "Radiance $L_o = L_e + \\int f L_i$ and `voxel.resolution`.\n");
  EXPECT_NE(html.find("<h2>Step 1: voxelize</h2>"), std::string::npos) << html;
  EXPECT_NE(html.find("<em>voxel</em>"), std::string::npos) << html;
  EXPECT_NE(html.find("<ul>\n<li>one</li>\n<li>two</li>\n</ul>"), std::string::npos) << html;
  EXPECT_NE(html.find("<pre><code class=\"language-glsl\">vec3 c = a &lt; b ? x : y;\n</code></pre>"), std::string::npos) << html;
  EXPECT_NE(html.find("$L_o = L_e + \\int f L_i$"), std::string::npos) << html;  // maths stays text
  EXPECT_NE(html.find("<code>voxel.resolution</code>"), std::string::npos) << html;
}

TEST(Handout, MarkdownLeavesRawHtmlOut) {
  std::string html = markdownToHtml("text <script>alert(1)</script> more\n");
  EXPECT_EQ(html.find("<script>"), std::string::npos) << html;
}

TEST(Handout, HtmlEscape) { EXPECT_EQ(htmlEscape("a<b & \"c\">"), "a&lt;b &amp; &quot;c&quot;&gt;"); }

TEST(Handout, ProgressBar) {
  EXPECT_EQ(progressBar(0, 14, 10, "x"), "[..........]  0/14  x");
  EXPECT_EQ(progressBar(7, 14, 10, "x"), "[#####.....]  7/14  x");
  EXPECT_EQ(progressBar(14, 14, 10, "done"), "[##########] 14/14  done");
  EXPECT_EQ(progressBar(20, 14, 10, ""), "[##########] 14/14  ");  // clamped
}

TEST(Handout, LessonFilesInOrderWithoutReadme) {
  auto files = lessonFiles(projectPath("lessons"));
  ASSERT_GE(files.size(), 2u);
  EXPECT_NE(files[0].find("01-"), std::string::npos);
  for (size_t i = 0; i < files.size(); ++i) {
    EXPECT_EQ(files[i].find("README"), std::string::npos);
    if (i) EXPECT_LT(files[i - 1], files[i]);
  }
}

TEST(Handout, OverlayBlendIsSourceAlphaOverTheImage) {
  DisplayImage img;
  img.width = 1;
  img.height = 2;
  img.rgb = {100, 100, 100, 0, 0, 0};  // top row, bottom row
  // Overlay rows bottom first: bottom pixel fully white, top pixel red at half alpha.
  std::vector<uint8_t> over = {255, 255, 255, 255, 255, 0, 0, 128};
  blendOverlay(img, over);
  EXPECT_EQ(img.rgb[0], 178);  // 100 + (255 - 100) * 128/255 = 177.8
  EXPECT_EQ(img.rgb[1], 50);   // 100 + (0 - 100) * 128/255 = 49.8
  EXPECT_EQ(img.rgb[3], 255);
}

}  // namespace
}  // namespace voxlab
