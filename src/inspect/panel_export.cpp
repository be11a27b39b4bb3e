// Camera/Export tab: scene cameras, framing and orbit buttons; saving the view, the output's
// files (through its visualiser's writers) and a screenshot; the `voxlab run` line that
// reproduces the state; UI scale and shader reload.
#include <filesystem>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/error.h"
#include "gpu/shader_library.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace fs = std::filesystem;

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

}  // namespace voxlab
