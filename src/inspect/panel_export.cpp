// Camera/Export tab: scene cameras, framing and orbit buttons; saving the view, the output's
// files (through its visualiser's writers) and a screenshot; the `voxlab run` line that
// reproduces the state; UI scale and shader reload.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"
#include "core/paths.h"
#include "gpu/shader_library.h"
#include "inspect/figure.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace fs = std::filesystem;

std::string Viewer::saveFigure(const std::string& path) {
  FigureRequest request;
  request.stage = cursor->technique().stage(selected).id();
  request.output = cap.desc.name;
  request.level = std::clamp(view.level, 0, std::max(int(cap.levels.size()) - 1, 0));
  request.slice = view.slice;
  request.display = view.display;
  const std::string svg = figureSvg(outputFigure(*cursor, request), 800);
  std::ofstream file(path, std::ios::binary);
  if (!file || !(file << svg)) throw Error("cannot write '" + path + "' (folder missing or not writable?)");
  return path;
}

void Viewer::drawExport() {
  const Technique& t = cursor->technique();
  ImGui::TextUnformatted("Camera");
  for (size_t i = 0; i < scene->cameras.size(); ++i) {
    std::string label = std::to_string(i) + ": " + scene->cameras[i].name;
    if (ImGui::Selectable(label.c_str(), cameraIndex == int(i))) setCameraIndex(int(i));
  }
  if (ImGui::Button("Frame the scene")) frameScene();
  ImGui::SameLine();
  if (ImGui::Button("Orbit -15")) orbit(-15, 0);
  ImGui::SameLine();
  if (ImGui::Button("Orbit +15")) orbit(15, 0);
  ImGui::Separator();
  ImGui::TextUnformatted("Export");
  char* dir = exportDir;
  ImGui::InputText("folder", exportDir, sizeof exportDir);
  if (ImGui::Button("Save view PNG")) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    std::string path = std::string(dir) + "/view.png";
    try {
      writePng(viewportImage(), path);
      status = "saved " + path;
    } catch (const Error& e) {
      status = e.what();
    }
  }
  ImGui::SameLine();
  if (ImGui::Button("Save output PNG/EXR") && capError.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    try {
      auto e = writeOutputFiles(cap, dir, std::string(t.stage(selected).id()) + "." + cap.desc.name);
      status = "saved " + e["files"].dump();
    } catch (const Error& e) {
      status = e.what();
    }
  }
  if (ImGui::Button("Save figure SVG") && capError.empty()) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    const std::string path = std::string(dir) + "/" + t.stage(selected).id() + "." + cap.desc.name + ".figure.svg";
    try {
      status = "saved " + saveFigure(path);
    } catch (const Error& e) {
      status = e.what();
    }
  }
  ImGui::SameLine();
  if (ImGui::Button("Screenshot")) {
    pendingScreenshot = std::string(dir) + "/screenshot.png";
    screenshotDelay = 1;
  }
  if (ImGui::Button("Copy `voxlab run` command")) {
    copied = commandLine();
    glfwSetClipboardString(window->handle(), copied.c_str());
  }
  if (!copied.empty()) ImGui::TextWrapped("%s", copied.c_str());
  ImGui::Separator();
  ImGui::SetNextItemWidth(120.0f * uiScale);
  float scale = wantUiScale;
  if (ImGui::SliderFloat("UI scale (Ctrl+= / Ctrl+-)", &scale, 0.75f, 3.0f, "%.2f")) wantUiScale = scale;
  if (ImGui::Button("Reload shaders (F5)")) reloadShaders();
  ImGui::SameLine();
  ImGui::Checkbox("watch shader files", &watchShaders);
  ImGui::TextDisabled("%d programs", shaders->programCount());
}

VOXLAB_REGISTER_DETAILS_TAB(exporting, "export", "Camera/Export", 50, nullptr, [](Viewer& v) { v.drawExport(); });

// --- Script verbs: saving, comparing with `voxlab run`, the reproducing command ---------------------

namespace {

// The selected output's file prefix as `voxlab run` names it: STAGE.OUTPUT.
std::string outputPrefix(const Viewer& viewer, const CapturedOutput& cap) {
  return std::string(viewer.cursor->technique().stage(viewer.selected).id()) + "." + cap.desc.name;
}

void saveOutput(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  const std::string prefix = outputPrefix(viewer, cap);
  std::error_code ec;
  fs::create_directories(call.arg(0), ec);
  auto written = writeOutputFiles(cap, call.arg(0), prefix);
  std::printf("saved %s: %s\n", prefix.c_str(), written["files"].dump().c_str());
}

// A buffer's records saved by the viewer and by `voxlab run`: appended records have no fixed
// order, so the sorted record sets are compared.
void compareRecords(const CapturedOutput& cap, const std::string& prefix, const ScriptCall& call) {
  const std::string x = readTextFile(call.arg(0) + "/" + prefix + ".bin"), y = readTextFile(call.arg(1) + "/" + prefix + ".bin");
  const uint32_t stride = std::max<uint32_t>(cap.desc.layout.stride, 1);
  if (x.size() != y.size())
    call.fail(prefix + ": " + std::to_string(x.size() / stride) + " records vs " + std::to_string(y.size() / stride));
  auto records = [&](const std::string& s) {
    std::vector<std::string> r;
    for (size_t i = 0; i + stride <= s.size(); i += stride) r.push_back(s.substr(i, stride));
    std::sort(r.begin(), r.end());
    return r;
  };
  if (records(x) != records(y)) call.fail(prefix + ": record sets differ");
  std::printf("compare-output %s: %zu records identical\n", prefix.c_str(), x.size() / stride);
}

// Every level's EXR saved by the viewer and by `voxlab run`, value by value within TOLERANCE.
void compareLevels(const CapturedOutput& cap, const std::string& prefix, const ScriptCall& call) {
  const double tolerance = call.count() > 2 ? call.floatArg(2) : 0.0;
  const size_t levels = cap.levels.size();
  for (size_t l = 0; l < levels; ++l) {
    const std::string name = prefix + (levels > 1 ? "@" + std::to_string(l) : "") + ".exr";
    LevelData p = readLevelExr(call.arg(0) + "/" + name), q = readLevelExr(call.arg(1) + "/" + name);
    if (p.size != q.size || p.channels != q.channels) call.fail(name + ": sizes or channel counts differ");
    double maxDiff = 0;
    size_t above = 0;
    for (size_t i = 0; i < p.values.size(); ++i) {
      const double d = std::abs(double(p.values[i]) - double(q.values[i]));
      if (!(d <= tolerance)) ++above;
      if (d > maxDiff || std::isnan(d)) maxDiff = d;
    }
    std::printf("compare-output %s: %zu values, max abs diff %g (tolerance %g)\n", name.c_str(), p.values.size(), maxDiff,
                tolerance);
    if (above)
      call.fail(name + ": " + std::to_string(above) + " values differ by more than " + call.arg(call.count() > 2 ? 2 : 0));
  }
}

void compareOutput(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  const std::string prefix = outputPrefix(viewer, cap);
  if (cap.desc.kind == OutputKind::Buffer) compareRecords(cap, prefix, call);
  else compareLevels(cap, prefix, call);
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(exporting, 100,
  {"save-output", 1, 1, "save-output DIR (selected output, files named as voxlab run names them)", saveOutput},
  {"compare-output", 2, 3,
   "compare-output VIEW_DIR RUN_DIR [TOLERANCE] (EXR/bin of the selected output saved by save-output vs voxlab run)",
   compareOutput},
  {"save-figure", 1, 1, "save-figure PATH.svg (the shown output as `voxlab figure` writes it: title, parameters, colour bar, reference)",
   [](Viewer& viewer, const ScriptCall& call) {
     requireShownCapture(viewer, call);
     std::printf("saved figure %s\n", viewer.saveFigure(call.arg(0)).c_str());
   }},
  {"screenshot", 1, 1, "screenshot PATH.png (the window's back buffer)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.pendingScreenshot = call.arg(0);
     viewer.screenshotDelay = 2;  // let ImGui settle one frame after the last change
   }},
  {"copy-command", 0, 0, "copy-command (prints the voxlab run line and copies it)",
   [](Viewer& viewer, const ScriptCall&) {
     viewer.copied = viewer.commandLine();
     glfwSetClipboardString(viewer.window->handle(), viewer.copied.c_str());
     std::printf("command: %s\n", viewer.copied.c_str());
   }});

}  // namespace voxlab
