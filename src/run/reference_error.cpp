#include "run/reference_error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "capture/image_files.h"
#include "core/error.h"
#include "core/paths.h"
#include "reference/image_io.h"
#include "reference/image_metrics.h"
#include "reference/path_tracer.h"

namespace voxlab {

using nlohmann::json;

std::string referenceImagePath(const std::string& scene, const std::string& mode) {
  return projectPath("tests/golden/reference/" + scene + "/" + mode + ".exr");
}

std::string referenceRole(const std::string& mode) {
  reference::Mode m;
  try {
    m = reference::parseMode(mode);
  } catch (const Error&) {
    return "";
  }
  if (m == reference::Mode::Direct) return "direct";
  if (m == reference::Mode::Full) return "full";
  if (m.indirectOnly()) return "indirect";
  return "";
}

bool hasReferences(const std::string& scene) {
  std::error_code ec;
  for (const auto& f : std::filesystem::directory_iterator(projectPath("tests/golden/reference/" + scene), ec))
    if (f.path().extension() == ".exr") return true;
  return false;
}

namespace {

const reference::ImageAttribute* findAttr(const reference::ImageAttributes& attrs, const std::string& name) {
  for (const auto& a : attrs)
    if (a.name == name) return &a;
  return nullptr;
}

json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

}  // namespace

json compareWithReference(const CapturedOutput& out, const std::string& scene, int camera,
                          const std::string& dir, const std::string& prefix) {
  const std::string& mode = out.desc.referenceMode;
  if (mode.find_first_of("{}") != std::string::npos)
    throw Error("output " + out.desc.name + ": reference mode '" + mode +
                "' is not resolved; pass the mode under the run's parameters (referenceModeUnder)");
  if (mode.empty() || out.desc.kind != OutputKind::Image2D || out.levels.empty()) return nullptr;
  std::string path = referenceImagePath(scene, mode);
  if (!fileExists(path)) return nullptr;
  json r;
  r["mode"] = mode;
  r["reference"] = "tests/golden/reference/" + scene + "/" + mode + ".exr";

  reference::ImageAttributes attrs;
  reference::Image ref;
  try {
    ref = reference::readExr(path, &attrs);
  } catch (const Error& e) {
    r["skipped"] = e.what();
    return r;
  }
  const LevelData& level = out.levels[0];
  auto attr = [&](const char* name) {
    const auto* a = findAttr(attrs, name);
    return a ? a->value : std::string();
  };
  std::string why;
  if (attr("voxlab:scene") != scene)
    why = "the reference is of scene '" + attr("voxlab:scene") + "'";
  else if (attr("voxlab:mode") != mode)
    why = "the reference is of mode '" + attr("voxlab:mode") + "'";
  else if (attr("voxlab:camera_index") != std::to_string(camera))
    why = "the reference is of camera " + (attr("voxlab:camera_index").empty() ? "?" : attr("voxlab:camera_index")) +
          ", the run of camera " + std::to_string(camera);
  else if (level.size.z != 1 || level.channels < 1 || level.size.x < 1 || level.size.y < 1)
    why = "the output is not a 2D image";
  // An output traced at a reduced resolution (e.g. one value per 2x2 block) is compared with the
  // reference box-filtered by the same integer factor.
  int factor = level.size.x > 0 ? ref.width / level.size.x : 0;
  if (why.empty() && (factor < 1 || ref.width != level.size.x * factor || ref.height != level.size.y * factor))
    why = "the run is " + std::to_string(level.size.x) + "x" + std::to_string(level.size.y) + ", the reference " +
          std::to_string(ref.width) + "x" + std::to_string(ref.height);
  if (!why.empty()) {
    r["skipped"] = why;
    return r;
  }
  if (factor > 1) {
    reference::Image small(level.size.x, level.size.y);
    const float w = 1.0f / float(factor * factor);
    for (int y = 0; y < small.height; ++y)
      for (int x = 0; x < small.width; ++x)
        for (int dy = 0; dy < factor; ++dy)
          for (int dx = 0; dx < factor; ++dx)
            for (int c = 0; c < 3; ++c) small.at(x, y)[c] += w * ref.at(x * factor + dx, y * factor + dy)[c];
    ref = std::move(small);
    r["reference_downsampled"] = factor;
  }

  // The capture is bottom row first (GL order) with 1..4 channels; the reference top row first, RGB.
  reference::Image img(level.size.x, level.size.y);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      float* px = img.at(x, img.height - 1 - y);
      for (int c = 0; c < 3; ++c) px[c] = level.at(x, y, 0, std::min(c, level.channels - 1));
    }
  reference::ImageMetrics m = reference::computeMetrics(img, ref);
  float scale = 0.0f;
  reference::Image err = reference::errorImage(img, ref, 0.0f, &scale);
  char scaleText[32];
  std::snprintf(scaleText, sizeof scaleText, "%g", scale);
  reference::ImageAttributes errAttrs = {
      {"voxlab:error_scale", scaleText, false},
      {"voxlab:reference", r["reference"].get<std::string>(), false},
      {"voxlab:content", "luminance of |output - reference| through the voxlab error colour ramp", false}};
  json files = json::array();
  // The error map's EXR as RLE: its 32-bit colours of a noisy difference deflate barely (2.1 MB ZIP,
  // 2.3 MB RLE at 512x512), and RLE writes it in a sixth of the time (55 -> 9 ms).
  for (const char* ext : {".error.png", ".error.exr"}) {
    reference::writeImage(dir + "/" + prefix + ext, err, errAttrs, false, ExrCompression::Rle);
    files.push_back(prefix + ext);
  }
  if (!attr("voxlab:spp").empty()) r["spp"] = std::stoi(attr("voxlab:spp"));
  if (!attr("voxlab:rms_stderr").empty()) r["rms_stderr"] = std::stod(attr("voxlab:rms_stderr"));
  // Energy: the output's mean over the reference's (all pixels, RGB). 1 = no overall bias.
  double sumA = 0.0, sumB = 0.0;
  for (float v : img.rgb) sumA += double(v);
  for (float v : ref.rgb) sumB += double(v);
  r["mean_ratio"] = number(sumB > 0.0 ? sumA / sumB : NAN);
  r["rmse"] = number(m.rmse);
  r["psnr"] = number(m.psnr);
  r["mae"] = number(m.mae);
  r["mre"] = number(m.mre);
  r["max_abs"] = number(m.maxAbs);
  r["ssim"] = number(m.ssim);
  r["dssim"] = number(m.dssim);
  r["error_scale"] = scale;
  r["files"] = files;
  return r;
}

std::vector<OutputAddress> finalAndComparedOutputs(const Technique& t) {
  std::vector<OutputAddress> only;
  only.push_back(OutputAddress::parse(t.id() + "/" + t.finalStage() + "/" + t.finalOutput()));
  for (int i = 0; i < t.stageCount(); ++i)
    for (const auto& o : t.decl(i).outputs)
      if (!o.referenceMode.empty() && !(t.stage(i).id() == t.finalStage() && o.name == t.finalOutput()))
        only.push_back(OutputAddress::parse(t.id() + "/" + t.stage(i).id() + "/" + o.name));
  return only;
}

DisplayImage referenceDisplayImage(const OutputDesc& desc, const std::string& exr) {
  ImageFileData f = readImageFile(exr);
  CapturedOutput c;
  c.desc = desc;
  LevelData L;
  L.size = {f.width, f.height, 1};
  L.channels = 4;
  L.values.assign(size_t(f.width) * f.height * 4, 1.0f);
  for (int y = 0; y < f.height; ++y)  // file rows top first; LevelData rows bottom first (GL order)
    for (int x = 0; x < f.width; ++x)
      for (int ch = 0; ch < std::min(f.channels, 3); ++ch)
        L.values[(size_t(f.height - 1 - y) * f.width + x) * 4 + ch] = f.pixels[(size_t(y) * f.width + x) * f.channels + ch];
  c.levels.push_back(std::move(L));
  return displayImage(c, 0);
}

void writeReferencePng(const OutputDesc& desc, const std::string& exr, const std::string& png) {
  writePng(referenceDisplayImage(desc, exr), png);
}

std::string manifestFileEndingWith(const json& entry, const std::string& suffix) {
  if (!entry.contains("files")) return "";
  for (const auto& f : entry["files"]) {
    std::string s = f.get<std::string>();
    if (s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0) return s;
  }
  return "";
}

}  // namespace voxlab
