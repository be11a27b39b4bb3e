// The view panel: the selected output's 2D view as its visualiser draws it (a slice of a level, a
// point view, ...), the value under the cursor and the picked element, scene overlays and the
// compare view on images, the 3D view switch; clicks probe (every stage with a probe in the
// clicked image's space) or pick, drags orbit or fly the camera on camera images.
#include <algorithm>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "inspect/viewer_state.h"

namespace voxlab {

void Viewer::drawView() {
  const Technique& t = cursor->technique();
  const StageRecord& rec = cursor->record(selected);
  const auto& outs = t.decl(selected).outputs;
  // Presenter mode: the image alone, as large as the window allows, centred; no controls.
  const bool bare = presenter.on;
  if (!bare) ImGui::Text("%s / %s", t.id().c_str(), t.stage(selected).title());
  if (!outs.empty() && !bare) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(200);
    if (ImGui::BeginCombo("output", outs[outputIndex].name.c_str())) {
      for (size_t k = 0; k < outs.size(); ++k)
        if (ImGui::Selectable(outs[k].name.c_str(), int(k) == outputIndex)) {
          outputIndex = int(k);
          view.level = 0;
          pickTexel = glm::ivec3(-1);
        }
      ImGui::EndCombo();
    }
  }
  if (rec.state == StageState::Stale && !bare) ImGui::TextColored(kWarningColour, "stale: showing the last run's data");
  if (!capError.empty()) {
    ImGui::TextWrapped("%s", capError.c_str());
    return;
  }
  const OutputDesc& d = cap.desc;
  const Visualiser& vis = *shownVisualiser();
  VisualiserContext ctx = visualiserContext();
  if (!bare)
    ImGui::TextDisabled("%s, %s, %s: %s", kindName(d.kind), semanticName(d.semantic), cap.format.c_str(), d.help.c_str());
  if (has3DView() && bare && viewMode != ViewMode::Slice) {
    draw3DView();
    return;
  }
  if (has3DView() && !bare) {
    int mode = int(viewMode);
    ImGui::TextUnformatted("view");
    ImGui::SameLine();
    ImGui::RadioButton(d.kind == OutputKind::Buffer ? "points 2D" : "slice", &mode,
                       int(ViewMode::Slice));
    ImGui::SameLine();
    ImGui::RadioButton("3D", &mode, int(ViewMode::Volume));
    ImGui::SameLine();
    ImGui::RadioButton("cubes", &mode, int(ViewMode::Cubes));
    viewMode = ViewMode(mode);
    if (viewMode != ViewMode::Slice) {
      draw3DView();
      return;
    }
  }

  // Build the displayed image when the data or the view settings changed.
  long key[8] = {capKey[0], capKey[1], capKey[2], view.level, view.slice.axis, view.slice.index, view.display.channel,
                 long(view.display.exposure * 1000)};
  if (!std::equal(key, key + 8, texKey)) {
    std::copy(key, key + 8, texKey);
    frameHeavy = true;
    viewImage = vis.image2D(ctx);
    if (viewImage.width > 0) viewTex.upload(viewImage.width, viewImage.height, viewImage.rgba.data());
  }
  if (viewImage.width == 0) {
    ImGui::TextUnformatted(vis.caption(ctx).c_str());
    return;
  }
  const bool cameraImage = isCameraImage(selected, cap);
  const std::vector<ProbeSpace> probeSpaces = probeSpacesOfShown();
  if (cameraImage && !bare) drawOverlayControls();
  if (d.kind == OutputKind::Image2D && !bare) drawCompareControls();

  // Fit the image into the panel, keeping its aspect; nearest filtering shows voxels as squares.
  ImVec2 avail = ImGui::GetContentRegionAvail();
  if (!bare) avail.y -= 60;
  if (compare.on && compare.mode == CompareState::Mode::SideBySide) avail.x *= 0.5f;
  float scale = std::min(avail.x / viewImage.width, avail.y / viewImage.height);
  ImVec2 size(viewImage.width * scale, viewImage.height * scale);
  if (bare) {
    ImVec2 at = ImGui::GetCursorScreenPos();
    ImGui::SetCursorScreenPos(ImVec2(std::floor(at.x + (avail.x - size.x) * 0.5f), std::floor(at.y + (avail.y - size.y) * 0.5f)));
  }
  ImVec2 origin = ImGui::GetCursorScreenPos();
  presenter.imageMin = origin;
  presenter.imageMax = ImVec2(origin.x + size.x, origin.y + size.y);
  if (!drawCompareImage(origin, size)) ImGui::Image(viewTex.imgui(), size);
  hover = false;
  bool imageHovered = ImGui::IsItemHovered();
  ImVec2 m = ImGui::GetIO().MousePos;
  int px = int(std::floor((m.x - origin.x) / scale)), py = int(std::floor((m.y - origin.y) / scale));
  glm::ivec3 element;
  const bool inside = px >= 0 && py >= 0 && px < viewImage.width && py < viewImage.height;
  if (imageHovered && !viewImage.pick.empty()) {
    // The visualiser drew a pick map: the element under the cursor is the one drawn there.
    int id = inside ? viewImage.pick[size_t(py) * viewImage.width + px] : -1;
    if (id >= 0) hover = true, hoverTexel = glm::ivec3(id, 0, 0);
  } else if (imageHovered && vis.elementAt(ctx, px, py, element)) {
    hover = true;
    hoverTexel = element;
  }
  // Camera images: the overlay (voxels, bounds) drawn with the live camera over the image.
  auto* dl = ImGui::GetWindowDrawList();
  if (cameraImage) {
    updateOverlay();
    if (!overlayKey.empty())
      dl->AddImage(reinterpret_cast<ImTextureID>(intptr_t(overlay->texture())), origin,
                   ImVec2(origin.x + size.x, origin.y + size.y), ImVec2(0, 1), ImVec2(1, 0));
  }
  // On camera images a left drag orbits the camera (with Shift it turns the light) and a right drag flies it (mouse looks,
  // W/A/S/D/Q/E move); a left click probes or picks.
  ImGuiIO& io = ImGui::GetIO();
  if (imageHovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    dragging = true;
    orbiting = false;
    dragStart = m;
  }
  if (dragging) {
    if (cameraImage && !orbiting && std::abs(m.x - dragStart.x) + std::abs(m.y - dragStart.y) > 4.0f) {
      orbiting = true;
      turningLight = io.KeyShift;  // Shift + drag turns the light instead of the camera
    }
    if (orbiting && (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f)) {
      if (turningLight) turnLight(io.MouseDelta.x * 0.3f, -io.MouseDelta.y * 0.3f);
      else orbit(-io.MouseDelta.x * 0.3f, io.MouseDelta.y * 0.3f);
    }
    if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
      dragging = false;
      if (!orbiting && hover) {
        pickTexel = hoverTexel;
        if (!probeSpaces.empty()) probeShownAt(hoverTexel, view.level);
      }
      orbiting = false;
    }
  }
  if (cameraImage && imageHovered && ImGui::IsMouseClicked(ImGuiMouseButton_Right)) {
    flying = true;
    lastFlyTime = glfwGetTime();
  }
  if (flying) {
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Right)) flying = false;
    else handleFly();
  }
  // Mark where the probes of the shown image's spaces point (in fractions of the image).
  std::vector<ImVec2> marks;
  const ParamSet& ps = cursor->params();
  const ParamSet defaults = bare ? t.defaultParams() : ParamSet();
  for (ProbeSpace space : probeSpaces)
    for (auto [stage, p] : probesFor(space, d.resourceName())) {
      // Presenter mode marks a probe only once it was set (a click, a lesson step): a laser pointer
      // on the default pixel of every camera image would point at nothing in particular.
      if (bare) {
        bool set = false;
        for (const std::string& n : p->paramNames()) set = set || ps.value(n) != defaults.value(n);
        if (!set) continue;
      }
      if (space != ProbeSpace::Volume) {
        marks.emplace_back(float(ps.value(p->x)), float(ps.value(p->y)));
        continue;
      }
      // A probed cell shows when it lies in the shown slice of the shown level (the inverse of sliceTexel).
      if (!p->level.empty() && ps.getInt(p->level) != view.level) continue;
      const LevelData& L = cap.levels.at(std::clamp(view.level, 0, int(cap.levels.size()) - 1));
      const SliceSpec sl = sliceToShow(L, view.slice);
      const glm::ivec3 c(ps.getInt(p->x), ps.getInt(p->y), ps.getInt(p->z));
      const glm::ivec2 e = sliceExtent(L, sl);
      glm::ivec2 at = sl.axis == 0 ? glm::ivec2(c.z, L.size.y - 1 - c.y) : sl.axis == 1 ? glm::ivec2(c.x, L.size.z - 1 - c.z)
                                                                               : glm::ivec2(c.x, L.size.y - 1 - c.y);
      if (c[sl.axis] == sl.index) marks.emplace_back((at.x + 0.5f) / e.x, (at.y + 0.5f) / e.y);
    }
  for (const ImVec2& f : marks) {
    float qx = origin.x + f.x * size.x, qy = origin.y + f.y * size.y;
    if (bare) {
      drawLaserPointer(dl, ImVec2(qx, qy), size);
      continue;
    }
    dl->AddCircle(ImVec2(qx, qy), 6.0f, IM_COL32(255, 60, 200, 255), 12, 2.0f);
    dl->AddLine(ImVec2(qx - 10, qy), ImVec2(qx + 10, qy), IM_COL32(255, 60, 200, 255));
    dl->AddLine(ImVec2(qx, qy - 10), ImVec2(qx, qy + 10), IM_COL32(255, 60, 200, 255));
  }

  if (bare) return;
  // Value under the cursor and the picked element.
  if (hover) {
    ImGui::TextWrapped("%s", vis.describeElement(ctx, hoverTexel).c_str());
  } else {
    std::string caption = vis.caption(ctx);
    const char* click = probeSpaces.empty() ? "pick" : "probe";
    if (!caption.empty())
      ImGui::TextUnformatted(caption.c_str());
    else if (cameraImage)
      ImGui::TextDisabled("hover for values; click to %s; left drag orbits, right drag + W/A/S/D/Q/E flies", click);
    else
      ImGui::TextDisabled("hover for values; click to %s", click);
  }
  if (pickTexel.x >= 0) {
    std::string picked = vis.describeElement(ctx, pickTexel);
    if (!picked.empty()) ImGui::TextWrapped("picked %s", picked.c_str());
  }
  if (pendingCamera) ImGui::TextColored(kWarningColour, "camera moving: the image follows when the stages have re-run");
  if (!status.empty()) ImGui::TextDisabled("%s", status.c_str());
}

DisplayImage Viewer::viewportImage() const {
  DisplayImage img;
  if (viewMode != ViewMode::Slice && view3d && has3DView()) {
    std::vector<uint8_t> px = view3d->readPixels();  // kSize^2, bottom row first; the render fills a corner
    int n = view3d->lastSize();
    img.width = img.height = n;
    for (int y = n - 1; y >= 0; --y)
      for (int x = 0; x < n; ++x)
        img.rgb.insert(img.rgb.end(), &px[(size_t(y) * View3D::kSize + x) * 4], &px[(size_t(y) * View3D::kSize + x) * 4] + 3);
    return img;
  }
  img.width = viewImage.width;
  img.height = viewImage.height;
  img.rgb.reserve(size_t(img.width) * img.height * 3);
  for (size_t i = 0; i < size_t(img.width) * img.height; ++i)
    img.rgb.insert(img.rgb.end(), &viewImage.rgba[i * 4], &viewImage.rgba[i * 4] + 3);
  // The overlay as ImGui draws it over the image (the handout's step pictures blend the same way).
  if (overlay && !overlayKey.empty() && isCameraImage(selected, cap)) blendOverlay(img, overlay->readPixels());
  return img;
}

}  // namespace voxlab
