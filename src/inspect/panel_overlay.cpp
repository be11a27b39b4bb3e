// Scene overlays over camera images: the non-empty voxels of a volume level (through their world
// placement) and the volume's bounds, drawn with the live camera.
#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "gpu/shader_library.h"
#include "inspect/script_verbs.h"
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
  ImGui::Checkbox("bounds", &overlay.options.bounds);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the voxel volume's box in the scene");
  ImGui::SameLine();
  ImGui::Checkbox("voxels", &overlay.options.voxels);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("the non-empty voxels of a volume level over the image");
  if (!overlay.options.voxels) return;
  auto volumes = overlayVolumes();
  ImGui::SameLine();
  ImGui::SetNextItemWidth(190);
  if (ImGui::BeginCombo("##overlayvolume", overlay.volume.empty() ? "(latest volume)" : overlay.volume.c_str())) {
    for (const auto& v : volumes)
      if (ImGui::Selectable(v.c_str(), v == overlay.volume)) overlay.volume = v, overlay.level = -1;
    ImGui::EndCombo();
  }
  ImGui::SameLine();
  ImGui::SetNextItemWidth(80);
  int level = std::max(overlay.level, 0);
  if (ImGui::SliderInt("level##overlay", &level, 0, std::max(overlay.levelCount - 1, 0))) overlay.level = level;
  ImGui::Checkbox("x-ray", &overlay.options.xray);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("draw the edges of every voxel, none hidden by surfaces or other voxels");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90);
  ImGui::SliderFloat("opacity##overlay", &overlay.options.opacity, 0.1f, 1.0f, "%.2f");
  if (!overlay.message.empty()) {
    ImGui::SameLine();
    ImGui::TextColored(kWarningColour, "%s", overlay.message.c_str());
  }
}

void Viewer::updateOverlay() {
  SceneOverlay::Options o = overlay.options;
  o.bounds = o.bounds || pendingCamera.has_value() || pointer.flying || pointer.orbiting;  // show where the camera goes
  if (!o.bounds && !o.voxels) {
    overlay.key.clear();
    return;
  }
  if (!overlay.renderer) overlay.renderer = std::make_unique<SceneOverlay>(*shaders);
  const Technique& t = cursor->technique();
  // The volume: the chosen one, else the latest of a stage up to the selected one.
  auto volumes = overlayVolumes();
  std::string volume = overlay.volume;
  if (std::find(volumes.begin(), volumes.end(), volume) == volumes.end()) {
    volume.clear();
    for (const auto& v : volumes)
      if (t.stageIndex(v.substr(0, v.find('/'))) <= selected || volume.empty()) volume = v;
  }
  // Content: re-read the volume only when the data or the choice changed.
  auto contentKey = [&] {
    return std::to_string(generation) + "|" + volume + "|" + std::to_string(overlay.level) + "|" + std::to_string(o.voxels);
  };
  if (contentKey() != overlay.contentKey) {
    OverlayContent content;
    try {
      content = overlayContent(*cursor, volume, overlay.level, o.voxels);
      if (content.levelCount > 0) overlay.level = content.level, overlay.levelCount = content.levelCount;
    } catch (const Error& e) {
      content = OverlayContent{};
      content.box = cursor->board().voxelSpace();
      content.message = e.what();
    }
    overlay.message = content.message;
    overlay.renderer->setCubes(content.cubes);
    overlay.renderer->setBox(content.box);
    overlay.contentKey = contentKey();  // with the resolved level, so the next frame matches
    overlay.key.clear();
  }
  // The camera the shown images were rendered from (Blackboard::renderedCamera: the G-buffer's,
  // e.g. clipmap's at the end of its path), else the cursor's; while the camera is being moved,
  // the camera it goes to.
  const ViewState& vs = cursor->view();
  const Camera& cam = liveCamera();
  glm::mat4 viewProj = cam.projection(float(vs.width) / float(vs.height)) * cam.view();
  glm::vec3 eye = cam.position;
  const auto& rendered = cursor->board().renderedCamera();
  const bool moving = pendingCamera.has_value() || pointer.flying || pointer.orbiting;
  if (rendered && !moving) {
    viewProj = rendered->projection * rendered->view;
    eye = rendered->position;
  }
  overlay.eye = eye;
  std::string key = overlay.contentKey + "|" + std::to_string(o.bounds) + std::to_string(o.xray) + "|" +
                    std::to_string(o.opacity);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) key += "," + std::to_string(viewProj[c][r]);
  if (overlay.key == key) return;
  overlay.key = key;
  try {
    overlay.ms = overlay.renderer->render(vs.width, vs.height, viewProj, cursor->gpuScene(), o);
  } catch (const ShaderError& e) {
    shaderError = e.what();
    if (script.active) throw;
  }
  frameHeavy = true;
}

// --- Script verbs: scene overlays -------------------------------------------------------------------

namespace {

void setOverlay(Viewer& viewer, const ScriptCall& call) {
  const bool on = call.onOff(1);
  if (call.arg(0) == "bounds") viewer.overlay.options.bounds = on;
  else if (call.arg(0) == "voxels") viewer.overlay.options.voxels = on;
  else if (call.arg(0) == "xray") viewer.overlay.options.xray = on;
  else call.badArgument("unknown overlay '" + call.arg(0) + "'; valid: bounds, voxels, xray");
}

// The shown camera image with its overlay drawn now; fails when either is missing.
const CapturedOutput& overlaidImage(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  if (!viewer.isCameraImage(viewer.selected, cap))
    call.fail("output " + cap.desc.name + " is not a camera image; overlays apply to those");
  viewer.updateOverlay();
  if (viewer.overlay.key.empty()) call.fail("no overlay is on (overlay bounds|voxels on)");
  return cap;
}

void expectOverlayPixels(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = overlaidImage(viewer, call);
  const size_t n = viewer.overlay.renderer->coveredPixels(), want = size_t(std::max(call.intArg(0), 0));
  std::printf("overlay on %s: %zu pixels covered (need > %zu), %zu voxel cubes, %.1f ms; %s\n", cap.desc.name.c_str(),
              n, want, viewer.overlay.renderer->cubeCount(), viewer.overlay.ms, viewer.overlay.message.c_str());
  if (n <= want) call.fail(std::to_string(n) + " pixels covered, expected more than " + call.arg(0));
}

void expectOverlayCamera(Viewer& viewer, const ScriptCall& call) {
  overlaidImage(viewer, call);
  const glm::vec3 want(call.floatArg(0), call.floatArg(1), call.floatArg(2));
  const glm::vec3 got = viewer.overlay.eye - viewer.liveCamera().position;
  std::printf("overlay camera: the viewer's camera + (%g, %g, %g)\n", got.x, got.y, got.z);
  // Float rounding of P + K D against (P + K D) - P; measured 0 for lesson 08's path (K D = 1 m).
  if (glm::any(glm::greaterThan(glm::abs(got - want), glm::vec3(1e-4f))))
    call.fail("the overlay is drawn from the viewer's camera + (" + std::to_string(got.x) + ", " + std::to_string(got.y) +
              ", " + std::to_string(got.z) + "), expected + (" + call.arg(0) + ", " + call.arg(1) + ", " + call.arg(2) +
              ")");
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(overlay, 50,
  {"overlay", 2, 2, "overlay bounds|voxels|xray on|off (overlays on camera images)", setOverlay},
  {"overlay-volume", 2, 2, "overlay-volume STAGE/OUTPUT LEVEL (the volume whose voxels the overlay shows)",
   [](Viewer& viewer, const ScriptCall& call) {
     const auto volumes = viewer.overlayVolumes();
     if (std::find(volumes.begin(), volumes.end(), call.arg(0)) == volumes.end())
       call.fail("no volume '" + call.arg(0) + "' has run; valid: " + joinNames(volumes));
     viewer.overlay.volume = call.arg(0);
     viewer.overlay.level = call.intArg(1);
   }},
  {"expect-overlay-pixels", 1, 1, "expect-overlay-pixels MIN (the overlay covers more than MIN pixels)",
   expectOverlayPixels},
  {"expect-overlay-camera", 3, 3,
   "expect-overlay-camera DX DY DZ (the overlay is drawn from the camera the images were rendered from: the viewer's "
   "camera moved by DX,DY,DZ metres, within 1e-4)",
   expectOverlayCamera});

}  // namespace voxlab
