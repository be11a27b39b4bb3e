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
  if (!capError.empty() || !has3DView() || viewMode == ViewMode::Slice) return false;
  if (!view3d) view3d = std::make_unique<View3D>(*shaders);
  long key[7] = {capKey[0], capKey[1], capKey[2], view.level, view.display.channel, long(view.display.exposure * 1000),
                 long(reinterpret_cast<intptr_t>(scene.get()))};
  bool rebuilt = false;
  if (!std::equal(key, key + 7, content3dKey)) {
    std::copy(key, key + 7, content3dKey);
    // The visualiser fills the view; the orbit frames what it reports.
    view3d->clear();
    VisualiserContext ctx = visualiserContext();
    Content3D c = shownVisualiser()->build3D(ctx, *view3d);
    msg3d = c.message;
    info3d = c.info;
    view3d->setBox(c.lo, c.hi);
    orbit3d.target = 0.5f * (c.lo + c.hi);
    orbit3d.radius = std::max(0.5f * glm::length(c.hi - c.lo), 1e-3f);
    if (orbitScene != scene.get()) {
      orbitScene = scene.get();
      orbit3d.lookAlong(cursor->camera().forward);
    }
    rebuilt = true;
  }
  if (viewMode == ViewMode::Cubes && view3d->cubesOverLimit()) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "%zu cubes would be drawn, over the limit of %zu: pick a coarser level or the 3D view",
                  view3d->cubeCandidates(), View3D::kCubeLimit);
    msg3d = buf;
  } else if (msg3d.find("over the limit") != std::string::npos) {
    msg3d.clear();
  }
  // While dragging, render a quarter of the pixels: the ray march costs per pixel (level 0 of a
  // 128^3 grid took 140-250 ms at 384^2 on llvmpipe); the full size follows on release.
  // Cubes cost per cube in the vertex shader (one thread on llvmpipe: 0.5-0.7 s for 100k), so a
  // drag shows the ray-marched view of the same texels and the cubes come back on release.
  const bool dragging = dragging3d || scriptDragging;
  const int size = dragging ? View3D::kSize / 2 : View3D::kSize;
  const ViewMode mode = dragging && viewMode == ViewMode::Cubes ? ViewMode::Volume : viewMode;
  double rkey[6] = {double(mode), orbit3d.yaw, orbit3d.pitch, orbit3d.distance, double(orbit3d.radius), double(size)};
  if (rebuilt || !std::equal(rkey, rkey + 6, render3dKey)) {
    std::copy(rkey, rkey + 6, render3dKey);
    try {
      render3dMs.push_back(view3d->render(mode, orbit3d, size));
    } catch (const ShaderError& e) {
      shaderError = e.what();
      if (scripted) throw;
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
  float used = float(view3d->lastSize()) / float(View3D::kSize);  // the rendered corner of the texture
  ImGui::Image(reinterpret_cast<ImTextureID>(intptr_t(view3d->texture())), ImVec2(side, side), ImVec2(0, used),
               ImVec2(used, 0));
  ImGuiIO& io = ImGui::GetIO();
  if (ImGui::IsItemHovered()) {
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) dragging3d = true;
    if (io.MouseWheel != 0.0f) orbit3d.distance = std::clamp(orbit3d.distance * std::pow(0.9f, io.MouseWheel), 0.6f, 8.0f);
  }
  if (dragging3d) {
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) dragging3d = false;
    else if (io.MouseDelta.x != 0.0f || io.MouseDelta.y != 0.0f) orbit3d.rotate(-io.MouseDelta.x * 0.4f, io.MouseDelta.y * 0.4f);
  }
  if (!msg3d.empty()) ImGui::TextColored(kWarningColour, "%s", msg3d.c_str());
  ImGui::TextWrapped("%s", info3d.c_str());
  ImGui::TextDisabled("%s view %dx%d, last render %.1f ms; drag to rotate, wheel to zoom", viewModeName(viewMode),
                      view3d->lastSize(), view3d->lastSize(), render3dMs.empty() ? 0.0 : render3dMs.back());
  if (!status.empty()) ImGui::TextDisabled("%s", status.c_str());
}

// --- Script verbs: the 3D view ----------------------------------------------------------------------

namespace {

void setViewMode(Viewer& viewer, const ScriptCall& call) {
  if (call.arg(0) == "slice") viewer.viewMode = ViewMode::Slice;
  else if (call.arg(0) == "3d") viewer.viewMode = ViewMode::Volume;
  else if (call.arg(0) == "cubes") viewer.viewMode = ViewMode::Cubes;
  else call.badArgument("unknown mode '" + call.arg(0) + "'; valid: slice, 3d, cubes");
  if (viewer.viewMode == ViewMode::Slice) return;
  viewer.refreshCapture();
  if (viewer.capError.empty() && !viewer.has3DView())
    call.fail("output " + viewer.cap.desc.name + " (" + kindName(viewer.cap.desc.kind) + ") has no 3D view");
}

void expectViewNonempty(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  if (!viewer.update3D()) call.fail("no 3D view is shown (view-mode 3d|cubes on a volume or a buffer with positions)");
  if (!viewer.msg3d.empty() && viewer.msg3d.find("over the limit") != std::string::npos) call.fail(viewer.msg3d);
  const ViewContent c = viewer.view3d->content();
  const double minFraction = call.floatArg(0), minSpread = call.floatArg(1);
  if (!(minFraction >= 0.0 && minFraction < 1.0)) call.badArgument("MIN_FRACTION must be in 0..1, not " + call.arg(0));
  std::printf("view %s of %s: %zu of %zu pixels show content (%.4f, need > %s), luma spread %.1f (need > %s); %s; "
              "render %.1f ms\n",
              viewModeName(viewer.viewMode), cap.desc.name.c_str(), c.content, c.pixels, c.fraction(), call.arg(0).c_str(),
              c.lumaStdDev, call.arg(1).c_str(), viewer.info3d.c_str(),
              viewer.render3dMs.empty() ? 0.0 : viewer.render3dMs.back());
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
   [](Viewer& viewer, const ScriptCall& call) { viewer.scriptDragging = call.onOff(0); }},
  {"view-orbit", 2, 2, "view-orbit YAW_DEG PITCH_DEG (rotate the 3D view's own camera)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.orbit3d.rotate(call.floatArg(0), call.floatArg(1)); }},
  {"expect-view-nonempty", 2, 2,
   "expect-view-nonempty MIN_FRACTION MIN_SPREAD (more than MIN_FRACTION of the 3D view's pixels are content, not "
   "background or bounds, and their luma standard deviation, 0..255, is more than MIN_SPREAD)",
   expectViewNonempty});

}  // namespace voxlab
