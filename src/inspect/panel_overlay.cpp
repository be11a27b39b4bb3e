// Scene overlays over camera images: the non-empty voxels of a volume level (through their world
// placement) and the volume's bounds, drawn with the live camera.
#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "gpu/shader_library.h"
#include "inspect/viewer_state.h"

namespace voxlab {

std::vector<std::string> Viewer::overlayVolumes() const {
  const Technique& t = cursor->technique();
  std::vector<std::string> names;
  for (int i = 0; i < t.stageCount(); ++i) {
    if (cursor->record(i).state == StageState::NotRun) continue;
    for (const auto& o : t.decl(i).outputs)
      if (o.kind == OutputKind::Volume3D) names.push_back(std::string(t.stage(i).id()) + "/" + o.name);
  }
  return names;
}

void Viewer::drawOverlayControls() {
  ImGui::Checkbox("bounds", &overlayOpt.bounds);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the voxel volume's box in the scene");
  ImGui::SameLine();
  ImGui::Checkbox("voxels", &overlayOpt.voxels);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the non-empty voxels of a volume level over the image");
  if (!overlayOpt.voxels) return;
  auto volumes = overlayVolumes();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(190);
  if (ImGui::BeginCombo("##overlayvolume", overlayVolume.empty() ? "(latest volume)" : overlayVolume.c_str())) {
    for (const auto& v : volumes)
      if (ImGui::Selectable(v.c_str(), v == overlayVolume)) overlayVolume = v, overlayLevel = -1;
    ImGui::EndCombo();
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(80);
  int level = std::max(overlayLevel, 0);
  if (ImGui::SliderInt("level##overlay", &level, 0, std::max(overlayLevelCount - 1, 0))) overlayLevel = level;
  ImGui::Checkbox("x-ray", &overlayOpt.xray);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("draw the edges of every voxel, none hidden by surfaces or other voxels");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  ImGui::SliderFloat("opacity##overlay", &overlayOpt.opacity, 0.1f, 1.0f, "%.2f");
  if (!overlayMsg.empty()) {
    ImGui::SameLine();
    ImGui::TextColored(kWarningColour, "%s", overlayMsg.c_str());
  }
}

void Viewer::updateOverlay() {
  SceneOverlay::Options o = overlayOpt;
  o.bounds = o.bounds || pendingCamera.has_value() || flying || orbiting;  // show where the camera goes
  if (!o.bounds && !o.voxels) {
    overlayKey.clear();
    return;
  }
  if (!overlay) overlay = std::make_unique<SceneOverlay>(*shaders);
  const Technique& t = cursor->technique();
  // The volume: the chosen one, else the latest of a stage up to the selected one.
  auto volumes = overlayVolumes();
  std::string volume = overlayVolume;
  if (std::find(volumes.begin(), volumes.end(), volume) == volumes.end()) {
    volume.clear();
    for (const auto& v : volumes)
      if (t.stageIndex(v.substr(0, v.find('/'))) <= selected || volume.empty()) volume = v;
  }
  // Content: re-read the volume only when the data or the choice changed.
  auto contentKey = [&] {
    return std::to_string(generation) + "|" + volume + "|" + std::to_string(overlayLevel) + "|" + std::to_string(o.voxels);
  };
  if (contentKey() != overlayContentKey) {
    OverlayContent content;
    try {
      content = overlayContent(*cursor, volume, overlayLevel, o.voxels);
      if (content.levelCount > 0) overlayLevel = content.level, overlayLevelCount = content.levelCount;
    } catch (const Error& e) {
      content = OverlayContent{};
      content.box = cursor->board().voxelSpace();
      content.message = e.what();
    }
    overlayMsg = content.message;
    overlay->setCubes(content.cubes);
    overlay->setBox(content.box);
    overlayContentKey = contentKey();  // with the resolved level, so the next frame matches
    overlayKey.clear();
  }
  // The camera the shown images were rendered from (Blackboard::renderedCamera: the G-buffer's,
  // e.g. clipmap's at the end of its path), else the cursor's; while the camera is being moved,
  // the camera it goes to.
  const ViewState& vs = cursor->view();
  const Camera& cam = liveCamera();
  glm::mat4 viewProj = cam.projection(float(vs.width) / float(vs.height)) * cam.view();
  glm::vec3 eye = cam.position;
  const auto& rendered = cursor->board().renderedCamera();
  const bool moving = pendingCamera.has_value() || flying || orbiting;
  if (rendered && !moving) {
    viewProj = rendered->projection * rendered->view;
    eye = rendered->position;
  }
  overlayEye = eye;
  std::string key = overlayContentKey + "|" + std::to_string(o.bounds) + std::to_string(o.xray) + "|" +
                    std::to_string(o.opacity);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) key += "," + std::to_string(viewProj[c][r]);
  if (overlayKey == key) return;
  overlayKey = key;
  try {
    overlayMs = overlay->render(vs.width, vs.height, viewProj, cursor->gpuScene(), o);
  } catch (const ShaderError& e) {
    shaderError = e.what();
    if (scripted) throw;
  }
  frameHeavy = true;
}

}  // namespace voxlab
