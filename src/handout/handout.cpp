#include "handout/handout.h"

#include <cmark.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "capture/capture.h"
#include "capture/image_files.h"
#include "core/error.h"
#include "handout/step_picture.h"
#include "lesson/lesson_check.h"
#include "run/sweep.h"

namespace voxlab {
namespace fs = std::filesystem;

std::string markdownToHtml(const std::string& markdown) {
  // CMARK_OPT_DEFAULT leaves raw HTML out ("<!-- raw HTML omitted -->") and escapes the rest.
  char* html = cmark_markdown_to_html(markdown.data(), markdown.size(), CMARK_OPT_DEFAULT | CMARK_OPT_SMART);
  std::string out = html ? html : "";
  free(html);
  return out;
}

namespace {

// How long each frame of a step's animation shows: four frames a second, slow enough to follow
// what moves and what flickers.
constexpr int kHandoutFrameMs = 250;

const char* kStyle = R"(
body { font-family: sans-serif; max-width: 56em; margin: 2em auto; padding: 0 1em; line-height: 1.5; color: #222; }
code, pre { font-family: monospace; background: #f3f3f3; }
pre { padding: 0.6em; overflow-x: auto; white-space: pre-wrap; }
section.step { border-top: 1px solid #ccc; margin-top: 2em; padding-top: 0.5em; }
.stepno { color: #777; font-size: 0.9em; }
figure { margin: 1em 0; }
figure img { max-width: 100%; height: auto; image-rendering: pixelated; border: 1px solid #ccc; }
figcaption { font-size: 0.9em; color: #444; }
table.index td { padding: 0.3em 0.8em; vertical-align: middle; }
.sweep iframe { width: 100%; height: 1000px; border: 1px solid #ccc; }
table.index img { width: 160px; height: auto; image-rendering: pixelated; border: 1px solid #ccc; }
)";

std::string pageHead(const std::string& title) {
  return "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>" + htmlEscape(title) +
         "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n";
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw Error("cannot write '" + path + "'");
}

// The lesson's first step narrative repeats the "# title" heading; the page shows it once.
std::string withoutTitle(const std::string& narrative, const std::string& title) {
  std::string first = narrative.substr(0, narrative.find('\n'));
  if (first == "# " + title) return narrative.substr(std::min(narrative.size(), first.size() + 1));
  return narrative;
}

// "0.190, 0.113, 0.136": a number of every run of a sweep, "-" where the run has none.
std::string runNumbers(const nlohmann::json& report, const char* key, const char* format) {
  std::string text;
  for (const auto& run : report["runs"]) {
    char buf[32] = "-";
    if (run.contains(key) && run[key].is_number()) std::snprintf(buf, sizeof buf, format, run[key].get<double>());
    text += (text.empty() ? "" : ", ") + std::string(buf);
  }
  return text;
}

// What a step's sweep measured, in a sentence, and its slider page in a frame.
std::string sweepSection(const LessonStep& step, const nlohmann::json& report, const std::string& page) {
  const auto& param = report["parameters"][0];
  std::string values;
  for (const auto& v : param["values"]) values += (values.empty() ? "" : ", ") + v.get<std::string>();
  std::string html = "<div class=\"sweep\">\n<p>Sweep of <code>" + htmlEscape(param["name"].get<std::string>()) +
                     "</code> over " + htmlEscape(values) + " on " + htmlEscape(report["scene"].get<std::string>()) +
                     " at " + htmlEscape(report["size"].get<std::string>());
  for (const auto& set : report["sets"]) html += ", <code>" + htmlEscape(set.get<std::string>()) + "</code>";
  html += ": " + htmlEscape(report["error"]["definition"].get<std::string>()) + " of <code>" +
          htmlEscape(report["error"]["output"].get<std::string>()) + "</code> " + runNumbers(report, "error", "%.3f") +
          "; CPU time of the stages " + runNumbers(report, "time_ms", "%.0f") +
          " ms. The slider picks a value; <a href=\"" + htmlEscape(page) + "\">open the sweep page</a>.</p>\n";
  html += "<iframe src=\"" + htmlEscape(page) + "\" title=\"sweep of " + htmlEscape(step.sweep) + "\"></iframe>\n</div>\n";
  return html;
}

}  // namespace

std::string blankPictureProblem(const Lesson& lesson, int index, const StepPicture& picture) {
  const double detail = pictureDetail(picture.image);
  if (detail >= kBlankPictureDetail) return "";
  char share[32], needed[32];
  std::snprintf(share, sizeof share, "%.2f %%", 100.0 * detail);
  std::snprintf(needed, sizeof needed, "%.2f %%", 100.0 * kBlankPictureDetail);
  return lesson.path + ":" + std::to_string(lesson.steps[size_t(index)].line) + ": step " + std::to_string(index + 1) +
         "'s picture (" + picture.address + ", " + std::to_string(picture.image.width) + "x" +
         std::to_string(picture.image.height) + ") is blank: " + share +
         " of its pixels stand out from its background, at least " + needed + " needed; show an output, level or slice in "
         "which the step's subject is visible";
}

HandoutPage writeHandout(const Lesson& lesson, const std::string& dir, StepRenderer& renderer,
                         const HandoutProgress& progress) {
  const std::string stem = fs::path(lesson.path).stem().string();
  std::error_code ec;
  fs::create_directories(fs::path(dir) / stem, ec);
  if (ec) throw Error("cannot create output folder '" + (fs::path(dir) / stem).string() + "': " + ec.message());

  for (const auto& e : fs::directory_iterator(fs::path(dir) / stem, ec))  // pictures of an older, longer version
    if (e.path().filename().string().rfind("step-", 0) == 0) fs::remove(e.path(), ec);

  HandoutPage page;
  page.title = lesson.title;
  page.file = stem + ".html";
  page.thumbnail = stem + "/thumbnail.png";
  page.steps = int(lesson.steps.size());

  const int n = int(lesson.steps.size());
  std::string html = pageHead(lesson.title);
  html += "<h1>" + htmlEscape(lesson.title) + "</h1>\n";
  html += "<p class=\"source\">Handout of <code>" + htmlEscape(fs::path(lesson.path).filename().string()) + "</code>, " +
          std::to_string(n) + " steps. Every picture was rendered by <code>voxlab handout</code>; the line under it " +
          "reproduces it with <code>voxlab run</code>.</p>\n";
  // The steps' sweeps first: each run opens a GL context of its own, so the renderer's is closed.
  std::vector<nlohmann::json> sweeps(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const LessonStep& step = lesson.steps[size_t(i)];
    if (step.sweep.empty()) continue;
    renderer.release();
    const std::string folder = (fs::path(dir) / stem / ("sweep-" + std::to_string(i + 1))).string();
    sweeps[size_t(i)] = runSweep(lessonSweepRequest(step), folder, [&](int done, int total, const std::string& label) {
      if (progress) progress(i, n, stem + ": step " + std::to_string(i + 1) + " sweep " + std::to_string(done) + "/" +
                                       std::to_string(total) + " " + label);
    });
    if (sweeps[size_t(i)]["failed_runs"].get<int>() > 0)
      throw Error(lesson.path + ":" + std::to_string(step.line) + ": the sweep " + step.sweep + " has failed runs (" +
                  folder + "/sweep.json)");
  }
  // The steps' frames as animated PNGs, at kLessonFramesSize (a renderer of their own, so the
  // page's renderer is closed first as for a sweep).
  std::vector<std::string> animations(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const LessonStep& step = lesson.steps[size_t(i)];
    if (step.frameCount <= 0) continue;
    if (progress) progress(i, n, stem + ": step " + std::to_string(i + 1) + " " + std::to_string(step.frameCount) + " frames");
    renderer.release();
    StepRenderer framesRenderer(kLessonFramesSize, kLessonFramesSize);
    const std::vector<DisplayImage> images = framesRenderer.renderFrames(lesson, step);
    std::vector<const uint8_t*> pixels;
    for (const DisplayImage& image : images) pixels.push_back(image.rgb.data());
    char name[40];
    std::snprintf(name, sizeof name, "step-%02d-frames.png", i + 1);
    animations[size_t(i)] = stem + "/" + name;
    writeText((fs::path(dir) / animations[size_t(i)]).string(),
              encodeAnimatedPng(images[0].width, images[0].height, 3, pixels, kHandoutFrameMs));
  }
  DisplayImage thumb;  // the closing step's picture: the technique at its best, as the lesson ends
  for (int i = 0; i < n; ++i) {
    const LessonStep& step = lesson.steps[i];
    if (progress) progress(i, n, stem + ": step " + std::to_string(i + 1) + " " + step.stage + "/" + step.output);
    StepPicture pic = renderer.render(lesson, step);
    char name[32];
    std::snprintf(name, sizeof name, "step-%02d.png", i + 1);
    const std::string rel = stem + "/" + name;
    const std::string blank = blankPictureProblem(lesson, i, pic);
    if (!blank.empty()) throw Error(blank);
    writePng(pic.image, (fs::path(dir) / rel).string());
    if (i == n - 1) thumb = pic.image;

    std::string params = "defaults";
    if (!pic.changed.empty()) {
      params.clear();
      for (const auto& c : pic.changed) params += (params.empty() ? "" : ", ") + ("<code>" + htmlEscape(c) + "</code>");
      params += " (the others at their defaults)";
    }
    html += "<section class=\"step\" id=\"step-" + std::to_string(i + 1) + "\">\n";
    html += "<p class=\"stepno\">Step " + std::to_string(i + 1) + " of " + std::to_string(n) + "</p>\n";
    html += markdownToHtml(i == 0 ? withoutTitle(step.narrative, lesson.title) : step.narrative);
    html += "<figure>\n<img src=\"" + htmlEscape(rel) + "\" width=\"" + std::to_string(pic.image.width * pic.displayScale) +
            "\" height=\"" + std::to_string(pic.image.height * pic.displayScale) + "\" alt=\"" + htmlEscape(pic.address) +
            "\">\n<figcaption>\n";
    html += "<p><code>" + htmlEscape(pic.address) + "</code> on " + htmlEscape(step.scene) + ", camera " +
            std::to_string(step.camera) + "; parameters: " + params + ".";
    if (!pic.notes.empty()) html += " " + htmlEscape(pic.notes) + ".";
    html += "</p>\n<pre class=\"run\"><code>" + htmlEscape(pic.command) + "</code></pre>\n</figcaption>\n</figure>\n";
    if (step.frameCount > 0) {
      std::string moving;
      for (const ParamAnimation& a : step.frameAnimations) {
        char range[96];
        std::snprintf(range, sizeof range, " from %g to %g", a.from, a.to);
        moving += (moving.empty() ? "" : ", ") + ("<code>" + htmlEscape(a.name) + "</code>" + range);
      }
      const std::string& run = pic.framesCommand;
      html += "<figure class=\"frames\">\n<img class=\"animation\" src=\"" + htmlEscape(animations[size_t(i)]) +
              "\" alt=\"" + std::to_string(step.frameCount) + " frames of " + htmlEscape(pic.address) + "\">\n" +
              "<figcaption>\n<p>" + std::to_string(step.frameCount) + " frames (an animated PNG, " +
              std::to_string(kHandoutFrameMs) + " ms each, looping) while " + moving + ", at " +
              std::to_string(kLessonFramesSize) + "x" + std::to_string(kLessonFramesSize) +
              "; each frame re-ran only the stages its change invalidates.</p>\n<pre class=\"run\"><code>" +
              htmlEscape(run) + "</code></pre>\n</figcaption>\n</figure>\n";
    }
    if (!step.sweep.empty())
      html += sweepSection(step, sweeps[size_t(i)], stem + "/sweep-" + std::to_string(i + 1) + "/sweep.html");
    html += "</section>\n";
  }
  if (!lesson.epilogue.empty()) html += "<div class=\"epilogue\">\n" + markdownToHtml(lesson.epilogue) + "</div>\n";
  html += "</body>\n</html>\n";
  writePng(shrink(thumb, 192), (fs::path(dir) / page.thumbnail).string());
  writeText((fs::path(dir) / page.file).string(), html);
  if (progress) progress(n, n, stem + ": written " + page.file);
  return page;
}

void writeHandoutIndex(const std::vector<HandoutPage>& pages, const std::string& dir) {
  std::string html = pageHead("voxlab lessons");
  html += "<h1>voxlab lessons</h1>\n<p>Handouts written by <code>voxlab handout --all</code>, one per lesson in "
          "<code>lessons/</code>, in order.</p>\n<table class=\"index\">\n";
  int k = 0;
  for (const auto& p : pages) {
    ++k;
    html += "<tr><td>" + std::to_string(k) + "</td><td><a href=\"" + htmlEscape(p.file) + "\"><img src=\"" +
            htmlEscape(p.thumbnail) + "\" alt=\"" + htmlEscape(p.title) + "\"></a></td><td><a href=\"" +
            htmlEscape(p.file) + "\">" + htmlEscape(p.title) + "</a> (" + std::to_string(p.steps) +
            " steps)</td></tr>\n";
  }
  html += "</table>\n</body>\n</html>\n";
  writeText((fs::path(dir) / "index.html").string(), html);
}

std::vector<std::string> lessonFiles(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder, ec)) {
    const fs::path& p = e.path();
    if (e.is_regular_file() && p.extension() == ".md" && p.filename() != "README.md") files.push_back(p.string());
  }
  if (ec) throw Error("cannot read the lesson folder '" + folder + "': " + ec.message());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace voxlab
