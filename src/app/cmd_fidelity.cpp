// voxlab fidelity: every technique on every scene of the fidelity suite against the reference path
// tracer, as one table.
//
// The suite is scenes/suite.json (written by scripts/make_suite_scenes.py: the scene names, which
// are interiors, what each tests); --scene and --technique narrow it. Each (technique, scene) runs
// once at its defaults (plus --set overrides the technique declares) through HeadlessSession, the
// code path of `voxlab run`, so its numbers are the "reference_error" entries a run's manifest
// holds. What is compared comes from the declarations alone: every output tagged with a
// reference mode (OutputDesc::referenceMode, resolved under the run's parameters), classified by
// what the mode counts: "direct" (r <= 1), "indirect" (indirect light only: indirect,
// indirect-K; the last such output in stage order, the one the composite uses), "full" (every
// path), and the final image.
//
// With --frames N it measures change instead (the animated scenes of suite.json's "animated", or
// --scene): each technique plays the scene's animation over N frames (`voxlab run --frames`), and
// its final image's flicker (mean |I_k - I_(k-1)|) and per-frame energy are compared with the path
// tracer's rendering of the same frames at the same size (run/temporal_reference.h, --reference-spp
// samples, cached under build/temporal-reference/): the flicker ratio (technique over reference;
// the reference's own noise floor, its flicker between two seeds of one frame, stated beside it)
// and the energy ratio per frame (mean, min, max over the frames). A technique with no output of
// mode full (nothing the still tables compare as the combined image) has its final image's
// flicker measured and no ratios.
//
// Writes DIR/fidelity.json (per cell: wall time, and per compared output its mode, mean ratio,
// RMSE, SSIM, ...), DIR/fidelity.md (tables: rows techniques, columns scenes) and
// DIR/fidelity.html (per cell the final image, the error image, the numbers; the references in the
// first row), with the run folders under DIR/<scene>/<technique>/. --check BANDS.json compares
// the numbers with bands and exits 1 naming every number outside its band. A band is
// {"technique": id or "*", "technique_except": [ids], "scene": name, "*" or "interior",
//  "scene_except": [names],
//  "output": "direct" | "indirect" | "full", "metric": "mean_ratio" | "ssim" | "rmse",
//  "min": x, "max": y, "why": "what was measured"} (tests/fidelity/bands.json, written by
// scripts/pin-fidelity-bands.py).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include <nlohmann/json.hpp>

#include "app/command.h"
#include "run/reference_error.h"
#include "run/frames.h"
#include "run/session.h"
#include "run/temporal_reference.h"
#include "core/args.h"
#include "core/error.h"
#include "core/paths.h"
#include "core/progress.h"
#include "graph/reference_mode.h"
#include "graph/technique.h"
#include "handout/handout.h"
#include "reference/path_tracer.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct SuiteScene {
  std::string name;      // the scene's name (its file's stem): folders, tables, reference images
  std::string argument;  // what the run loads: a name in scenes/ or a path
  bool interior = false;
  bool inSuite = false;  // false: named by --scene, not listed in scenes/suite.json
  std::string tests;
};

std::vector<SuiteScene> readSuite() {
  const std::string path = projectPath("scenes/suite.json");
  std::ifstream in(path);
  if (!in) throw Error("cannot read the fidelity suite " + path + " (written by scripts/make_suite_scenes.py)");
  json doc;
  try {
    doc = json::parse(in);
  } catch (const json::exception& e) {
    throw Error(path + " is not valid JSON: " + e.what());
  }
  std::vector<SuiteScene> suite;
  try {
    for (const auto& s : doc.at("scenes"))
      suite.push_back({s.at("name").get<std::string>(), s.at("name").get<std::string>(), s.at("interior").get<bool>(),
                       true, s.value("tests", "")});
  } catch (const json::exception& e) {
    throw Error(path + ": " + e.what() + " (valid: {\"scenes\": [{\"name\", \"interior\", \"tests\"}, ...]})");
  }
  return suite;
}


std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// --- bands -----------------------------------------------------------------------------------------

struct Band {
  std::string technique = "*";  // id or "*"
  std::set<std::string> except;  // with "*": techniques the band does not hold for
  std::string scene = "*";      // name, "*" or "interior"
  std::set<std::string> sceneExcept;  // with "*" or "interior": scenes the band does not hold for
  std::string role;             // direct, indirect, full
  std::string metric;           // mean_ratio, ssim, rmse
  double lo = -INFINITY, hi = INFINITY;
  std::string why;
};

std::vector<Band> readBands(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("--check: cannot read '" + path + "'");
  json doc;
  try {
    doc = json::parse(in, nullptr, true, true);
  } catch (const json::exception& e) {
    throw Error("--check: '" + path + "' is not valid JSON: " + e.what());
  }
  if (!doc.contains("bands") || !doc["bands"].is_array())
    throw Error("--check: '" + path + "' has no \"bands\" array; valid: {\"bands\": [{\"technique\", \"technique_except\", "
                "\"scene\", \"scene_except\", \"output\", \"metric\", \"min\", \"max\", \"why\"}, ...]}");
  const std::set<std::string> roles = {"direct", "indirect", "full"}, metrics = {"mean_ratio", "ssim", "rmse"};
  std::vector<Band> bands;
  int k = 0;
  for (const auto& b : doc["bands"]) {
    ++k;
    Band band;
    auto where = "--check: " + path + " band " + std::to_string(k) + ": ";
    try {
      band.technique = b.value("technique", "*");
      if (b.contains("technique_except")) band.except = b["technique_except"].get<std::set<std::string>>();
      if (b.contains("scene_except")) band.sceneExcept = b["scene_except"].get<std::set<std::string>>();
      band.scene = b.value("scene", "*");
      band.role = b.at("output").get<std::string>();
      band.metric = b.value("metric", "mean_ratio");
      if (b.contains("min")) band.lo = b["min"].get<double>();
      if (b.contains("max")) band.hi = b["max"].get<double>();
      band.why = b.value("why", "");
    } catch (const json::exception& e) {
      throw Error(where + e.what());
    }
    if (!roles.count(band.role)) throw Error(where + "output '" + band.role + "' is not valid; valid: direct, indirect, full");
    if (!metrics.count(band.metric))
      throw Error(where + "metric '" + band.metric + "' is not valid; valid: mean_ratio, ssim, rmse");
    if (!(band.lo <= band.hi)) throw Error(where + "needs min <= max");
    if (band.technique != "*") createTechnique(band.technique);  // an unknown id: one line listing the valid ones
    for (const std::string& id : band.except) createTechnique(id);
    bands.push_back(band);
  }
  return bands;
}

// --- one cell ---------------------------------------------------------------------------------------

// Runs one technique on one scene; returns the cell's JSON (numbers per compared output).
json runCell(const RunRequest& request, const std::string& sceneName, const std::string& outDir, const std::string& rel) {
  const auto start = std::chrono::steady_clock::now();
  HeadlessSession session(request);
  const Technique& t = session.cursor().technique();
  const std::vector<OutputAddress> only = finalAndComparedOutputs(t);
  session.demand(false, only);  // only what the compared outputs need is computed
  session.run();
  const double runSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string dir = (fs::path(outDir) / rel).string();
  json manifest = session.writeOutputs(dir, false, only);

  json cell = {{"technique", t.id()}, {"scene", sceneName}, {"wall_s", runSeconds}, {"outputs", json::array()}};
  for (const auto& s : manifest["stages"])
    for (const auto& e : s["outputs"]) {
      auto [stage, desc] = t.findOutput(s["id"].get<std::string>(), e["name"].get<std::string>());
      (void)stage;
      json o = {{"address", e["address"]}, {"final", e["final"]}};
      std::string png = manifestFileEndingWith(e, s["id"].get<std::string>() + "." + desc->name + ".png");
      if (png.empty()) png = manifestFileEndingWith(e, ".png");
      if (!png.empty()) o["image"] = rel + "/" + png;
      if (!desc->referenceMode.empty()) {
        const std::string mode = referenceModeUnder(*desc, session.cursor().params());
        o["mode"] = mode;
        o["role"] = referenceRole(mode);
        if (e.contains("reference_error")) {
          json r = e["reference_error"];
          std::string err = manifestFileEndingWith(e, ".error.png");
          if (!err.empty()) o["error_image"] = rel + "/" + err;
          if (!r.contains("skipped") && o["role"] == "full") {
            const std::string refPng = s["id"].get<std::string>() + "." + desc->name + ".reference.png";
            writeReferencePng(*desc, projectPath(r["reference"].get<std::string>()), dir + "/" + refPng);
            o["reference_image"] = rel + "/" + refPng;
          }
          r.erase("files");
          o["reference_error"] = r;
        } else {
          o["reference_missing"] = "no reference image of mode " + mode + " for this scene";
        }
      }
      cell["outputs"].push_back(o);
    }
  return cell;
}

// The output of a cell that plays 'role' in the tables: the last one in stage order (for
// "indirect", the term the composite uses, e.g. a filtered one), or null.
const json* outputOfRole(const json& cell, const std::string& role) {
  const json* found = nullptr;
  for (const auto& o : cell["outputs"])
    if (o.value("role", "") == role) found = &o;
  return found;
}

std::optional<double> metricOf(const json& cell, const std::string& role, const std::string& metric) {
  const json* o = outputOfRole(cell, role);
  if (!o || !o->contains("reference_error")) return std::nullopt;
  const json& r = (*o)["reference_error"];
  if (r.contains("skipped") || !r.contains(metric) || r[metric].is_null()) return std::nullopt;
  return r[metric].get<double>();
}

// --- the page and the tables -----------------------------------------------------------------------

std::string markdownTables(const json& report) {
  const auto& scenes = report["scenes"];
  auto header = [&](const std::string& first) {
    std::string h = "| " + first + " |", rule = "|---|";
    for (const auto& s : scenes) {
      h += " " + s["name"].get<std::string>() + (!s["in_suite"].get<bool>() ? " (not in the suite)"
                                                 : s["interior"].get<bool>()  ? ""
                                                                              : " (exterior)") + " |";
      rule += "---:|";
    }
    return h + "\n" + rule + "\n";
  };
  auto cellOf = [&](const std::string& technique, const std::string& scene) -> const json* {
    for (const auto& c : report["cells"])
      if (c["technique"] == technique && c["scene"] == scene) return &c;
    return nullptr;
  };
  std::string md;
  struct Table {
    const char* title;
    const char* role;
  };
  const Table tables[] = {
      {"Indirect light: energy ratio to the reference (SSIM)", "indirect"},
      {"Direct light: energy ratio to the reference (SSIM)", "direct"},
      {"Combined image: energy ratio to the reference (SSIM)", "full"},
  };
  for (const Table& table : tables) {
    md += "### " + std::string(table.title) + "\n\n" + header("technique (mode)");
    for (const auto& tid : report["techniques"]) {
      std::string mode;
      std::string row;
      for (const auto& s : scenes) {
        const json* c = cellOf(tid.get<std::string>(), s["name"].get<std::string>());
        std::string text = "-";
        if (c && c->contains("error")) {
          text = "failed";
        } else if (c) {
          const json* o = outputOfRole(*c, table.role);
          if (o && mode.empty()) mode = (*o)["mode"].get<std::string>();
          auto ratio = metricOf(*c, table.role, "mean_ratio");
          auto ssim = metricOf(*c, table.role, "ssim");
          if (ratio) text = fmt("%.2f", *ratio) + (ssim ? " (" + fmt("%.2f", *ssim) + ")" : "");
          else if (o) text = "no ref.";
          if (c->contains("out_of_band") && (*c)["out_of_band"].contains(table.role)) text += " ✗";
        }
        row += " " + text + " |";
      }
      if (mode.empty()) continue;  // the technique has no output of this kind
      md += "| " + tid.get<std::string>() + " (" + mode + ") |" + row + "\n";
    }
    md += "\n";
  }
  md += "### Wall time of one run (s: context, scene, every stage; outputs not written)\n\n" + header("technique");
  for (const auto& tid : report["techniques"]) {
    md += "| " + tid.get<std::string>() + " |";
    for (const auto& s : scenes) {
      const json* c = cellOf(tid.get<std::string>(), s["name"].get<std::string>());
      md += " " + (c && c->contains("wall_s") ? fmt("%.1f", (*c)["wall_s"].get<double>()) : std::string("-")) + " |";
    }
    md += "\n";
  }
  return md;
}

std::string htmlPage(const json& report) {
  const auto& scenes = report["scenes"];
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>voxlab fidelity</title>\n<style>\n"
      "body { font-family: sans-serif; margin: 1.5em; color: #222; }\n"
      "table.grid { border-collapse: collapse; } table.grid td, table.grid th { border: 1px solid #ddd; padding: 0.3em; "
      "vertical-align: top; text-align: center; font-size: 0.85em; }\n"
      "img { width: 128px; height: 128px; image-rendering: pixelated; } img.err { width: 64px; height: 64px; }\n"
      ".bad { color: #b00; font-weight: bold; } code { background: #f3f3f3; }\n</style>\n</head>\n<body>\n"
      "<h1>voxlab fidelity</h1>\n<p>Every technique at its default parameters";
  if (!report["sets"].empty()) {
    html += " with";
    for (const auto& s : report["sets"]) html += " <code>" + htmlEscape(s.get<std::string>()) + "</code>";
  }
  html += " on every scene, camera 0, " + htmlEscape(report["size"].get<std::string>()) +
          ", against the reference path tracer (<code>voxlab reference</code>). Per cell: the final image, the error of "
          "the combined image against the <code>full</code> reference, and per compared output its energy ratio "
          "(mean of the output over the mean of the reference) and SSIM. docs/fidelity.md explains the numbers.</p>\n";
  html += "<table class=\"grid\">\n<tr><th>technique</th>";
  for (const auto& s : scenes)
    html += "<th>" + htmlEscape(s["name"].get<std::string>()) +
            (!s["in_suite"].get<bool>() ? "<br>(not in the suite)" : s["interior"].get<bool>() ? "" : "<br>(exterior)") + "</th>";
  html += "</tr>\n<tr><th>reference<br>(full)</th>";
  for (const auto& s : scenes) {
    std::string img;
    for (const auto& c : report["cells"]) {
      if (c["scene"] != s["name"] || c.contains("error")) continue;
      const json* o = outputOfRole(c, "full");
      if (o && o->contains("reference_image")) {
        img = (*o)["reference_image"].get<std::string>();
        break;
      }
    }
    html += "<td>" + (img.empty() ? std::string("no reference") : "<img src=\"" + htmlEscape(img) + "\" alt=\"reference\">") + "</td>";
  }
  html += "</tr>\n";
  for (const auto& tid : report["techniques"]) {
    html += "<tr><th>" + htmlEscape(tid.get<std::string>()) + "</th>";
    for (const auto& s : scenes) {
      const json* cell = nullptr;
      for (const auto& c : report["cells"])
        if (c["technique"] == tid && c["scene"] == s["name"]) cell = &c;
      if (!cell) {
        html += "<td>-</td>";
        continue;
      }
      if (cell->contains("error")) {
        html += "<td class=\"bad\">failed: " + htmlEscape((*cell)["error"].get<std::string>()) + "</td>";
        continue;
      }
      html += "<td>";
      for (const auto& o : (*cell)["outputs"])
        if (o["final"].get<bool>() && o.contains("image"))
          html += "<img src=\"" + htmlEscape(o["image"].get<std::string>()) + "\" alt=\"final image\">";
      if (const json* full = outputOfRole(*cell, "full"); full && full->contains("error_image"))
        html += "<img class=\"err\" src=\"" + htmlEscape((*full)["error_image"].get<std::string>()) + "\" alt=\"error\">";
      html += "<br>";
      for (const char* role : {"direct", "indirect", "full"}) {
        auto ratio = metricOf(*cell, role, "mean_ratio");
        if (!ratio) continue;
        auto ssim = metricOf(*cell, role, "ssim");
        const bool bad = cell->contains("out_of_band") && (*cell)["out_of_band"].contains(role);
        html += std::string(bad ? "<span class=\"bad\">" : "<span>") + role + " " + fmt("%.2f", *ratio) +
                (ssim ? " / " + fmt("%.2f", *ssim) : "") + "</span><br>";
      }
      html += fmt("%.1f s", (*cell)["wall_s"].get<double>()) + "</td>";
    }
    html += "</tr>\n";
  }
  html += "</table>\n</body>\n</html>\n";
  return html;
}

// --- frames: flicker and energy per frame against the reference animation ---------------------------

std::vector<SuiteScene> readAnimatedSuite() {
  std::ifstream in(projectPath("scenes/suite.json"));
  const json doc = json::parse(in);
  std::vector<SuiteScene> scenes;
  for (const auto& s : doc.value("animated", json::array()))
    scenes.push_back({s.at("name").get<std::string>(), s.at("name").get<std::string>(), s.at("interior").get<bool>(),
                      true, s.value("tests", "")});
  return scenes;
}

int runTemporalFidelity(const Args& args, const std::vector<std::string>& techniques, int frames) {
  const std::string out = args.require("--out");
  RunRequest base;
  base.width = base.height = 64;
  if (args.has("--size")) Args::parseSize(args.get("--size"), base.width, base.height);
  const int spp = args.has("--reference-spp") ? Args::parseInt("--reference-spp", args.get("--reference-spp"), 1, 100000) : 64;
  std::vector<SuiteScene> scenes;
  if (args.has("--scene")) {
    for (const std::string& name : args.all("--scene")) scenes.push_back({loadScene(resolveScenePath(name)).name, name, false, false, ""});
  } else {
    scenes = readAnimatedSuite();
  }
  json report = {{"size", std::to_string(base.width) + "x" + std::to_string(base.height)}, {"frames", frames},
                 {"reference_spp", spp}, {"references", json::array()}, {"cells", json::array()}};
  const std::string cache = projectPath("build/temporal-reference");
  std::string md = "## Fidelity over frames: flicker and energy per frame\n\nWritten by `voxlab fidelity --frames " +
                   std::to_string(frames) + "` (" + report["size"].get<std::string>() +
                   ", camera 0, default parameters). flicker: mean |I_k - I_(k-1)| of the final image over pixels "
                   "and colour channels; ratio: the technique's over the reference's (1 = as much change as the "
                   "light transport has; the reference's noise floor, its flicker between two seeds of one frame, "
                   "is what part of its flicker is noise). energy: the image's mean over the reference's, per "
                   "frame (mean, min..max). The image is the technique's combined output in linear radiance (the "
                   "one the still tables compare as 'full'); a technique without one has its final image's flicker "
                   "only.\n\n";
  int failed = 0;
  for (const SuiteScene& scene : scenes) {
    const TemporalReference ref = temporalReference(scene.argument, frames, base.width, base.height, spp, cache);
    report["references"].push_back({{"scene", ref.scene}, {"spp", spp}, {"mean_flicker", ref.meanFlicker},
                                    {"noise_floor", ref.noiseFloor}, {"energy", ref.energy}, {"flicker", ref.flicker},
                                    {"seconds", ref.seconds}});
    md += "### " + ref.scene + "\n\nReference: the path tracer at " + std::to_string(spp) + " spp, mean flicker " +
          fmt("%.4g", ref.meanFlicker) + ", noise floor " + fmt("%.4g", ref.noiseFloor) + ".\n\n" +
          "| technique | flicker | flicker / reference | energy ratio (mean) | min | max | s |\n|---|---:|---:|---:|---:|---:|---:|\n";
    for (const std::string& id : techniques) {
      RunRequest request = base;
      request.technique = id;
      request.scene = scene.argument;
      json cell = {{"technique", id}, {"scene", ref.scene}};
      try {
        const auto start = std::chrono::steady_clock::now();
        HeadlessSession session(request);
        FramesRequest fr;
        fr.frames = frames;
        fr.finalOnly = true;
        // The output compared with the reference: the last one of role "full" (the combined
        // image in linear radiance), else the final image.
        const Technique& t = session.cursor().technique();
        for (int i = 0; i < t.stageCount(); ++i)
          for (const OutputDesc& o : t.decl(i).outputs)
            if (!o.referenceMode.empty() && referenceRole(referenceModeUnder(o, session.cursor().params())) == "full")
              fr.measure = OutputAddress{t.id(), t.stage(i).id(), o.name, -1};
        cell["output"] = fr.measure ? fr.measure->str() : t.id() + "/" + t.finalStage() + "/" + t.finalOutput();
        const bool compared = fr.measure.has_value();
        const json m = runFrames(session, fr, (fs::path(out) / ref.scene / id).string());
        cell["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        cell["mean_flicker"] = m["temporal"]["mean_flicker"];
        if (!compared) {
          cell["not_compared"] = "no output of mode full: its final image's flicker only";
          md += "| " + id + " | " + fmt("%.4g", cell["mean_flicker"].get<double>()) +
                " | no output of mode full | | | | " + fmt("%.1f", cell["wall_s"].get<double>()) + " |\n";
          report["cells"].push_back(cell);
          continue;
        }
        cell["flicker_ratio"] = ref.meanFlicker > 0 ? m["temporal"]["mean_flicker"].get<double>() / ref.meanFlicker : 0.0;
        std::vector<double> ratios;
        for (size_t k = 0; k < m["temporal"]["energy"].size() && k < ref.energy.size(); ++k)
          ratios.push_back(ref.energy[k] > 0 ? m["temporal"]["energy"][k].get<double>() / ref.energy[k] : 0.0);
        double sum = 0.0;
        for (double r : ratios) sum += r;
        cell["energy_ratio"] = ratios;
        cell["energy_ratio_mean"] = ratios.empty() ? 0.0 : sum / double(ratios.size());
        cell["energy_ratio_min"] = ratios.empty() ? 0.0 : *std::min_element(ratios.begin(), ratios.end());
        cell["energy_ratio_max"] = ratios.empty() ? 0.0 : *std::max_element(ratios.begin(), ratios.end());
        md += "| " + id + " | " + fmt("%.4g", cell["mean_flicker"].get<double>()) + " | " +
              fmt("%.2f", cell["flicker_ratio"].get<double>()) + " | " + fmt("%.2f", cell["energy_ratio_mean"].get<double>()) +
              " | " + fmt("%.2f", cell["energy_ratio_min"].get<double>()) + " | " +
              fmt("%.2f", cell["energy_ratio_max"].get<double>()) + " | " + fmt("%.1f", cell["wall_s"].get<double>()) + " |\n";
      } catch (const std::exception& e) {
        cell["error"] = e.what();
        ++failed;
        md += "| " + id + " | failed: " + e.what() + " | | | | | |\n";
        std::fprintf(stderr, "voxlab fidelity: %s on %s failed: %s\n", id.c_str(), ref.scene.c_str(), e.what());
      }
      report["cells"].push_back(cell);
    }
    md += "\n";
  }
  fs::create_directories(out);
  std::ofstream(fs::path(out) / "fidelity.json") << report.dump(2) << "\n";
  std::ofstream(fs::path(out) / "fidelity.md") << md;
  std::printf("voxlab fidelity: %zu techniques x %zu animated scenes, %d frames each, written to %s/fidelity.{json,md}\n",
              techniques.size(), scenes.size(), frames, out.c_str());
  return failed > 0 ? 1 : 0;
}

// --- the command --------------------------------------------------------------------------------------

int runFidelity(const std::vector<std::string>& argv) {
  Args args("fidelity", argv,
            {{"--scene", true, true, "scene name or glTF path, repeatable (default: every scene of scenes/suite.json)"},
             {"--technique", true, true, "technique id, repeatable (default: every technique)"},
             {"--set", true, true, "NAME=VALUE override for every technique that declares NAME, repeatable"},
             {"--size", true, false, "image size WIDTHxHEIGHT (default 256x256; the references' size or a divisor of it)"},
             {"--check", true, false, "bands file (JSON): exit 1 naming every number outside its band"},
             {"--frames", true, false, "N: the animated scenes over N frames: flicker and energy per frame against the reference animation"},
             {"--reference-spp", true, false, "--frames: samples per pixel of the reference frames (default 64)"},
             {"--out", true, false, "folder for fidelity.json, fidelity.md, fidelity.html and the runs"}});
  if (args.has("--frames")) {
    const int frames = Args::parseInt("--frames", args.get("--frames"), 2, 1000);
    std::vector<std::string> ids = args.has("--technique") ? args.all("--technique") : techniqueIds();
    for (const std::string& id : ids) createTechnique(id);  // unknown id: one line listing the valid ones
    return runTemporalFidelity(args, ids, frames);
  }
  const std::string out = args.require("--out");
  RunRequest base;
  base.width = base.height = 256;
  if (args.has("--size")) Args::parseSize(args.get("--size"), base.width, base.height);

  // Validate everything before the first run: scenes, techniques, parameters, bands.
  const std::vector<SuiteScene> suite = readSuite();
  std::vector<SuiteScene> scenes;
  if (args.has("--scene")) {
    for (const std::string& name : args.all("--scene")) {
      const Scene loaded = loadScene(resolveScenePath(name));  // bad scene: one line listing the valid ones
      SuiteScene s{loaded.name, name, false, false, ""};
      for (const auto& known : suite)
        if (known.name == loaded.name && resolveScenePath(known.argument) == resolveScenePath(name)) s = known;
      scenes.push_back(s);
    }
  } else {
    scenes = suite;
  }
  std::vector<std::string> techniques = args.has("--technique") ? args.all("--technique") : techniqueIds();
  std::map<std::string, std::vector<std::string>> setsOf;  // technique -> the --set it declares
  std::set<std::string> usedSets;
  for (const std::string& id : techniques) {
    auto technique = createTechnique(id);  // unknown id: one line listing the valid ones
    const ParamSet params = technique->defaultParams();
    for (const std::string& set : args.all("--set")) {
      const auto eq = set.find('=');
      if (eq == std::string::npos || eq == 0) throw Error("--set '" + set + "' is not NAME=VALUE");
      if (!params.has(set.substr(0, eq))) continue;
      setsOf[id].push_back(set);
      usedSets.insert(set);
    }
  }
  for (const std::string& set : args.all("--set"))
    if (!usedSets.count(set))
      throw Error("--set " + set + ": no technique of this run declares " + set.substr(0, set.find('=')) +
                  " (voxlab list names each technique's parameters)");
  const std::vector<Band> bands = args.has("--check") ? readBands(args.get("--check")) : std::vector<Band>{};

  json report = {{"size", std::to_string(base.width) + "x" + std::to_string(base.height)},
                 {"sets", args.all("--set")},
                 {"scenes", json::array()},
                 {"techniques", techniques},
                 {"cells", json::array()}};
  for (const auto& s : scenes)
    report["scenes"].push_back({{"name", s.name}, {"interior", s.interior}, {"in_suite", s.inSuite}, {"tests", s.tests}});

  ProgressBar progress("fidelity");
  const size_t total = scenes.size() * techniques.size();
  size_t done = 0;
  int failed = 0;
  const auto start = std::chrono::steady_clock::now();
  for (const auto& scene : scenes)
    for (const std::string& id : techniques) {
      progress.update(int(done), int(total), id + " on " + scene.name);
      RunRequest request = base;
      request.technique = id;
      request.scene = scene.argument;
      request.sets = setsOf[id];
      json cell;
      try {
        cell = runCell(request, scene.name, out, scene.name + "/" + id);
      } catch (const std::exception& e) {
        cell = {{"technique", id}, {"scene", scene.name}, {"error", e.what()}};
        ++failed;
        progress.finish();
        std::fprintf(stderr, "voxlab fidelity: %s on %s failed: %s\n", id.c_str(), scene.name.c_str(), e.what());
      }
      report["cells"].push_back(cell);
      ++done;
    }
  progress.update(int(total), int(total), "done");
  progress.finish();
  report["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // The bands: every number of every matching cell.
  std::vector<std::string> outside;
  for (auto& cell : report["cells"]) {
    if (cell.contains("error")) continue;
    const std::string tid = cell["technique"], sname = cell["scene"];
    bool interior = false;
    for (const auto& s : scenes)
      if (s.name == sname) interior = s.interior;
    for (const Band& band : bands) {
      if ((band.technique != "*" && band.technique != tid) || band.except.count(tid)) continue;
      if (band.scene == "interior" ? !interior : (band.scene != "*" && band.scene != sname)) continue;
      if (band.sceneExcept.count(sname)) continue;
      const json* o = outputOfRole(cell, band.role);
      if (!o) continue;  // the technique has no output of this kind
      auto value = metricOf(cell, band.role, band.metric);
      std::string line = tid + " on " + sname + ": " + band.role + " (" + (*o)["address"].get<std::string>() + ", " +
                         (*o)["mode"].get<std::string>() + ") " + band.metric + " ";
      if (!value) {
        outside.push_back(line + "not measured (no reference image)");
      } else if (*value < band.lo || *value > band.hi) {
        outside.push_back(line + fmt("%.4g", *value) + " outside [" + fmt("%.4g", band.lo) + ", " + fmt("%.4g", band.hi) +
                          "]" + (band.why.empty() ? "" : " (" + band.why + ")"));
      } else {
        continue;
      }
      cell["out_of_band"][band.role] = true;
    }
  }

  fs::create_directories(out);
  std::ofstream(fs::path(out) / "fidelity.json") << report.dump(2) << "\n";
  std::ofstream(fs::path(out) / "fidelity.md")
      << "## Fidelity: every technique on every scene\n\nWritten by `voxlab fidelity` (" << report["size"].get<std::string>()
      << ", camera 0, default parameters" << (args.has("--set") ? " with the --set overrides in fidelity.json" : "")
      << "). Energy ratio: the output's mean over the reference's; SSIM of the luminance in brackets.\n\n"
      << markdownTables(report);
  std::ofstream(fs::path(out) / "fidelity.html") << htmlPage(report);
  std::printf("voxlab fidelity: %zu techniques x %zu scenes in %.0f s, written to %s/fidelity.{json,md,html}\n",
              techniques.size(), scenes.size(), report["wall_s"].get<double>(), out.c_str());
  for (const std::string& line : outside) std::fprintf(stderr, "voxlab fidelity: %s\n", line.c_str());
  if (!bands.empty())
    std::printf("voxlab fidelity: %zu numbers outside their bands (%zu bands checked)\n", outside.size(), bands.size());
  return failed > 0 || !outside.empty() ? 1 : 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("fidelity",
                        "voxlab fidelity [--scene S]... [--technique T]... [--set NAME=VALUE]... [--size WxH] "
                        "[--check BANDS.json] [--frames N [--reference-spp S]] --out DIR",
                        "every technique on every scene of the suite against the reference: energy, RMSE, SSIM, time",
                        &runFidelity);

}  // namespace voxlab
