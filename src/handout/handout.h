// Handouts: a lesson as an HTML page a student reads without the program.
//
// `voxlab handout LESSON.md --out DIR` writes DIR/<lesson>.html and its pictures as PNG files in
// DIR/<lesson>/ (step-01.png, ..., thumbnail.png): one page plus a folder of images, linked
// relatively, so DIR can be copied, zipped or served as it is. Files rather than images embedded
// as data: URIs keep the page small (a 512x512 step picture is 100-400 KB of PNG, a third more
// as base64), let a browser load the pictures lazily, and let the index reuse the thumbnails.
//
// Each step is a <section class="step"> with its narrative (Markdown through cmark, the CommonMark
// reference library; raw HTML in a lesson is left out, as cmark does by default), the picture the
// viewer shows at that step (StepRenderer) and a caption: the output address, the parameters that
// differ from the defaults and the `voxlab run` line that reproduces the state.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/html.h"
#include "lesson/lesson.h"

namespace voxlab {

class StepRenderer;
struct StepPicture;

// "" when step 'index' of 'lesson' shows something, else "FILE:LINE: step N's picture ... is blank"
// with the measure (lesson/lesson_check.h: pictureDetail under kBlankPictureDetail).
std::string blankPictureProblem(const Lesson& lesson, int index, const StepPicture& picture);

// CommonMark to HTML (cmark). Inline maths such as $L_o$ stays text.
std::string markdownToHtml(const std::string& markdown);


struct HandoutPage {
  std::string title;
  std::string file;       // the page, relative to the output folder: "<stem>.html"
  std::string thumbnail;  // relative to the output folder
  int steps = 0;
};

// Called before each step is rendered (done = steps finished so far) and once at the end.
using HandoutProgress = std::function<void(int done, int total, const std::string& label)>;

// Renders every step of 'lesson' with 'renderer' and writes the page and its pictures into 'dir'.
// Throws Error "lesson.md:LINE: ..." naming the first step that cannot be rendered or whose
// picture is blank.
HandoutPage writeHandout(const Lesson& lesson, const std::string& dir, StepRenderer& renderer,
                         const HandoutProgress& progress = {});

// DIR/index.html: the lessons in the given order, one line each with its thumbnail (the lesson's
// closing step picture, 192 px wide).
void writeHandoutIndex(const std::vector<HandoutPage>& pages, const std::string& dir);

// The lesson files of a folder in order (file name order: 01-..., 02-...), README.md left out.
std::vector<std::string> lessonFiles(const std::string& folder);

}  // namespace voxlab
