// The compare view: the shown image next to another image (another image output, a snapshot of an
// output kept earlier, e.g. before a parameter change, or an EXR / PNG file such as a reference
// render) as side by side, a split with a slider, or the difference in false colour; with the
// metrics `voxlab compare` reports (reference/image_metrics.h: the shown image is A, the other B,
// both as linear RGB from the first three channels, top row first).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/paths.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"
#include "reference/image_io.h"

namespace voxlab {

namespace {

// Level 0 of an image output as the image tools read its EXR: channels 0..2 (the last one repeated
// when there are fewer), top row first.
reference::Image toReferenceImage(const LevelData& L) {
  reference::Image img(L.size.x, L.size.y);
  for (int y = 0; y < L.size.y; ++y)
    for (int x = 0; x < L.size.x; ++x)
      for (int c = 0; c < 3; ++c) img.at(x, L.size.y - 1 - y)[c] = L.at(x, y, 0, std::min(c, L.channels - 1));
  return img;
}

LevelData fromReferenceImage(const reference::Image& img) {
  LevelData L;
  L.size = {img.width, img.height, 1};
  L.channels = 3;
  L.values.resize(img.rgb.size());
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) L.values[(size_t(img.height - 1 - y) * img.width + x) * 3 + c] = img.at(x, y)[c];
  return L;
}

const char* kModeNames[] = {"side by side", "split", "difference"};

}  // namespace

std::vector<std::string> Viewer::imageOutputs() const {
  const Technique& t = cursor->technique();
  std::vector<std::string> names;
  for (int i = 0; i < t.stageCount(); ++i) {
    if (cursor->record(i).state == StageState::NotRun) continue;
    for (const auto& o : t.decl(i).outputs)
      if (o.kind == OutputKind::Image2D) names.push_back(std::string(t.stage(i).id()) + "/" + o.name);
  }
  return names;
}

std::optional<CapturedOutput> Viewer::compareOther(std::string& label, std::string& error) {
  try {
    switch (compare.source) {
      case CompareState::Source::Output: {
        if (compare.other.empty()) throw Error("pick an image output to compare with");
        size_t slash = compare.other.find('/');
        auto [stage, desc] = cursor->technique().findOutput(compare.other.substr(0, slash), compare.other.substr(slash + 1));
        if (cursor->record(stage).state == StageState::NotRun) throw Error(compare.other + " has not run yet");
        if (!cursor->outputHeld(stage, desc->name))  // an output on demand: the demand now holds it
          throw Error(runQueuedThrough(stage) ? "computing " + compare.other + " ..."
                                              : compare.other + " was not computed by the last run: press Run to here (R)");
        label = compare.other;
        return captureOutput(cursor->board(), *desc);
      }
      case CompareState::Source::Snapshot:
        if (!compare.snapshot) throw Error("no snapshot kept yet: Keep snapshot stores the shown output");
        label = "snapshot of " + compare.snapshotLabel;
        return compare.snapshot;
      case CompareState::Source::File: {
        CapturedOutput c;
        c.desc = cap.desc;  // shown as the shown output is
        c.format = "file";
        c.levels.push_back(fromReferenceImage(reference::readImage(compare.file)));
        label = compare.file;
        return c;
      }
    }
  } catch (const Error& e) {
    error = e.what();
  }
  return std::nullopt;
}

void Viewer::updateCompare() {
  if (!compare.on || cap.levels.empty()) return;
  char key[900];
  std::snprintf(key, sizeof key, "%ld|%ld|%ld|%d|%s|%s|%s|%d|%g|%d", capKey[0], capKey[1], capKey[2], int(compare.source),
                compare.other.c_str(), compare.file, compare.snapshotLabel.c_str(), view.display.channel,
                double(view.display.exposure), int(compare.snapshot.has_value()));
  if (compare.key == key) return;
  compare.key = key;
  frameHeavy = true;
  compare.error.clear();
  compare.metrics.reset();
  std::optional<CapturedOutput> other = compareOther(compare.otherLabel, compare.error);
  if (!other) return;
  if (other->levels.empty()) {
    compare.error = compare.otherLabel + " has no image";
    return;
  }
  const LevelData& a = cap.levels[0];
  const LevelData& b = other->levels[0];
  try {
    reference::Image ia = toReferenceImage(a), ib = toReferenceImage(b);
    compare.metrics = reference::computeMetrics(ia, ib);  // throws when the sizes differ
    reference::Image err = reference::errorImage(ia, ib, 0.0f, &compare.errorScale);
    std::vector<uint8_t> rgba(err.pixelCount() * 4, 255);
    for (size_t i = 0; i < err.pixelCount(); ++i)
      for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = unitToByte(srgbEncode(err.rgb[i * 3 + c]));
    compare.diffTex.upload(err.width, err.height, rgba.data());
  } catch (const Error& e) {
    compare.error = e.what();
    return;
  }
  SliceImage o = mapSlice(b, other->desc.semantic, SliceSpec{2, 0}, view.display);
  compare.otherTex.upload(o.width, o.height, o.rgba.data());
  compare.otherImage = rgbOf(o);
}

void Viewer::drawCompareControls() {
  ImGui::Checkbox("compare", &compare.on);
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("show this image against another output, a snapshot or a file, with the difference");
  if (!compare.on) return;
  ImGui::SameLine();
  int source = int(compare.source);
  ImGui::RadioButton("output", &source, 0);
  ImGui::SameLine();
  ImGui::RadioButton("snapshot", &source, 1);
  ImGui::SameLine();
  ImGui::RadioButton("file", &source, 2);
  compare.source = CompareState::Source(source);
  ImGui::SameLine();
  if (ImGui::Button("Keep snapshot")) {
    compare.snapshot = cap;
    compare.snapshotLabel = std::string(cursor->technique().stage(selected).id()) + "/" + cap.desc.name;
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("keep the shown output; change a parameter, then compare with the snapshot");
  if (compare.source == CompareState::Source::Output) {
    ImGui::SetNextItemWidth(220);
    if (ImGui::BeginCombo("##compareoutput", compare.other.empty() ? "(pick an image)" : compare.other.c_str())) {
      for (const auto& n : imageOutputs())
        if (ImGui::Selectable(n.c_str(), n == compare.other)) compare.other = n;
      ImGui::EndCombo();
    }
  } else if (compare.source == CompareState::Source::File) {
    ImGui::SetNextItemWidth(300);
    ImGui::InputText("EXR/PNG##comparefile", compare.file, sizeof compare.file, ImGuiInputTextFlags_EnterReturnsTrue);
  }
  int mode = int(compare.mode);
  for (int k = 0; k < 3; ++k) {
    if (k) ImGui::SameLine();
    ImGui::RadioButton(kModeNames[k], &mode, k);
  }
  compare.mode = CompareState::Mode(mode);
  if (compare.mode == CompareState::Mode::Split) {
    ImGui::SameLine();
    ImGui::SetNextItemWidth(120);
    ImGui::SliderFloat("split", &compare.split, 0.0f, 1.0f, "%.2f");
  }
  updateCompare();
  if (!compare.error.empty()) {
    ImGui::TextColored(kWarningColour, "%s", compare.error.c_str());
  } else if (compare.metrics) {
    const auto& m = *compare.metrics;
    ImGui::TextWrapped("vs %s: rmse %.5g, psnr %.2f dB, mae %.4g, max %.4g, ssim %.4f", compare.otherLabel.c_str(), m.rmse, m.psnr,
                m.mae, m.maxAbs, m.ssim);
    if (compare.mode == CompareState::Mode::Difference)
      ImGui::TextDisabled("luminance of |A - B|, false colour up to %.4g (99th percentile)", double(compare.errorScale));
  }
}

bool Viewer::drawCompareImage(ImVec2 origin, ImVec2 size) {
  if (!compare.on || !compare.error.empty() || !compare.metrics) return false;
  auto* dl = ImGui::GetWindowDrawList();
  const ImVec2 end(origin.x + size.x, origin.y + size.y);
  switch (compare.mode) {
    case CompareState::Mode::Difference:
      ImGui::Image(compare.diffTex.imgui(), size);
      return true;
    case CompareState::Mode::SideBySide:
      ImGui::Image(image2d.texture.imgui(), size);
      dl->AddImage(compare.otherTex.imgui(), ImVec2(end.x + 8, origin.y), ImVec2(end.x + 8 + size.x, end.y));
      return true;
    case CompareState::Mode::Split: {
      ImGui::Image(image2d.texture.imgui(), size);
      float x = origin.x + compare.split * size.x;
      dl->AddImage(compare.otherTex.imgui(), ImVec2(x, origin.y), end, ImVec2(compare.split, 0), ImVec2(1, 1));
      dl->AddLine(ImVec2(x, origin.y), ImVec2(x, end.y), IM_COL32(255, 255, 255, 220), 2.0f);
      return true;
    }
  }
  return false;
}

// --- Script verbs: the compare view -----------------------------------------------------------------

namespace {

void keepSnapshot(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  const Technique& t = viewer.cursor->technique();
  viewer.compare.snapshot = cap;
  viewer.compare.snapshotLabel = std::string(t.stage(viewer.selected).id()) + "/" + cap.desc.name;
  for (const auto& [name, value] : viewer.cursor->params().formatted())
    if (t.defaultParams().formatted().at(name) != value) viewer.compare.snapshotLabel += " " + name + "=" + value;
}

void compareWith(Viewer& viewer, const ScriptCall& call) {
  CompareState& compare = viewer.compare;
  const std::string& what = call.arg(0);
  compare.on = what != "off";
  if (what == "output") {
    if (call.count() < 2) call.badArgument("compare-with output needs STAGE/OUTPUT");
    const auto outputs = viewer.imageOutputs();
    if (std::find(outputs.begin(), outputs.end(), call.arg(1)) == outputs.end())
      call.fail("no image output '" + call.arg(1) + "' has run; valid: " + joinNames(outputs));
    compare.source = CompareState::Source::Output;
    compare.other = call.arg(1);
  } else if (what == "snapshot") {
    if (!compare.snapshot) call.fail("no snapshot kept (keep-snapshot)");
    compare.source = CompareState::Source::Snapshot;
  } else if (what == "file") {
    if (call.count() < 2) call.badArgument("compare-with file needs PATH");
    if (!fileExists(call.arg(1))) call.fail("file '" + call.arg(1) + "' does not exist");
    compare.source = CompareState::Source::File;
    std::snprintf(compare.file, sizeof compare.file, "%s", call.arg(1).c_str());
  } else if (what != "off") {
    call.badArgument("unknown source '" + what + "'; valid: output, snapshot, file, off");
  }
  compare.key.clear();
}

void setCompareMode(Viewer& viewer, const ScriptCall& call) {
  CompareState& compare = viewer.compare;
  if (call.arg(0) == "side") compare.mode = CompareState::Mode::SideBySide;
  else if (call.arg(0) == "split") compare.mode = CompareState::Mode::Split;
  else if (call.arg(0) == "difference") compare.mode = CompareState::Mode::Difference;
  else call.badArgument("unknown mode '" + call.arg(0) + "'; valid: side, split, difference");
  if (call.count() > 1) compare.split = std::clamp(call.floatArg(1), 0.0f, 1.0f);
}

void printCompare(Viewer& viewer, const ScriptCall& call) {
  const CapturedOutput& cap = requireShownCapture(viewer, call);
  CompareState& compare = viewer.compare;
  if (!compare.on) call.fail("compare is off (compare-with ...)");
  if (cap.desc.kind != OutputKind::Image2D) call.fail("output " + cap.desc.name + " is not an image");
  compare.key.clear();
  const auto t0 = std::chrono::steady_clock::now();
  viewer.updateCompare();
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!compare.error.empty()) call.fail(compare.error);
  const auto& m = *compare.metrics;
  // %.9g: enough digits for the test to compare with `voxlab compare --json`.
  std::printf("compare %s vs %s: rmse %.9g psnr %.9g mae %.9g max_abs %.9g ssim %.9g (%.1f ms)\n", cap.desc.name.c_str(),
              compare.otherLabel.c_str(), m.rmse, m.psnr, m.mae, m.maxAbs, m.ssim, ms);
  if (call.count() > 0 && !(m.rmse > call.floatArg(0)))
    call.fail("rmse " + std::to_string(m.rmse) + " is not above " + call.arg(0));
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(compare, 70,
  {"keep-snapshot", 0, 0, "keep-snapshot (keep the shown output to compare with later, as Keep snapshot)", keepSnapshot},
  {"compare-with", 1, 2, "compare-with output STAGE/OUTPUT | snapshot | file PATH | off (the compare view)", compareWith},
  {"compare-mode", 1, 2, "compare-mode side|split|difference [SPLIT] (how the compare view shows both)", setCompareMode},
  {"print-compare", 0, 1,
   "print-compare [MIN_RMSE] (prints the compare view's metrics: rmse, psnr, mae, max_abs, ssim; with MIN_RMSE fails "
   "unless rmse is above it)",
   printCompare});

}  // namespace voxlab
