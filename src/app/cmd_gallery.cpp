// voxlab gallery --scene S --out DIR: every registered technique against the reference path
// tracer on one scene, as one HTML page (DIR/<scene>.html, numbers in DIR/<scene>.json).
//
// Each technique runs once with its default parameters through HeadlessSession::writeOutputs, the
// code path of `voxlab run` (so the error images and numbers are those of docs/fidelity.md, which
// `voxlab fidelity` reports from the same code). What is shown comes from the
// declarations alone: the final output (Technique::finalOutput), and every output tagged with a
// reference mode (OutputDesc::referenceMode) with the reference image of that mode, the error
// image and the metrics (the mode under the run's parameters, referenceModeUnder). An output
// whose mode counts only indirect light (reference::Mode::indirectOnly: indirect, indirect-K) is
// the technique's indirect term. The time per frame
// is the median over --bench-runs runs of all stages, measured as `voxlab bench` measures it.
// Beside it a small plot of error against time over the technique's default sweep
// (defaultGallerySweep: its grid's resolution at three values, 64x64 pixels; run/sweep.h), which
// --no-sweeps leaves out.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "run/bench_runs.h"
#include "app/command.h"
#include "run/reference_error.h"
#include "run/session.h"
#include "capture/capture.h"
#include "capture/image_files.h"
#include "core/args.h"
#include "core/error.h"
#include "core/paths.h"
#include "graph/reference_mode.h"
#include "graph/technique.h"
#include "handout/handout.h"
#include "handout/step_picture.h"
#include "reference/path_tracer.h"
#include "run/sweep.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

bool indirectOnly(const std::string& mode) {
  try {
    return reference::parseMode(mode).indirectOnly();
  } catch (const Error&) {
    return false;
  }
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// The sweep the gallery plots for a technique: the first grid resolution it declares, at 32, 64 and
// 128, or 16, 32 and 64 where 128 is out of its range (cheap at 64x64: a second or two per run); an
// empty request (no "params") when it declares none of them or compares no output with the
// reference (no error to plot).
SweepRequest defaultGallerySweep(const std::string& technique, const std::string& scene) {
  SweepRequest request;
  request.technique = technique;
  request.scene = scene;
  request.width = request.height = 64;
  const auto declared = createTechnique(technique);
  bool compared = false;  // an error needs an output compared with the reference
  for (int i = 0; i < declared->stageCount(); ++i)
    for (const OutputDesc& o : declared->decl(i).outputs) compared = compared || !o.referenceMode.empty();
  if (!compared) return request;
  const ParamSet params = declared->defaultParams();
  for (const char* name : {"voxel.resolution", "clipmap.resolution", "density.resolution"}) {
    if (!params.has(name)) continue;
    for (const char* values : {"=32,64,128", "=16,32,64"}) {
      request.params = {std::string(name) + values};
      try {
        validateSweep(request);
        return request;
      } catch (const Error&) {
        request.params.clear();
      }
    }
  }
  return request;
}

// A small copy for the documentation: DIR/<scene>.md (a Markdown table per technique) and its
// pictures, 160 px wide, in DIR/<scene>/ (about 20-40 KB each).
void writeDocsCopy(const json& page, const std::string& galleryDir, const std::string& dir) {
  const std::string scene = page["scene"].get<std::string>();
  fs::create_directories(fs::path(dir) / scene);
  auto copy = [&](const std::string& rel) {
    ImageFileData f = readImageFile((fs::path(galleryDir) / rel).string());
    DisplayImage img;
    img.width = f.width;
    img.height = f.height;
    img.rgb.resize(size_t(f.width) * f.height * 3);
    for (size_t i = 0; i < size_t(f.width) * f.height; ++i)
      for (int c = 0; c < 3; ++c)
        img.rgb[i * 3 + c] = uint8_t(std::lround(255.0f * f.pixels[i * f.channels + std::min(c, f.channels - 1)]));
    std::string name = rel.substr(rel.find('/') + 1);  // <technique>/<file>
    std::replace(name.begin(), name.end(), '/', '.');
    writePng(shrink(img, 160), (fs::path(dir) / scene / name).string());
    return "![" + name + "](" + scene + "/" + name + ")";
  };
  std::string md = "# Gallery: " + scene + "\n\nWritten by `voxlab gallery --scene " + scene + " --docs-copy docs/gallery` " +
                   "(camera " + std::to_string(page["camera"].get<int>()) + ", " + page["size"].get<std::string>() +
                   ", default parameters; pictures reduced to 160 px). The full-size page is `<out>/" + scene +
                   ".html`; docs/fidelity.md explains the numbers.\n";
  for (const auto& t : page["techniques"]) {
    md += "\n## " + t["title"].get<std::string>() + " (`" + t["id"].get<std::string>() + "`)\n\nTime per frame " +
          fmt("%.0f", t["frame_cpu_ms_median"].get<double>()) + " ms (CPU wall, median of " +
          std::to_string(page["bench_runs"].get<int>()) + " runs, " + t["gl_renderer"].get<std::string>() + ").\n\n" +
          "| output | image | reference | error | RMSE | SSIM | mean ratio |\n|---|---|---|---|---:|---:|---:|\n";
    for (const auto& o : t["outputs"]) {
      md += "| `" + o["address"].get<std::string>() + "` (" + o["role"].get<std::string>() + ") | " + copy(o["image"]) + " | ";
      if (o.contains("reference_image")) {
        const json& r = o["reference_error"];
        md += copy(o["reference_image"]) + " `" + r["mode"].get<std::string>() + "` | " +
              (o.contains("error_image") ? copy(o["error_image"]) : std::string()) + " | " + fmt("%.4f", r["rmse"].get<double>()) +
              " | " + fmt("%.3f", r["ssim"].get<double>()) + " | " + fmt("%.3f", r["mean_ratio"].get<double>()) + " |\n";
      } else {
        md += "no reference | | | | |\n";
      }
    }
  }
  std::ofstream(fs::path(dir) / (scene + ".md")) << md;
}

int runGallery(const std::vector<std::string>& argv) {
  Args args("gallery", argv,
            {{"--scene", true, false, "scene name in scenes/ or a glTF path"},
             {"--camera", true, false, "index of the scene camera (default 0, the references' camera)"},
             {"--size", true, false, "image size WIDTHxHEIGHT (default 512x512, the references' size)"},
             {"--bench-runs", true, false, "timed runs of all stages per technique (default 5, as voxlab bench)"},
             {"--no-sweeps", false, false, "leave out the error-against-time plot of each technique's default sweep"},
             {"--docs-copy", true, false, "also write DIR/<scene>.md with its pictures 160 px wide (docs/gallery)"},
             {"--out", true, false, "folder for <scene>.html, <scene>.json and <scene>/<technique>/"}});
  RunRequest base;
  base.scene = args.require("--scene");
  if (args.has("--camera")) base.camera = Args::parseInt("--camera", args.get("--camera"), 0, 1000);
  if (args.has("--size")) Args::parseSize(args.get("--size"), base.width, base.height);
  const int benchRuns = Args::parseInt("--bench-runs", args.get("--bench-runs", "5"), 1, 1000);
  const std::string out = args.require("--out");
  const Scene sceneInfo = loadScene(resolveScenePath(base.scene));  // bad scene: one line, before any GL
  const std::string scene = sceneInfo.name;

  json page = {{"scene", scene}, {"camera", base.camera}, {"size", std::to_string(base.width) + "x" + std::to_string(base.height)},
               {"bench_runs", benchRuns}, {"techniques", json::array()}};
  const auto& registry = techniqueRegistry();
  int k = 0;
  for (const auto& entry : registry) {
    ++k;
    std::fprintf(stderr, "voxlab gallery: %d/%zu %s on %s\n", k, registry.size(), entry.id.c_str(), scene.c_str());
    json tj;
    {  // the session's GL context is closed before the sweep opens its own
    RunRequest req = base;
    req.technique = entry.id;
    HeadlessSession session(req);
    const Technique& t = session.cursor().technique();
    const std::vector<OutputAddress> only = finalAndComparedOutputs(t);
    const std::string rel = scene + "/" + t.id();
    const std::string dir = (fs::path(out) / rel).string();
    session.run();
    json manifest = session.writeOutputs(dir, false, only);

    tj = {{"id", t.id()}, {"title", t.title()}, {"outputs", json::array()}};
    for (const auto& s : manifest["stages"])
      for (const auto& e : s["outputs"]) {
        auto [stage, desc] = t.findOutput(s["id"].get<std::string>(), e["name"].get<std::string>());
        (void)stage;
        json oj = {{"address", e["address"]}, {"final", e["final"]}, {"help", e["help"]}};
        std::string png = manifestFileEndingWith(e, s["id"].get<std::string>() + "." + desc->name + ".png");
        if (png.empty()) png = manifestFileEndingWith(e, ".png");  // a buffer's point view, a volume's level 0
        oj["image"] = rel + "/" + png;
        std::string role = e["final"].get<bool>() ? "final image" : "";
        if (!desc->referenceMode.empty()) {
          const std::string mode = referenceModeUnder(*desc, session.cursor().params());
          oj["reference_mode"] = mode;
          if (indirectOnly(mode)) role += std::string(role.empty() ? "" : ", ") + "indirect term";
          if (e.contains("reference_error")) {
            const json& r = e["reference_error"];
            oj["reference_error"] = r;
            if (!r.contains("skipped")) {
              std::string err = manifestFileEndingWith(e, ".error.png");
              if (!err.empty()) oj["error_image"] = rel + "/" + err;
              std::string refPng = s["id"].get<std::string>() + "." + desc->name + ".reference.png";
              writeReferencePng(*desc, projectPath(r["reference"].get<std::string>()), dir + "/" + refPng);
              oj["reference_image"] = rel + "/" + refPng;
            }
          }
        }
        oj["role"] = role.empty() ? "compared with the reference" : role;
        tj["outputs"].push_back(oj);
      }
    StageTimes times = timeStages(session.cursor(), benchRuns);
    tj["frame_cpu_ms_median"] = median(times.totalCpu);
    tj["frame_gpu_ms_median"] = median(times.totalGpu);
    tj["gl_renderer"] = manifest["gl"]["renderer"];
    }
    if (!args.has("--no-sweeps")) {
      const SweepRequest sweep = defaultGallerySweep(entry.id, base.scene);
      if (sweep.params.empty()) {
        tj["sweep"] = {{"none", "compares no output with the reference or declares no grid resolution to sweep"}};
      } else {
        const std::string rel = scene + "/" + entry.id + "/sweep";
        std::fprintf(stderr, "voxlab gallery: %s: sweep of %s at 64x64\n", entry.id.c_str(), sweep.params[0].c_str());
        const json report = runSweep(sweep, (fs::path(out) / rel).string());
        tj["sweep"] = {{"param", sweep.params[0]}, {"plot", rel + "/error-by-time.svg"}, {"page", rel + "/sweep.html"},
                       {"error", report["error"]}, {"failed_runs", report["failed_runs"]}};
      }
    }
    page["techniques"].push_back(tj);
  }

  // The page: one section per technique; final image first, then the indirect term, then the rest.
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>voxlab gallery: " +
                     htmlEscape(scene) + "</title>\n<style>\nbody { font-family: sans-serif; margin: 2em; color: #222; }\n"
                     "table { border-collapse: collapse; } td, th { padding: 0.3em 0.6em; vertical-align: top; text-align: left; }\n"
                     "img { width: 256px; height: auto; border: 1px solid #ccc; }\n"
                     "img.sweep { width: 345px; } figure.sweep { margin: 0.5em 0; font-size: 0.85em; }\n"
                     "table.metrics td { padding: 0 0.4em; text-align: right; } code { background: #f3f3f3; }\n"
                     "</style>\n</head>\n<body>\n";
  html += "<h1>voxlab gallery: " + htmlEscape(scene) + "</h1>\n<p>Every technique in <code>voxlab list</code> at its default "
          "parameters, camera " + std::to_string(base.camera) + ", " + page["size"].get<std::string>() +
          ", against the reference path tracer (<code>voxlab reference</code>; docs/fidelity.md explains the numbers). "
          "Time per frame: median of " + std::to_string(benchRuns) + " runs of all stages, as <code>voxlab bench</code> "
          "measures it.</p>\n";
  for (auto& tj : page["techniques"]) {
    auto& outs = tj["outputs"];
    std::stable_sort(outs.begin(), outs.end(), [](const json& a, const json& b) {
      auto rank = [](const json& o) {
        std::string r = o["role"].get<std::string>();
        return r.rfind("final", 0) == 0 ? 0 : r.find("indirect") != std::string::npos ? 1 : 2;
      };
      return rank(a) < rank(b);
    });
    html += "<section class=\"technique\" id=\"" + htmlEscape(tj["id"].get<std::string>()) + "\">\n<h2>" +
            htmlEscape(tj["title"].get<std::string>()) + " (<code>" + htmlEscape(tj["id"].get<std::string>()) + "</code>)</h2>\n";
    html += "<p>Time per frame: " + fmt("%.1f", tj["frame_cpu_ms_median"].get<double>()) + " ms CPU wall, " +
            fmt("%.1f", tj["frame_gpu_ms_median"].get<double>()) + " ms GPU (" +
            htmlEscape(tj["gl_renderer"].get<std::string>()) + ").</p>\n";
    if (tj.contains("sweep") && tj["sweep"].contains("plot")) {
      const json& sw = tj["sweep"];
      html += "<figure class=\"sweep\"><a href=\"" + htmlEscape(sw["page"].get<std::string>()) + "\"><img class=\"sweep\" src=\"" +
              htmlEscape(sw["plot"].get<std::string>()) + "\" alt=\"error against time\"></a><figcaption>Error (" +
              htmlEscape(sw["error"]["definition"].get<std::string>()) + " of <code>" +
              htmlEscape(sw["error"]["output"].get<std::string>()) + "</code>) against time over the sweep <code>" +
              htmlEscape(sw["param"].get<std::string>()) + "</code> at 64x64 (the link opens its slider page).</figcaption></figure>\n";
    } else if (tj.contains("sweep")) {
      html += "<p>No sweep: the technique " + htmlEscape(tj["sweep"]["none"].get<std::string>()) + ".</p>\n";
    }
    html += "<table>\n<tr><th>output</th><th>image</th><th>reference</th><th>error</th><th>numbers</th></tr>\n";
    for (const auto& o : outs) {
      html += "<tr><td><code>" + htmlEscape(o["address"].get<std::string>()) + "</code><br>" +
              htmlEscape(o["role"].get<std::string>()) + "</td>";
      html += "<td><img src=\"" + htmlEscape(o["image"].get<std::string>()) + "\" alt=\"output\"></td>";
      if (o.contains("reference_image")) {
        const json& r = o["reference_error"];
        html += "<td><img src=\"" + htmlEscape(o["reference_image"].get<std::string>()) + "\" alt=\"reference\"><br>mode <code>" +
                htmlEscape(r["mode"].get<std::string>()) + "</code>, " + std::to_string(r.value("spp", 0)) + " spp</td>";
        html += "<td>" + (o.contains("error_image") ? "<img src=\"" + htmlEscape(o["error_image"].get<std::string>()) +
                                                          "\" alt=\"error\"><br>|output - reference|, top of ramp " +
                                                          fmt("%.3g", r.value("error_scale", 0.0))
                                                    : std::string("")) + "</td>";
        std::string psnr = r["psnr"].is_null() ? "inf" : fmt("%.2f", r["psnr"].get<double>());
        html += "<td><table class=\"metrics\"><tr><td>RMSE</td><td>" + fmt("%.4f", r["rmse"].get<double>()) +
                "</td></tr><tr><td>PSNR (dB)</td><td>" + psnr + "</td></tr><tr><td>MAE</td><td>" +
                fmt("%.4f", r["mae"].get<double>()) + "</td></tr><tr><td>MRE</td><td>" + fmt("%.3f", r["mre"].get<double>()) +
                "</td></tr><tr><td>SSIM</td><td>" + fmt("%.3f", r["ssim"].get<double>()) +
                "</td></tr><tr><td>mean ratio</td><td>" + fmt("%.3f", r["mean_ratio"].get<double>()) + "</td></tr>";
        if (r.contains("reference_downsampled"))
          html += "<tr><td colspan=\"2\">1/" + std::to_string(r["reference_downsampled"].get<int>()) +
                  " res., vs reference box-filtered</td></tr>";
        html += "</table></td>";
      } else if (o.contains("reference_error")) {
        html += "<td colspan=\"3\">reference " + htmlEscape(o["reference_error"]["mode"].get<std::string>()) +
                " skipped: " + htmlEscape(o["reference_error"].value("skipped", std::string())) + "</td>";
      } else if (o.contains("reference_mode")) {
        html += "<td colspan=\"3\">no reference image for mode <code>" + htmlEscape(o["reference_mode"].get<std::string>()) +
                "</code> on " + htmlEscape(scene) + " (scripts/make-references.sh)</td>";
      } else {
        html += "<td colspan=\"3\">no reference mode declared for this output (OutputDesc::referenceMode)</td>";
      }
      html += "</tr>\n";
    }
    html += "</table>\n</section>\n";
  }
  html += "</body>\n</html>\n";
  fs::create_directories(out);
  std::ofstream(fs::path(out) / (scene + ".html")) << html;
  std::ofstream(fs::path(out) / (scene + ".json")) << page.dump(2) << "\n";
  if (args.has("--docs-copy")) writeDocsCopy(page, out, args.get("--docs-copy"));
  std::printf("voxlab gallery: %zu techniques on %s, written to %s/%s.html\n", registry.size(), scene.c_str(), out.c_str(),
              scene.c_str());
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("gallery",
                        "voxlab gallery --scene S [--camera N] [--size WxH] [--bench-runs N] [--no-sweeps] --out DIR",
                        "every technique against the reference on one scene: images, error images, numbers, time per frame",
                        &runGallery);

}  // namespace voxlab
