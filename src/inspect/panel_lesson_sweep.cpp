// The Lesson tab's sweep plot: a lesson step that declares a sweep (lesson/lesson.h) gets its error
// and time plotted beside the view, the value the view shows ringed. A child `voxlab sweep` (this
// executable) runs the step's sweep request (lessonSweepRequest: the handout's) into a cache folder
// named by its command line, so the viewer stays responsive while it runs and a step seen before
// plots at once; the plot reads the child's sweep.json.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/error.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"
#include "run/sweep.h"

extern char** environ;

namespace voxlab {
namespace {

namespace fs = std::filesystem;

// Loads DIR/sweep.json into the plot's report; false when there is none (yet).
bool loadReport(LessonSweepPlot& plot) {
  std::ifstream in(fs::path(plot.dir) / "sweep.json");
  if (!in) return false;
  try {
    plot.report = nlohmann::json::parse(in);
  } catch (const std::exception& e) {
    plot.status = std::string("sweep.json does not parse: ") + e.what();
    return true;
  }
  plot.status.clear();
  return true;
}

// Starts the child for 'request' unless its folder already holds the report.
void startSweep(LessonSweepPlot& plot, const SweepRequest& request) {
  const std::vector<std::string> args = sweepArguments(request, "DIR");
  std::string key;
  for (const std::string& a : args) key += a + " ";
  if (key == plot.key) return;
  plot.stop();
  plot.status.clear();
  plot.key = key;
  plot.swept = request.params.front().substr(0, request.params.front().find('='));
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016zx", std::hash<std::string>{}(key));
  plot.dir = (fs::temp_directory_path() / "voxlab-sweeps" / hash).string();
  plot.report = nullptr;
  if (loadReport(plot)) return;
  std::error_code ec;
  fs::create_directories(plot.dir, ec);
  std::vector<std::string> argv = {"voxlab", "sweep"};
  for (const std::string& a : sweepArguments(request, plot.dir)) argv.push_back(a);
  std::vector<char*> cargs;
  for (std::string& a : argv) cargs.push_back(a.data());
  cargs.push_back(nullptr);
  const std::string log = (fs::path(plot.dir) / "sweep.log").string();
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, "/proc/self/exe", &files, nullptr, cargs.data(), environ);
  posix_spawn_file_actions_destroy(&files);
  if (rc != 0) {
    plot.status = std::string("could not start voxlab sweep: ") + std::strerror(rc);
    return;
  }
  plot.pid = pid;
  plot.status = "running";
}

// Collects the child when it has ended and loads its report.
void pollSweep(LessonSweepPlot& plot) {
  if (plot.pid <= 0) return;
  int status = 0;
  if (waitpid(plot.pid, &status, WNOHANG) != plot.pid) return;
  plot.pid = 0;
  if (!loadReport(plot))
    plot.status = "voxlab sweep ended without a report (" + (fs::path(plot.dir) / "sweep.log").string() + ")";
}

// The step's sweep, started or polled: what a frame (or a script verb) calls before reading it.
LessonSweepPlot& currentSweep(Viewer& v, const LessonStep& step) {
  startSweep(v.lessonSweep, lessonSweepRequest(step));
  pollSweep(v.lessonSweep);
  return v.lessonSweep;
}

// The run whose swept value the view shows, or -1.
int markedRun(const Viewer& v, const LessonSweepPlot& plot) {
  if (!plot.report.is_object()) return -1;
  const std::string shown = v.currentParamText(plot.swept);
  for (const auto& run : plot.report["runs"])
    if (run["values"].value(plot.swept, std::string()) == shown) return run["index"].get<int>();
  return -1;
}

// One small plot: a number of every run against the swept value (evenly spaced, in the order
// given), the marked run ringed.
void drawPlot(const char* title, const nlohmann::json& report, const char* key, const char* format, int marked,
              float width, float height) {
  const auto& runs = report["runs"];
  std::vector<float> ys;
  float lo = INFINITY, hi = -INFINITY;
  for (const auto& run : runs) {
    const float y = run.contains(key) && run[key].is_number() ? run[key].get<float>() : NAN;
    ys.push_back(y);
    if (std::isfinite(y)) lo = std::min(lo, y), hi = std::max(hi, y);
  }
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  if (lo >= 0 && lo < 0.5f * hi) lo = 0;
  if (hi - lo < 1e-6f) hi = lo + 1e-6f;
  ImGui::BeginGroup();
  ImGui::TextUnformatted(title);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(title, ImVec2(width, height));
  ImDrawList* draw = ImGui::GetWindowDrawList();
  const float left = 44, bottom = 18, top = 6, right = 10;
  const ImVec2 a(origin.x + left, origin.y + top), b(origin.x + width - right, origin.y + height - bottom);
  draw->AddRectFilled(a, b, IM_COL32(30, 30, 34, 255));
  draw->AddRect(a, b, IM_COL32(120, 120, 120, 255));
  char text[32];
  std::snprintf(text, sizeof text, format, hi);
  draw->AddText(ImVec2(origin.x, a.y - 2), IM_COL32(200, 200, 200, 255), text);
  std::snprintf(text, sizeof text, format, lo);
  draw->AddText(ImVec2(origin.x, b.y - 12), IM_COL32(200, 200, 200, 255), text);
  const size_t n = ys.size();
  auto at = [&](size_t i) {
    const float t = n > 1 ? float(i) / float(n - 1) : 0.5f;
    const float x = a.x + 10 + (b.x - a.x - 20) * t;
    return ImVec2(x, b.y - 4 - (b.y - a.y - 8) * (std::isfinite(ys[i]) ? (ys[i] - lo) / (hi - lo) : 0.0f));
  };
  for (size_t i = 0; i + 1 < n; ++i)
    if (std::isfinite(ys[i]) && std::isfinite(ys[i + 1])) draw->AddLine(at(i), at(i + 1), IM_COL32(90, 160, 230, 255), 1.5f);
  for (size_t i = 0; i < n; ++i) {
    const std::string label = runs[i]["values"].begin()->get<std::string>();
    const ImVec2 p = at(i);
    draw->AddText(ImVec2(p.x - 3.5f * float(label.size()), b.y + 2), IM_COL32(200, 200, 200, 255), label.c_str());
    if (!std::isfinite(ys[i])) continue;
    draw->AddCircleFilled(p, 3.5f, IM_COL32(90, 160, 230, 255));
    if (int(i) == marked) draw->AddCircle(p, 8, IM_COL32(255, 220, 80, 255), 0, 2);
  }
  ImGui::EndGroup();
}

}  // namespace

LessonSweepPlot::~LessonSweepPlot() { stop(); }

void LessonSweepPlot::stop() {
  if (pid <= 0) return;
  kill(pid, SIGTERM);
  waitpid(pid, nullptr, 0);
  pid = 0;
}

std::string Viewer::currentParamText(const std::string& name) const {
  const ParamSet& params = cursor->params();
  if (!params.has(name)) return "";
  return params.desc(name).format(params.value(name));
}

void Viewer::drawLessonSweep(const LessonStep& step) {
  LessonSweepPlot& plot = currentSweep(*this, step);
  ImGui::Text("Sweep of %s (%dx%d)", plot.swept.c_str(), kLessonSweepSize, kLessonSweepSize);
  if (plot.status == "running") {
    ImGui::TextDisabled("running voxlab sweep ... (%s)", plot.dir.c_str());
    return;
  }
  if (!plot.status.empty()) {
    ImGui::TextColored(kErrorColour, "%s", plot.status.c_str());
    return;
  }
  const int marked = markedRun(*this, plot);
  const float width = std::max(160.0f, ImGui::GetContentRegionAvail().x * 0.5f - 6);
  const std::string error = plot.report["error"].value("definition", std::string("error")) + " (" +
                            plot.report["error"].value("role", std::string()) + ")";
  drawPlot(error.c_str(), plot.report, "error", "%.3f", marked, width, 130);
  ImGui::SameLine();
  drawPlot("time, all stages (ms)", plot.report, "time_ms", "%.0f", marked, width, 130);
  if (marked >= 0)
    ImGui::TextDisabled("ringed: %s=%s, what the view shows", plot.swept.c_str(), currentParamText(plot.swept).c_str());
  else
    ImGui::TextColored(kWarningColour, "the view shows %s=%s, not one of the sweep's values", plot.swept.c_str(),
                       currentParamText(plot.swept).c_str());
}

// --- Script verbs: the lesson step's sweep -----------------------------------------------------------

namespace {

const LessonStep& sweepStep(Viewer& viewer, const ScriptCall& call) {
  if (viewer.lesson.steps.empty()) call.fail("no lesson is open");
  const LessonStep& step = viewer.lesson.steps[size_t(viewer.lessonStep)];
  if (step.sweep.empty()) call.fail("lesson step " + std::to_string(viewer.lessonStep + 1) + " declares no sweep");
  return step;
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(lesson_sweep, 81,
  {"lesson-sweep-wait", 0, 0, "lesson-sweep-wait (until the step's sweep has its report)",
   [](Viewer& viewer, const ScriptCall& call) {
     LessonSweepPlot& plot = currentSweep(viewer, sweepStep(viewer, call));
     if (plot.status == "running") {
       --viewer.script.next;  // ask again next frame
       return;
     }
     if (!plot.status.empty()) call.fail(plot.status);
     std::printf("lesson sweep of %s: %zu runs (%s)\n", plot.swept.c_str(), plot.report["runs"].size(), plot.dir.c_str());
   }},
  {"expect-lesson-sweep-mark", 1, 1, "expect-lesson-sweep-mark VALUE (the plot rings the run of that value)",
   [](Viewer& viewer, const ScriptCall& call) {
     LessonSweepPlot& plot = currentSweep(viewer, sweepStep(viewer, call));
     if (!plot.status.empty()) call.fail("the sweep has no report: " + plot.status);
     const int marked = markedRun(viewer, plot);
     const std::string got =
         marked < 0 ? "none" : plot.report["runs"][size_t(marked)]["values"][plot.swept].get<std::string>();
     if (got != call.arg(0)) call.fail("the plot rings " + plot.swept + "=" + got + ", expected " + call.arg(0));
   }});

}  // namespace voxlab
