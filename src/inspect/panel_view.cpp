// The view panel: the selected output's 2D view as its visualiser draws it (a slice of a level, a
// point view, ...), the value under the cursor and the picked element, scene overlays and the
// compare view on images, the 3D view switch; clicks probe (every stage with a probe in the
// clicked image's space) or pick, drags orbit or fly the camera on camera images.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"
#include "techniques/common/light_stage.h"

namespace voxlab {

namespace {

// On camera images a left drag orbits the camera (with Shift it turns the light) and a right drag
// flies it (mouse looks, W/A/S/D/Q/E move); a left click probes or picks.
void handleViewMouse(Viewer& v, bool imageHovered, bool cameraImage, const std::vector<ProbeSpace>& probeSpaces) {
  ImGuiIO& io = ImGui::GetIO();
  const ImVec2 m = io.MousePos;
  if (imageHovered && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
    v.pointer.dragging = true;
    v.pointer.orbiting = false;
    v.pointer.dragStart = m;
  }
  if (v.pointer.dragging) {
    if (cameraImage && !v.pointer.orbiting && std::abs(m.x - v.pointer.dragStart.x) + std::abs(m.y - v.pointer.dragStart.y) > 4.0f) {
      v.pointer.orbiting = true;
      v.pointer.turningLight = io.KeyShift;  // Shift + drag turns the light instead of the camera
    }
    if (v.pointer.orbiting && (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f)) {
      if (v.pointer.turningLight) v.turnLight(io.MouseDelta.x * 0.3f, -io.MouseDelta.y * 0.3f);
      else v.orbit(-io.MouseDelta.x * 0.3f, io.MouseDelta.y * 0.3f);
    }
    if (ImGui::IsMouseReleased(ImGuiMouseButton_Left)) {
      v.pointer.dragging = false;
      if (!v.pointer.orbiting && v.pointer.hover) {
        v.pointer.pickTexel = v.pointer.hoverTexel;
        if (!probeSpaces.empty()) v.probeShownAt(v.pointer.hoverTexel, v.view.level);
      }
      v.pointer.orbiting = false;
    }
  }
  if (cameraImage && imageHovered && ImGui::IsMouseClicked(ImGuiMouseButton_Right)) {
    v.pointer.flying = true;
    v.pointer.lastFlyTime = glfwGetTime();
  }
  if (v.pointer.flying) {
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Right)) v.pointer.flying = false;
    else v.handleFly();
  }
}

// Where the probes of the shown image's spaces point, in fractions of the image. Presenter mode
// marks a probe only once it was set (a click, a lesson step): a laser pointer on the default
// pixel of every camera image would point at nothing in particular.
std::vector<ImVec2> probeMarks(const Viewer& v, const std::vector<ProbeSpace>& probeSpaces, bool bare) {
  const Technique& t = v.cursor->technique();
  const CapturedOutput& cap = v.cap;
  std::vector<ImVec2> marks;
  const ParamSet& ps = v.cursor->params();
  const ParamSet defaults = bare ? t.defaultParams() : ParamSet();
  for (ProbeSpace space : probeSpaces)
    for (auto [stage, p] : v.probesFor(space, cap.desc.resourceName())) {
      if (bare) {
        // Set by a click or by the lesson step (a step may point it at the default pixel).
        bool set = false;
        for (const std::string& n : p->paramNames()) set = set || ps.value(n) != defaults.value(n) || v.lessonStepSets(n);
        if (!set) continue;
      }
      if (space != ProbeSpace::Volume) {
        // Stages probing the same pixel share one mark.
        const ImVec2 at(float(ps.value(p->x)), float(ps.value(p->y)));
        if (std::none_of(marks.begin(), marks.end(), [&](const ImVec2& m) { return m.x == at.x && m.y == at.y; }))
          marks.push_back(at);
        continue;
      }
      // A probed cell shows when it lies in the shown slice of the shown level (the inverse of sliceTexel).
      if (!p->level.empty() && ps.getInt(p->level) != v.view.level) continue;
      const LevelData& L = cap.levels.at(std::clamp(v.view.level, 0, int(cap.levels.size()) - 1));
      const SliceSpec sl = sliceToShow(L, v.view.slice);
      const glm::ivec3 c(ps.getInt(p->x), ps.getInt(p->y), ps.getInt(p->z));
      const glm::ivec2 e = sliceExtent(L, sl);
      glm::ivec2 at = sl.axis == 0 ? glm::ivec2(c.z, L.size.y - 1 - c.y) : sl.axis == 1 ? glm::ivec2(c.x, L.size.z - 1 - c.z)
                                                                               : glm::ivec2(c.x, L.size.y - 1 - c.y);
      if (c[sl.axis] == sl.index) marks.emplace_back((at.x + 0.5f) / e.x, (at.y + 0.5f) / e.y);
    }
  return marks;
}

// Under the image: the value under the cursor, the picked element, the camera and the status.
void drawViewCaption(const Viewer& v, const Visualiser& vis, const VisualiserContext& ctx, bool cameraImage,
                     const std::vector<ProbeSpace>& probeSpaces) {
  if (v.pointer.hover) {
    ImGui::TextWrapped("%s", vis.describeElement(ctx, v.pointer.hoverTexel).c_str());
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
  if (v.pointer.pickTexel.x >= 0) {
    std::string picked = vis.describeElement(ctx, v.pointer.pickTexel);
    if (!picked.empty()) ImGui::TextWrapped("picked %s", picked.c_str());
  }
  if (v.pendingCamera) ImGui::TextColored(kWarningColour, "camera moving: the image follows when the stages have re-run");
  if (!v.status.empty()) ImGui::TextDisabled("%s", v.status.c_str());
}

}  // namespace

void Viewer::drawView() {
  probes.marksShown = 0;
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
          pointer.pickTexel = glm::ivec3(-1);
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
  if (has3DView() && bare && view3d.mode != ViewMode::Slice) {
    draw3DView();
    return;
  }
  if (has3DView() && !bare) {
    int mode = int(view3d.mode);
    ImGui::TextUnformatted("view");
    ImGui::SameLine();
    ImGui::RadioButton(d.kind == OutputKind::Buffer ? "points 2D" : "slice", &mode,
                       int(ViewMode::Slice));
    ImGui::SameLine();
    ImGui::RadioButton("3D", &mode, int(ViewMode::Volume));
    ImGui::SameLine();
    ImGui::RadioButton("cubes", &mode, int(ViewMode::Cubes));
    view3d.mode = ViewMode(mode);
    if (view3d.mode != ViewMode::Slice) {
      draw3DView();
      return;
    }
  }

  // Build the displayed image when the data or the view settings changed.
  long key[8] = {capKey[0], capKey[1], capKey[2], view.level, view.slice.axis, view.slice.index, view.display.channel,
                 long(view.display.exposure * 1000)};
  if (!std::equal(key, key + 8, image2d.key)) {
    std::copy(key, key + 8, image2d.key);
    frameHeavy = true;
    image2d.image = vis.image2D(ctx);
    if (image2d.image.width > 0) image2d.texture.upload(image2d.image.width, image2d.image.height, image2d.image.rgba.data());
  }
  if (image2d.image.width == 0) {
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
  float scale = std::min(avail.x / image2d.image.width, avail.y / image2d.image.height);
  ImVec2 size(image2d.image.width * scale, image2d.image.height * scale);
  if (bare) {
    ImVec2 at = ImGui::GetCursorScreenPos();
    ImGui::SetCursorScreenPos(ImVec2(std::floor(at.x + (avail.x - size.x) * 0.5f), std::floor(at.y + (avail.y - size.y) * 0.5f)));
  }
  ImVec2 origin = ImGui::GetCursorScreenPos();
  presenter.imageMin = origin;
  presenter.imageMax = ImVec2(origin.x + size.x, origin.y + size.y);
  if (!drawCompareImage(origin, size)) ImGui::Image(image2d.texture.imgui(), size);
  pointer.hover = false;
  bool imageHovered = ImGui::IsItemHovered();
  ImVec2 m = ImGui::GetIO().MousePos;
  int px = int(std::floor((m.x - origin.x) / scale)), py = int(std::floor((m.y - origin.y) / scale));
  glm::ivec3 element;
  const bool inside = px >= 0 && py >= 0 && px < image2d.image.width && py < image2d.image.height;
  if (imageHovered && !image2d.image.pick.empty()) {
    // The visualiser drew a pick map: the element under the cursor is the one drawn there.
    int id = inside ? image2d.image.pick[size_t(py) * image2d.image.width + px] : -1;
    if (id >= 0) pointer.hover = true, pointer.hoverTexel = glm::ivec3(id, 0, 0);
  } else if (imageHovered && vis.elementAt(ctx, px, py, element)) {
    pointer.hover = true;
    pointer.hoverTexel = element;
  }
  // Camera images: the overlay (voxels, bounds) drawn with the live camera over the image.
  auto* dl = ImGui::GetWindowDrawList();
  if (cameraImage) {
    updateOverlay();
    if (!overlay.key.empty())
      dl->AddImage(reinterpret_cast<ImTextureID>(intptr_t(overlay.renderer->texture())), origin,
                   ImVec2(origin.x + size.x, origin.y + size.y), ImVec2(0, 1), ImVec2(1, 0));
  }
  handleViewMouse(*this, imageHovered, cameraImage, probeSpaces);
  const std::vector<ImVec2> marks = probeMarks(*this, probeSpaces, bare);
  probes.marksShown = int(marks.size());
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
  drawViewCaption(*this, vis, ctx, cameraImage, probeSpaces);
}

DisplayImage Viewer::viewportImage() const {
  DisplayImage img;
  if (view3d.mode != ViewMode::Slice && view3d.renderer && has3DView()) {
    std::vector<uint8_t> px = view3d.renderer->readPixels();  // kSize^2, bottom row first; the render fills a corner
    int n = view3d.renderer->lastSize();
    img.width = img.height = n;
    for (int y = n - 1; y >= 0; --y)
      for (int x = 0; x < n; ++x)
        img.rgb.insert(img.rgb.end(), &px[(size_t(y) * View3D::kSize + x) * 4], &px[(size_t(y) * View3D::kSize + x) * 4] + 3);
    return img;
  }
  img.width = image2d.image.width;
  img.height = image2d.image.height;
  img.rgb.reserve(size_t(img.width) * img.height * 3);
  for (size_t i = 0; i < size_t(img.width) * img.height; ++i)
    img.rgb.insert(img.rgb.end(), &image2d.image.rgba[i * 4], &image2d.image.rgba[i * 4] + 3);
  // The overlay as ImGui draws it over the image (the handout's step pictures blend the same way).
  if (overlay.renderer && !overlay.key.empty() && isCameraImage(selected, cap)) blendOverlay(img, overlay.renderer->readPixels());
  // The compare view side by side: the other image beside it, as the panel draws them.
  if (compare.on && compare.mode == CompareState::Mode::SideBySide && compare.error.empty() && compare.metrics &&
      compare.otherImage.width > 0)
    img = besideImage(img, compare.otherImage);
  return img;
}

// --- Script verbs: what the view shows, the camera, clicks ------------------------------------------

namespace {

void setSlice(Viewer& viewer, const ScriptCall& call) {
  const std::string& axis = call.arg(0);
  if (axis != "x" && axis != "y" && axis != "z") call.badArgument("axis must be x, y or z");
  viewer.view.slice.axis = axis[0] - 'x';
  viewer.view.slice.index = call.intArg(1);
}

// A left click on pixel (X, Y) of the shown 2D view (from its top left), as the mouse does.
void clickView(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  VisualiserContext ctx = viewer.visualiserContext();
  const Visualiser& vis = *viewer.shownVisualiser();
  glm::ivec3 element;
  const int x = call.intArg(0), y = call.intArg(1);
  SliceImage img = vis.image2D(ctx);
  bool found = false;
  if (!img.pick.empty()) {  // a pick map (point views): the element drawn at that pixel
    int id = x >= 0 && y >= 0 && x < img.width && y < img.height ? img.pick[size_t(y) * img.width + x] : -1;
    found = id >= 0;
    element = glm::ivec3(id, 0, 0);
  } else {
    found = vis.elementAt(ctx, x, y, element);
  }
  if (!found) call.fail("nothing of " + cap.desc.name + " is shown at (" + call.arg(0) + ", " + call.arg(1) + ")");
  viewer.pointer.pickTexel = element;
  const int probed = viewer.probeSpacesOfShown().empty() ? 0 : viewer.probeShownAt(element, viewer.view.level);
  std::printf("click %s: %s; %d probe(s) set\n", cap.desc.name.c_str(), vis.describeElement(ctx, element).c_str(), probed);
}

void saveView(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  if (viewer.view3d.mode != ViewMode::Slice) viewer.update3D();
  else if (viewer.isCameraImage(viewer.selected, cap)) viewer.updateOverlay();
  if (cap.desc.kind == OutputKind::Image2D) viewer.updateCompare();
  const std::filesystem::path p(call.arg(0));
  std::error_code ec;
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path(), ec);
  writePng(viewer.viewportImage(), call.arg(0));
  std::printf("saved view %s\n", call.arg(0).c_str());
}

// The shown output's statistics (as the Inspect tab lists them): more than MIN_FRACTION of the
// shown level's texels are non-empty; a buffer must hold at least one record.
void expectShownNonempty(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  const double atLeast = call.floatArg(0);
  const std::string address = std::string(viewer.cursor->technique().stage(viewer.selected).id()) + "/" + cap.desc.name;
  double fraction = 0.0;
  if (cap.desc.kind == OutputKind::Buffer) {
    fraction = cap.recordCount > 0 ? 1.0 : 0.0;
  } else {
    const int level = std::clamp(viewer.view.level, 0, int(cap.levels.size()) - 1);
    const auto& stats = viewer.capStats.at("levels").at(size_t(level));
    fraction = stats.at("non_empty").get<double>() / double(std::max<size_t>(cap.levels[size_t(level)].texelCount(), 1));
  }
  std::printf("shown %s: non-empty fraction %.4f\n", address.c_str(), fraction);
  if (!(fraction > atLeast))
    call.fail(address + ": " + std::to_string(fraction) + " of it is non-empty, expected more than " + call.arg(0));
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(view, 30,
  {"level", 1, 1, "level N", [](Viewer& viewer, const ScriptCall& call) { viewer.view.level = call.intArg(0); }},
  {"slice", 2, 2, "slice x|y|z INDEX", setSlice},
  {"channel", 1, 1, "channel N (-1 = all)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.view.display.channel = std::clamp(call.intArg(0), -1, 3); }},
  {"exposure", 1, 1, "exposure F",
   [](Viewer& viewer, const ScriptCall& call) { viewer.view.display.exposure = call.floatArg(0); }},
  {"camera", 1, 1, "camera N (scene camera bookmark)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.setCameraIndex(call.intArg(0)); }},
  {"orbit", 2, 2, "orbit YAW_DEG PITCH_DEG",
   [](Viewer& viewer, const ScriptCall& call) { viewer.orbit(call.floatArg(0), call.floatArg(1)); }},
  {"frame-scene", 0, 0, "frame-scene", [](Viewer& viewer, const ScriptCall&) { viewer.frameScene(); }},
  {"fly", 3, 3, "fly RIGHT UP FORWARD (move the camera along its axes, metres)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.moveCamera(flyCamera(viewer.liveCamera(), call.floatArg(0), call.floatArg(1), call.floatArg(2)));
   }},
  {"look", 2, 2, "look YAW_DEG PITCH_DEG (turn the camera about its eye)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.moveCamera(lookCamera(viewer.liveCamera(), call.floatArg(0), call.floatArg(1)));
   }},
  {"turn-light", 2, 2, "turn-light AZIMUTH_DEG ELEVATION_DEG (turn the light from where it points, as Shift + drag)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (!viewer.turnLight(call.floatArg(0), call.floatArg(1))) call.fail(viewer.status);
     const auto formatted = viewer.cursor->params().formatted();
     std::printf("light: azimuth %s, elevation %s\n", formatted.at(kLightAzimuth).c_str(),
                 formatted.at(kLightElevation).c_str());
   }},
  {"click", 2, 2,
   "click X Y (left click on pixel X, Y of the shown 2D view, from its top left: picks, and probes every stage with "
   "a probe in that image's space)",
   clickView},
  {"expect-visualiser", 1, 1, "expect-visualiser NAME (the shown output's visualiser)",
   [](Viewer& viewer, const ScriptCall& call) {
     const CapturedOutput& cap = requireShownCapture(viewer, call);
     const std::string got = viewer.shownVisualiser()->name();
     if (got != call.arg(0))
       call.fail("output " + cap.desc.name + " is shown by visualiser '" + got + "', expected '" + call.arg(0) + "'");
     std::printf("output %s (%s, %s): visualiser %s\n", cap.desc.name.c_str(), kindName(cap.desc.kind),
                 semanticName(cap.desc.semantic), got.c_str());
   }},
  {"expect-shown-nonempty", 1, 1,
   "expect-shown-nonempty MIN_FRACTION (the shown output is captured and more than MIN_FRACTION of its shown level is "
   "non-empty, as its statistics count; a buffer: it holds records)",
   expectShownNonempty},
  {"save-view", 1, 1,
   "save-view PATH.png (what the view shows: the image with its overlay, or the 3D view; as Save view PNG)", saveView});

}  // namespace voxlab
