// The 3D view: the shown output's visualiser fills View3D (volume, cubes, points, spheres,
// lines); this panel renders it when anything shown changed, at half size while dragging, and
// turns the view's own orbit camera with the mouse.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "gpu/shader_library.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

bool Viewer::has3DView() const {
  const Visualiser* v = shownVisualiser();
  return v && v->has3D(cap.desc);
}

bool Viewer::update3D() {
  if (!capError.empty() || !has3DView() || view3d.mode == ViewMode::Slice) return false;
  if (!view3d.renderer) view3d.renderer = std::make_unique<View3D>(*shaders);
  long key[7] = {capKey[0], capKey[1], capKey[2], view.level, view.display.channel, long(view.display.exposure * 1000),
                 long(reinterpret_cast<intptr_t>(scene.get()))};
  bool rebuilt = false;
  if (!std::equal(key, key + 7, view3d.contentKey)) {
    std::copy(key, key + 7, view3d.contentKey);
    // The visualiser fills the view; the orbit frames what it reports.
    view3d.renderer->clear();
    VisualiserContext ctx = visualiserContext();
    Content3D c = shownVisualiser()->build3D(ctx, *view3d.renderer);
    view3d.message = c.message;
    view3d.info = c.info;
    view3d.renderer->setBox(c.lo, c.hi);
    view3d.orbit.target = 0.5f * (c.lo + c.hi);
    view3d.orbit.radius = std::max(0.5f * glm::length(c.hi - c.lo), 1e-3f);
    if (view3d.orbitScene != scene.get()) {
      view3d.orbitScene = scene.get();
      view3d.orbit.lookAlong(cursor->camera().forward);
    }
    rebuilt = true;
  }
  if (view3d.mode == ViewMode::Cubes && view3d.renderer->cubesOverLimit()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu cubes would be drawn, over the limit of %zu: pick a coarser level or the 3D view",
                  view3d.renderer->cubeCandidates(), View3D::kCubeLimit);
    view3d.message = buf;
  } else if (view3d.message.find("over the limit") != std::string::npos) {
    view3d.message.clear();
  }
  // While dragging, render a quarter of the pixels: the ray march costs per pixel (level 0 of a
  // 128^3 grid took 140-250 ms at 384^2 on llvmpipe); the full size follows on release.
  // Cubes cost per cube in the vertex shader (one thread on llvmpipe: 0.5-0.7 s for 100k), so a
  // drag shows the ray-marched view of the same texels and the cubes come back on release.
  const bool dragged = view3d.dragging || view3d.scriptDragging;
  const int size = dragged ? View3D::kSize / 2 : View3D::kSize;
  const ViewMode mode = dragged && view3d.mode == ViewMode::Cubes ? ViewMode::Volume : view3d.mode;
  double rkey[6] = {double(mode), view3d.orbit.yaw, view3d.orbit.pitch, view3d.orbit.distance, double(view3d.orbit.radius), double(size)};
  if (rebuilt || !std::equal(rkey, rkey + 6, view3d.renderKey)) {
    std::copy(rkey, rkey + 6, view3d.renderKey);
    try {
      view3d.renderMs.push_back(view3d.renderer->render(mode, view3d.orbit, size));
    } catch (const ShaderError& e) {
      shaderError = e.what();
      if (script.active) throw;
    }
    frameHeavy = true;
  }
  return true;
}

void Viewer::draw3DView() {
  if (!update3D()) return;
  ImVec2 avail = ImGui::GetContentRegionAvail();
  avail.y -= 70;
  float side = std::max(64.0f, std::min(avail.x, avail.y));
  float used = float(view3d.renderer->lastSize()) / float(View3D::kSize);  // the rendered corner of the texture
  ImGui::Image(reinterpret_cast<ImTextureID>(intptr_t(view3d.renderer->texture())), ImVec2(side, side), ImVec2(0, used),
               ImVec2(used, 0));
  ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsItemHovered()) {
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) view3d.dragging = true;
    if (io.MouseWheel != 0.0f) view3d.orbit.distance = std::clamp(view3d.orbit.distance * std::pow(0.9f, io.MouseWheel), 0.6f, 8.0f);
  }
  if (view3d.dragging) {
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) view3d.dragging = false;
    else if (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f) view3d.orbit.rotate(-io.MouseDelta.x * 0.4f, io.MouseDelta.y * 0.4f);
  }
  if (!view3d.message.empty()) ImGui::TextColored(kWarningColour, "%s", view3d.message.c_str());
  ImGui::TextWrapped("%s", view3d.info.c_str());
  ImGui::TextDisabled("%s view %dx%d, last render %.1f ms; drag to rotate, wheel to zoom", viewModeName(view3d.mode),
                      view3d.renderer->lastSize(), view3d.renderer->lastSize(), view3d.renderMs.empty() ? 0.0 : view3d.renderMs.back());
  if (!status.empty()) ImGui::TextDisabled("%s", status.c_str());
}

// --- Script verbs: the 3D view ----------------------------------------------------------------------

namespace {

void setViewMode(Viewer& viewer, const ScriptCall& call) {
  if (call.arg(0) == "slice") viewer.view3d.mode = ViewMode::Slice;
  else if (call.arg(0) == "3d") viewer.view3d.mode = ViewMode::Volume;
  else if (call.arg(0) == "cubes") viewer.view3d.mode = ViewMode::Cubes;
  else call.badArgument("unknown mode '" + call.arg(0) + "'; valid: slice, 3d, cubes");
  if (viewer.view3d.mode == ViewMode::Slice) return;
  viewer.refreshCapture();
  if (viewer.capError.empty() && !viewer.has3DView())
    call.fail("output " + viewer.cap.desc.name + " (" + kindName(viewer.cap.desc.kind) + ") has no 3D view");
}

void expectViewNonempty(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  if (!viewer.update3D()) call.fail("no 3D view is shown (view-mode 3d|cubes on a volume or a buffer with positions)");
  if (!viewer.view3d.message.empty() && viewer.view3d.message.find("over the limit") != std::string::npos) call.fail(viewer.view3d.message);
  const ViewContent c = viewer.view3d.renderer->content();
  const double minFraction = call.floatArg(0), minSpread = call.floatArg(1);
  if (!(minFraction >= 0.0 && minFraction < 1.0)) call.badArgument("MIN_FRACTION must be in 0..1, not " + call.arg(0));
  std::printf("view %s of %s: %zu of %zu pixels show content (%.4f, need > %s), luma spread %.1f (need > %s); %s; "
              "render %.1f ms\n",
              viewModeName(viewer.view3d.mode), cap.desc.name.c_str(), c.content, c.pixels, c.fraction(), call.arg(0).c_str(),
              c.lumaStdDev, call.arg(1).c_str(), viewer.view3d.info.c_str(),
              viewer.view3d.renderMs.empty() ? 0.0 : viewer.view3d.renderMs.back());
  if (!(c.fraction() > minFraction))
    call.fail(std::to_string(c.fraction()) + " of the view shows content, expected more than " + call.arg(0));
  if (!(c.lumaStdDev > minSpread))
    call.fail("the content is flat: luma standard deviation " + std::to_string(c.lumaStdDev) +
              " of 255, expected more than " + call.arg(1));
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(view3d, 40,
  {"view-mode", 1, 1, "view-mode slice|3d|cubes (3D views of volumes and of buffers with positions)", setViewMode},
  {"view-dragging", 1, 1, "view-dragging on|off (render the 3D view as while the mouse drags it: half size)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.view3d.scriptDragging = call.onOff(0); }},
  {"view-orbit", 2, 2, "view-orbit YAW_DEG PITCH_DEG (rotate the 3D view's own camera)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.view3d.orbit.rotate(call.floatArg(0), call.floatArg(1)); }},
  {"expect-view-nonempty", 2, 2,
   "expect-view-nonempty MIN_FRACTION MIN_SPREAD (more than MIN_FRACTION of the 3D view's pixels are content, not "
   "background or bounds, and their luma standard deviation, 0..255, is more than MIN_SPREAD)",
   expectViewNonempty});

}  // namespace voxlab
