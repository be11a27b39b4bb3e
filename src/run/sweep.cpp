// Sweeps (run/sweep.h): the swept values, the runs, the plots and the page.
#include "run/sweep.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "core/error.h"
#include "core/html.h"
#include "core/paths.h"
#include "graph/reference_mode.h"
#include "graph/resource_budget.h"
#include "graph/technique.h"
#include "run/bench_runs.h"
#include "run/reference_error.h"
#include "run/session.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kMaxSteps = 64;   // values of one parameter
constexpr int kMaxRuns = 256;   // runs of one sweep (the grid of two parameters)

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// --- the swept parameters --------------------------------------------------------------------------

struct SweptParam {
  ParamDesc desc;
  std::vector<double> values;  // in the order given (a range: ascending from FROM to TO)
  std::string text(size_t i) const { return desc.format(values[i]); }
  // Choices, booleans, and a list holding "scene" (a value with no place on a number line) are
  // plotted as categories in the order given.
  bool categorical() const {
    return desc.type == ParamType::Choice || desc.type == ParamType::Bool ||
           std::any_of(values.begin(), values.end(), ParamDesc::isSceneValue);
  }
};

std::vector<std::string> split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (;;) {
    const size_t end = text.find(separator, start);
    parts.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) return parts;
    start = end + 1;
  }
}

bool isCategory(const ParamDesc& desc) { return desc.type == ParamType::Choice || desc.type == ParamType::Bool; }

// "NAME=V1,V2,..." or "NAME=FROM:TO:STEPS", validated against the technique's declaration.
SweptParam parseSweptParam(const std::string& text, const ParamSet& params, const std::string& label) {
  const std::string form = " (valid: NAME=V1,V2,... or NAME=FROM:TO:STEPS, e.g. cone.aperture=30,45,60 or "
                           "cone.aperture=30:60:4)";
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw Error(label + " '" + text + "' is not NAME=VALUES" + form);
  const std::string name = text.substr(0, eq), rest = text.substr(eq + 1);
  SweptParam p;
  try {
    p.desc = params.desc(name);  // unknown: one line listing the technique's parameters
  } catch (const Error& e) {
    throw Error(label + ": " + e.what());
  }
  const std::string where = label + " " + text + ": ";
  if (rest.find(':') != std::string::npos) {
    const std::vector<std::string> f = split(rest, ':');
    if (f.size() != 3)
      throw Error(where + "a range is FROM:TO:STEPS with STEPS an integer 2.." + std::to_string(kMaxSteps));
    if (isCategory(p.desc))
      throw Error(where + name + " is a " + p.desc.typeName() + " (valid: " + p.desc.rangeText() +
                  "); a range needs an int or float parameter, give a list of values");
    double from = 0, to = 0;
    try {
      from = p.desc.parse(f[0]);
      to = p.desc.parse(f[1]);
    } catch (const Error& e) {
      throw Error(where + e.what());
    }
    char* end = nullptr;
    const long steps = std::strtol(f[2].c_str(), &end, 10);
    if (f[2].empty() || *end != '\0' || steps < 2 || steps > kMaxSteps)
      throw Error(where + "STEPS '" + f[2] + "' is not an integer 2.." + std::to_string(kMaxSteps));
    if (ParamDesc::isSceneValue(from) || ParamDesc::isSceneValue(to))
      throw Error(where + "a range runs between numbers (valid: " + p.desc.rangeText() + "); give \"scene\" in a list");
    if (from >= to) throw Error(where + "FROM must be below TO");
    for (long i = 0; i < steps; ++i) {
      const double t = double(i) / double(steps - 1);
      double v = from + (to - from) * t;
      if (p.desc.powerOfTwo) v = std::exp2(std::round(std::log2(from) + (std::log2(to) - std::log2(from)) * t));
      else if (p.desc.type == ParamType::Int) v = std::round(v);
      if (!p.values.empty() && v == p.values.back())
        throw Error(where + std::to_string(steps) + " steps from " + f[0] + " to " + f[1] + " repeat values (" +
                    name + " is " + p.desc.rangeText() + "); take fewer steps");
      p.values.push_back(v);
    }
  } else {
    for (const std::string& value : split(rest, ',')) {
      double v = 0;
      try {
        v = p.desc.parse(value);
      } catch (const Error& e) {
        throw Error(where + e.what());
      }
      for (double seen : p.values)
        if (ParamDesc::sameValue(seen, v)) throw Error(where + "the value " + value + " is given twice");
      p.values.push_back(v);
    }
    if (p.values.size() > size_t(kMaxSteps))
      throw Error(where + std::to_string(p.values.size()) + " values; at most " + std::to_string(kMaxSteps));
  }
  if (p.values.size() < 2) throw Error(where + "a sweep needs at least two values" + form);
  // What the run will be given is the formatted value: keep the value that text parses back to.
  for (double& v : p.values) v = p.desc.parse(p.desc.format(v));
  return p;
}

// --- one run ---------------------------------------------------------------------------------------


json number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// Runs the request once untimed (shader compilation included: "first_cpu_ms") and then
// 'repeats' timed times in the same session, as `voxlab bench` does; the last run writes its
// outputs. A stage's time is its median over the timed runs (each in cpu_ms_runs), the total
// their sum.
json runOne(const RunRequest& request, const std::string& outDir, const std::string& rel, int repeats) {
  const auto start = std::chrono::steady_clock::now();
  HeadlessSession session(request);
  const Technique& t = session.cursor().technique();
  session.demand(false, finalAndComparedOutputs(t));  // timed for what is compared, as fidelity runs
  const StageTimes times = timeStages(session.cursor(), repeats);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::string dir = (fs::path(outDir) / rel).string();
  json manifest = session.writeOutputs(dir, false, finalAndComparedOutputs(t));

  json run = {{"dir", rel},
              {"wall_s", wall},
              {"resource_bytes", manifest["resource_bytes"]},
              {"stages", json::array()},
              {"outputs", json::array()}};
  if (manifest.contains("references_skipped")) run["references_skipped"] = manifest["references_skipped"];
  double totalCpu = 0, totalGpu = 0;
  size_t index = 0;
  for (const auto& s : manifest["stages"]) {
    const std::string stage = s["id"].get<std::string>();
    const double cpu = median(times.cpu[index]), gpu = median(times.gpu[index]);
    totalCpu += cpu, totalGpu += gpu;
    json entry = {{"id", stage}, {"cpu_ms", cpu}, {"gpu_ms", gpu}, {"first_cpu_ms", times.first[index]}};
    if (repeats > 1) entry["cpu_ms_runs"] = times.cpu[index];
    run["stages"].push_back(entry);
    ++index;
    for (const auto& e : s["outputs"]) {
      const OutputDesc* desc = t.findOutput(stage, e["name"].get<std::string>()).second;
      std::string png = manifestFileEndingWith(e, stage + "." + desc->name + ".png");
      if (png.empty()) png = manifestFileEndingWith(e, ".png");
      if (e["final"].get<bool>() && !png.empty()) run["final_image"] = rel + "/" + png;
      if (desc->referenceMode.empty()) continue;
      const std::string mode = referenceModeUnder(*desc, session.cursor().params());
      json o = {{"address", e["address"]}, {"mode", mode}, {"role", referenceRole(mode)}};
      if (!png.empty()) o["image"] = rel + "/" + png;
      if (!e.contains("reference_error")) {
        o["reference_missing"] = "no reference image of mode " + mode + " for this scene";
      } else if (e["reference_error"].contains("skipped")) {
        o["skipped"] = e["reference_error"]["skipped"];
      } else {
        const json& r = e["reference_error"];
        for (const char* metric : {"mean_ratio", "rmse", "ssim"}) o[metric] = r[metric];
        const std::string err = manifestFileEndingWith(e, ".error.png");
        if (!err.empty()) o["error_image"] = rel + "/" + err;
        // The reference through this output's display mapping, once per mode.
        const std::string refPng = "reference/" + mode + ".png";
        if (!fs::exists(fs::path(outDir) / refPng)) {
          fs::create_directories(fs::path(outDir) / "reference");
          writeReferencePng(*desc, projectPath(r["reference"].get<std::string>()), (fs::path(outDir) / refPng).string());
        }
        o["reference_image"] = refPng;
      }
      run["outputs"].push_back(o);
    }
  }
  run["total_cpu_ms"] = totalCpu;
  run["total_gpu_ms"] = totalGpu;
  return run;
}

// The compared output the plots use, by address: the last indirect one in stage order (the term
// the composite uses), else the last combined one, else the last direct one; "" when none.
std::string mainOutputAddress(const json& runs) {
  for (const char* role : {"indirect", "full", "direct"})
    for (const auto& run : runs) {
      if (!run.contains("outputs")) continue;
      std::string found;
      for (const auto& o : run["outputs"])
        if (o["role"] == role) found = o["address"].get<std::string>();
      if (!found.empty()) return found;
    }
  return "";
}

const json* outputAt(const json& run, const std::string& address) {
  if (!run.contains("outputs")) return nullptr;
  for (const auto& o : run["outputs"])
    if (o["address"] == address) return &o;
  return nullptr;
}

// --- plots -----------------------------------------------------------------------------------------

struct Tick {
  double value;
  std::string label;
};

struct Axis {
  std::string label;
  double lo = 0, hi = 1;
  bool log2 = false;
  std::vector<Tick> ticks;
  double position(double v) const {  // 0..1 along the axis
    const double a = log2 ? std::log2(lo) : lo, b = log2 ? std::log2(hi) : hi, x = log2 ? std::log2(v) : v;
    return b > a ? (x - a) / (b - a) : 0.5;
  }
};

// An axis from 0 (or the smallest value when it is far from 0) to a round number above every
// value, with 4-6 ticks at steps of 1, 2 or 5 times a power of ten.
Axis numberAxis(const std::string& label, const std::vector<double>& values, const char* tickFormat) {
  Axis a;
  a.label = label;
  double lo = INFINITY, hi = -INFINITY;
  for (double v : values)
    if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!std::isfinite(lo)) lo = 0, hi = 1;
  if (lo >= 0 && lo < 0.5 * hi) lo = 0;
  if (hi - lo < 1e-12) {
    const double pad = std::max(std::abs(hi) * 0.1, 1e-6);
    lo -= pad, hi += pad;
    if (lo < 0 && values.size() && *std::min_element(values.begin(), values.end()) >= 0) lo = 0;
  }
  const double rough = (hi - lo) / 5.0, power = std::pow(10.0, std::floor(std::log10(rough)));
  double step = power;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * power >= rough) {
      step = m * power;
      break;
    }
  a.lo = std::floor(lo / step + 1e-9) * step;
  a.hi = std::ceil(hi / step - 1e-9) * step;
  for (double v = a.lo; v <= a.hi + step * 0.5; v += step) a.ticks.push_back({v, fmt(tickFormat, std::abs(v) < step * 1e-6 ? 0.0 : v)});
  return a;
}

// The axis of a swept parameter: a tick at every value; powers of two on a log2 scale; choices and
// booleans as categories in the order given.
Axis paramAxis(const SweptParam& p) {
  Axis a;
  a.label = p.desc.name + (p.desc.unit.empty() ? "" : " (" + p.desc.unit + ")");
  const auto [mn, mx] = std::minmax_element(p.values.begin(), p.values.end());
  if (p.categorical()) {
    a.lo = -0.5, a.hi = double(p.values.size()) - 0.5;
    for (size_t i = 0; i < p.values.size(); ++i) a.ticks.push_back({double(i), p.text(i)});
    return a;
  }
  a.log2 = p.desc.powerOfTwo;
  const double span = *mx - *mn;
  a.lo = a.log2 ? *mn / std::sqrt(2.0) : *mn - 0.05 * span;
  a.hi = a.log2 ? *mx * std::sqrt(2.0) : *mx + 0.05 * span;
  for (size_t i = 0; i < p.values.size(); ++i) a.ticks.push_back({p.values[i], p.text(i)});
  return a;
}

// Where a parameter value lies on its axis (categories: the index in the order given).
double axisValue(const SweptParam& p, size_t index) { return p.categorical() ? double(index) : p.values[index]; }

// One run of the sweep: the indices of its values, and the --set assignments it runs with.
struct GridPoint {
  size_t i0, i1;
  std::vector<std::string> sets;
};

struct PlotPoint {
  int run;
  double x, y;
};

const char* const kSeriesColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};

// One SVG plot: axes with ticks and labels, lines through each series (points in order), a point
// per run (data-run="K"), the runs of 'front' joined by a dashed line and ringed, and a marker
// (class "marker") that the page's slider moves onto the shown run's point.
std::string svgPlot(const std::string& id, const std::string& title, const Axis& xa, const Axis& ya,
                    const std::vector<std::vector<PlotPoint>>& series, const std::vector<std::string>& seriesNames,
                    const std::vector<PlotPoint>& front, const std::string& note) {
  const double W = 460, H = seriesNames.size() > 1 ? 336 : 320, left = 70, right = 20, top = 34,
               bottom = seriesNames.size() > 1 ? 72 : 56;
  const double pw = W - left - right, ph = H - top - bottom;
  auto px = [&](double v) { return left + pw * xa.position(v); };
  auto py = [&](double v) { return top + ph * (1.0 - ya.position(v)); };
  std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" id=\"" + id + "\" width=\"" + fmt("%.0f", W) +
                  "\" height=\"" + fmt("%.0f", H) + "\" viewBox=\"0 0 " + fmt("%.0f", W) + " " + fmt("%.0f", H) +
                  "\" font-family=\"sans-serif\" font-size=\"11\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + fmt("%.1f", W / 2) + "\" y=\"18\" text-anchor=\"middle\" font-size=\"13\" font-weight=\"bold\">" +
       htmlEscape(title) + "</text>\n";
  for (const Tick& t : xa.ticks) {
    const double x = px(t.value);
    s += "<line x1=\"" + fmt("%.1f", x) + "\" y1=\"" + fmt("%.1f", top) + "\" x2=\"" + fmt("%.1f", x) + "\" y2=\"" +
         fmt("%.1f", top + ph + 5) + "\" stroke=\"#e4e4e4\"/>\n";
    s += "<text x=\"" + fmt("%.1f", x) + "\" y=\"" + fmt("%.1f", top + ph + 18) + "\" text-anchor=\"middle\">" +
         htmlEscape(t.label) + "</text>\n";
  }
  for (const Tick& t : ya.ticks) {
    const double y = py(t.value);
    s += "<line x1=\"" + fmt("%.1f", left - 5) + "\" y1=\"" + fmt("%.1f", y) + "\" x2=\"" + fmt("%.1f", left + pw) +
         "\" y2=\"" + fmt("%.1f", y) + "\" stroke=\"#e4e4e4\"/>\n";
    s += "<text x=\"" + fmt("%.1f", left - 8) + "\" y=\"" + fmt("%.1f", y + 4) + "\" text-anchor=\"end\">" +
         htmlEscape(t.label) + "</text>\n";
  }
  s += "<rect x=\"" + fmt("%.1f", left) + "\" y=\"" + fmt("%.1f", top) + "\" width=\"" + fmt("%.1f", pw) + "\" height=\"" +
       fmt("%.1f", ph) + "\" fill=\"none\" stroke=\"#444\"/>\n";
  s += "<text x=\"" + fmt("%.1f", left + pw / 2) + "\" y=\"" + fmt("%.1f", top + ph + 36) + "\" text-anchor=\"middle\">" +
       htmlEscape(xa.label) + "</text>\n";
  s += "<text transform=\"translate(16," + fmt("%.1f", top + ph / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
       htmlEscape(ya.label) + "</text>\n";
  if (!note.empty())
    s += "<text x=\"" + fmt("%.1f", left + pw / 2) + "\" y=\"" + fmt("%.1f", top + ph / 2) +
         "\" text-anchor=\"middle\" fill=\"#888\">" + htmlEscape(note) + "</text>\n";
  if (front.size() > 1) {  // a staircase: the best error for any time budget
    std::string d = "M" + fmt("%.1f", px(front[0].x)) + "," + fmt("%.1f", py(front[0].y));
    for (size_t i = 1; i < front.size(); ++i)
      d += " H" + fmt("%.1f", px(front[i].x)) + " V" + fmt("%.1f", py(front[i].y));
    s += "<path class=\"pareto\" d=\"" + d + "\" fill=\"none\" stroke=\"#2ca02c\" stroke-width=\"1.5\" stroke-dasharray=\"5,3\"/>\n";
  }
  for (const PlotPoint& p : front)
    s += "<circle class=\"pareto\" cx=\"" + fmt("%.1f", px(p.x)) + "\" cy=\"" + fmt("%.1f", py(p.y)) +
         "\" r=\"7\" fill=\"none\" stroke=\"#2ca02c\" stroke-width=\"2\"/>\n";
  for (size_t k = 0; k < series.size(); ++k) {
    const char* colour = kSeriesColours[k % (sizeof kSeriesColours / sizeof *kSeriesColours)];
    if (series[k].size() > 1) {
      std::string pts;
      for (const PlotPoint& p : series[k]) pts += fmt("%.1f", px(p.x)) + "," + fmt("%.1f", py(p.y)) + " ";
      s += "<polyline points=\"" + pts + "\" fill=\"none\" stroke=\"" + colour + "\" stroke-width=\"1.5\"/>\n";
    }
    for (const PlotPoint& p : series[k])
      s += "<circle class=\"point\" data-run=\"" + std::to_string(p.run) + "\" cx=\"" + fmt("%.1f", px(p.x)) + "\" cy=\"" +
           fmt("%.1f", py(p.y)) + "\" r=\"3.5\" fill=\"" + colour + "\"><title>run " + std::to_string(p.run) +
           "</title></circle>\n";
  }
  // The legend of the series, in a row under the axis label.
  double legendX = left;
  for (size_t k = 0; seriesNames.size() > 1 && k < seriesNames.size(); ++k) {
    const char* colour = kSeriesColours[k % (sizeof kSeriesColours / sizeof *kSeriesColours)];
    const double width = 14 + 6.2 * double(seriesNames[k].size());
    if (legendX + width > W && legendX > left) break;  // what does not fit is left out (the table of sweep.html names every run)
    s += "<rect x=\"" + fmt("%.1f", legendX) + "\" y=\"" + fmt("%.1f", H - 14) + "\" width=\"9\" height=\"9\" fill=\"" +
         colour + "\"/><text x=\"" + fmt("%.1f", legendX + 12) + "\" y=\"" + fmt("%.1f", H - 6) + "\">" +
         htmlEscape(seriesNames[k]) + "</text>\n";
    legendX += width + 10;
  }
  s += "<circle class=\"marker\" cx=\"-100\" cy=\"-100\" r=\"9\" fill=\"none\" stroke=\"#000\" stroke-width=\"2\"/>\n";
  s += "</svg>\n";
  return s;
}

// The runs that no other run beats on both time and error (ties on one: the better other), by time.
std::vector<PlotPoint> paretoFront(std::vector<PlotPoint> points) {
  std::sort(points.begin(), points.end(),
            [](const PlotPoint& a, const PlotPoint& b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  std::vector<PlotPoint> front;
  for (const PlotPoint& p : points)
    if (front.empty() || p.y < front.back().y) front.push_back(p);
  return front;
}

// --- the page --------------------------------------------------------------------------------------

std::string htmlPage(const json& report, const std::vector<std::string>& svgs) {
  std::string html =
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>voxlab sweep: " +
      htmlEscape(report["technique"].get<std::string>()) +
      "</title>\n<style>\n"
      "body { font-family: sans-serif; margin: 1.5em; color: #222; }\n"
      ".images figure { display: inline-block; margin: 0 1em 0 0; text-align: center; font-size: 0.85em; }\n"
      ".images img { width: 256px; height: 256px; image-rendering: pixelated; background: #eee; }\n"
      ".plots svg { margin: 0 0.5em 0.5em 0; border: 1px solid #ddd; }\n"
      "table { border-collapse: collapse; font-size: 0.85em; } td, th { border: 1px solid #ddd; padding: 0.2em 0.5em; "
      "text-align: right; }\ntr.shown { background: #fff3b0; } code { background: #f3f3f3; }\n"
      "#slider { width: 30em; }\n</style>\n</head>\n<body>\n";
  html += "<h1>voxlab sweep: " + htmlEscape(report["technique"].get<std::string>()) + " on " +
          htmlEscape(report["scene"].get<std::string>()) + "</h1>\n<p>" + htmlEscape(report["size"].get<std::string>()) +
          ", camera 0";
  for (const auto& s : report["sets"]) html += ", <code>" + htmlEscape(s.get<std::string>()) + "</code>";
  html += ". Error: <b>" + htmlEscape(report["error"]["definition"].get<std::string>()) + "</b> of <code>" +
          htmlEscape(report["error"]["output"].get<std::string>()) + "</code> against the reference path tracer; time: " +
          htmlEscape(report["time"].get<std::string>()) + ".</p>\n";
  const int runs = int(report["runs"].size());
  html += "<p><label for=\"slider\">run</label> <input type=\"range\" id=\"slider\" min=\"0\" max=\"" +
          std::to_string(runs - 1) + "\" step=\"1\" value=\"0\"> <span id=\"run-label\"></span></p>\n";
  html += "<div class=\"images\">"
          "<figure><img id=\"final\" alt=\"final image\"><figcaption>final image</figcaption></figure>"
          "<figure><img id=\"compared\" alt=\"compared output\"><figcaption>compared output</figcaption></figure>"
          "<figure><img id=\"error-image\" alt=\"error image\"><figcaption>error against the reference</figcaption></figure>"
          "<figure><img id=\"reference\" alt=\"reference\"><figcaption>reference</figcaption></figure></div>\n";
  html += "<div class=\"plots\">\n";
  for (const std::string& svg : svgs) html += svg;
  html += "</div>\n<table id=\"runs\">\n<tr><th>run</th>";
  for (const auto& p : report["parameters"]) html += "<th>" + htmlEscape(p["name"].get<std::string>()) + "</th>";
  html += "<th>error</th><th>energy ratio</th><th>RMSE</th><th>SSIM</th><th>time (ms)</th><th>GPU memory</th><th>Pareto</th></tr>\n";
  json data = json::array();
  for (const auto& run : report["runs"]) {
    const int k = run["index"].get<int>();
    html += "<tr id=\"row-" + std::to_string(k) + "\"><td>" + std::to_string(k) + "</td>";
    std::string label;
    for (const auto& p : report["parameters"]) {  // in the order given (run["values"] is sorted by name)
      const std::string name = p["name"].get<std::string>(), value = run["values"][name].get<std::string>();
      html += "<td>" + htmlEscape(value) + "</td>";
      label += (label.empty() ? "" : ", ") + name + "=" + value;
    }
    auto cell = [&](const char* key, const char* format) {
      return run.contains(key) && run[key].is_number() ? fmt(format, run[key].get<double>()) : std::string("-");
    };
    const json* main = run.contains("main") ? &run["main"] : nullptr;
    auto mainCell = [&](const char* key, const char* format) {
      return main && main->contains(key) && (*main)[key].is_number() ? fmt(format, (*main)[key].get<double>()) : std::string("-");
    };
    if (run.contains("failed")) {
      html += "<td colspan=\"7\">failed: " + htmlEscape(run["failed"].get<std::string>()) + "</td></tr>\n";
    } else {
      html += "<td>" + cell("error", "%.4f") + "</td><td>" + mainCell("mean_ratio", "%.3f") + "</td><td>" +
              mainCell("rmse", "%.4f") + "</td><td>" + mainCell("ssim", "%.3f") + "</td><td>" +
              cell("time_ms", "%.0f") + "</td><td>" +
              formatBytes(run["resource_bytes"].get<size_t>()) + "</td><td>" +
              (run.value("pareto", false) ? "yes" : "") + "</td></tr>\n";
    }
    data.push_back({{"label", label},
                    {"final", run.value("final_image", "")},
                    {"compared", main ? main->value("image", "") : ""},
                    {"error", main ? main->value("error_image", "") : ""},
                    {"reference", main ? main->value("reference_image", "") : ""}});
  }
  html += "</table>\n";
  // The slider: swaps the images, moves the marker of every plot onto the run's point (hidden when
  // the run has none there), highlights the run's row. "#run=K" in the address opens run K.
  html += "<script>\nvar runs = " + data.dump() + ";\n" +
          "var slider = document.getElementById('slider');\n"
          "function show(k) {\n"
          "  var r = runs[k]; slider.value = k;\n"
          "  document.getElementById('run-label').textContent = 'run ' + k + ': ' + r.label;\n"
          "  [['final', r.final], ['compared', r.compared], ['error-image', r.error], ['reference', r.reference]]"
          ".forEach(function (p) { var img = document.getElementById(p[0]); if (p[1]) img.setAttribute('src', p[1]); "
          "else img.removeAttribute('src'); });\n"
          "  document.querySelectorAll('.plots svg').forEach(function (svg) {\n"
          "    var point = svg.querySelector('[data-run=\"' + k + '\"]'), marker = svg.querySelector('.marker');\n"
          "    marker.setAttribute('cx', point ? point.getAttribute('cx') : -100);\n"
          "    marker.setAttribute('cy', point ? point.getAttribute('cy') : -100);\n"
          "  });\n"
          "  document.querySelectorAll('#runs tr').forEach(function (tr) { tr.className = tr.id == 'row-' + k ? 'shown' : ''; });\n"
          "}\n"
          "slider.addEventListener('input', function () { show(parseInt(slider.value, 10)); });\n"
          "var asked = /run=(\\d+)/.exec(location.hash);\n"
          "show(asked && +asked[1] < runs.length ? +asked[1] : 0);\n"
          "</script>\n</body>\n</html>\n";
  return html;
}

// The error of every run ("error", and "main": the main compared output's entry) and the
// report's "error" (what it is and of which output).
void assignErrors(json& report, const std::string& errorKind) {
  const std::string mainAddress = mainOutputAddress(report["runs"]);
  const std::string definition = errorKind == "ssim" ? "1 - SSIM" : "|1 - energy ratio|";
  std::string mainRole;
  for (auto& run : report["runs"]) {
    const json* o = outputAt(run, mainAddress);
    if (!o) continue;
    run["main"] = *o;
    mainRole = (*o)["role"].get<std::string>();
    const char* metric = errorKind == "ssim" ? "ssim" : "mean_ratio";
    if (o->contains(metric) && (*o)[metric].is_number())
      run["error"] = number(errorKind == "ssim" ? 1.0 - (*o)[metric].get<double>() : std::abs(1.0 - (*o)[metric].get<double>()));
  }
  report["error"] = {{"definition", definition},
                     {"metric", errorKind},
                     {"output", mainAddress.empty() ? std::string("none") : mainAddress},
                     {"role", mainRole}};

}

// The three plots (SVG) of a sweep; marks the runs of the Pareto front ("pareto": true).
std::vector<std::string> plotSweep(json& report, const std::vector<SweptParam>& swept,
                                   const std::vector<GridPoint>& points, const std::string& timeLabel) {
  const size_t n1 = swept.size() > 1 ? swept[1].values.size() : 1;
  const std::string definition = report["error"]["definition"], mainRole = report["error"]["role"];
  const std::string mainAddress = report["error"]["output"] == "none" ? "" : report["error"]["output"].get<std::string>();
  std::vector<PlotPoint> errorByTime;
  std::vector<std::vector<PlotPoint>> errorSeries(n1), timeSeries(n1), tradeSeries(n1);
  std::vector<double> errors, times;
  for (const auto& run : report["runs"]) {
    if (run.contains("failed")) continue;
    const int k = run["index"].get<int>();
    const GridPoint& p = points[size_t(k)];
    const double x = axisValue(swept[0], p.i0), t = run["time_ms"].get<double>();
    timeSeries[p.i1].push_back({k, x, t});
    times.push_back(t);
    if (!run.contains("error") || !run["error"].is_number()) continue;
    const double e = run["error"].get<double>();
    errorSeries[p.i1].push_back({k, x, e});
    tradeSeries[p.i1].push_back({k, t, e});
    errorByTime.push_back({k, t, e});
    errors.push_back(e);
  }
  const std::vector<PlotPoint> front = paretoFront(errorByTime);
  for (const PlotPoint& p : front) report["runs"][size_t(p.run)]["pareto"] = true;
  std::vector<std::string> seriesNames;
  if (swept.size() > 1)
    for (size_t i = 0; i < n1; ++i) seriesNames.push_back(swept[1].desc.name + "=" + swept[1].text(i));
  const std::string errorLabel = definition + " (" + (mainRole.empty() ? std::string("no compared output") : mainRole) + ")";
  const std::string noError = mainAddress.empty()           ? "no output of this technique is compared"
                              : errors.empty()               ? "no reference to compare with"
                                                             : "";
  const Axis valueAxis = paramAxis(swept[0]);
  const Axis errorAxis = numberAxis(errorLabel, errors, "%.3g");
  const Axis timeAxis = numberAxis(timeLabel, times, "%.0f");
  // Error against time: each series joined in the order of the swept value (the path the
  // parameter takes through the trade-off), the Pareto front ringed.
  return {
      svgPlot("error-by-value", "error against " + swept[0].desc.name, valueAxis, errorAxis, errorSeries, seriesNames, {},
              noError),
      svgPlot("time-by-value", "time against " + swept[0].desc.name, valueAxis, timeAxis, timeSeries, seriesNames, {}, ""),
      svgPlot("error-by-time", "error against time (green: the Pareto front)", timeAxis, errorAxis, tradeSeries, seriesNames, front, noError)};
}

// The CPU time of the named stages of a run (all of them when none is named).
double timeOfStages(const json& run, const std::vector<std::string>& stages) {
  double ms = 0;
  for (const auto& stage : run["stages"])
    if (stages.empty() || std::find(stages.begin(), stages.end(), stage["id"].get<std::string>()) != stages.end())
      ms += stage["cpu_ms"].get<double>();
  return ms;
}


// A validated request: the parameters swept and every run's assignments.
struct SweepPlan {
  std::vector<SweptParam> swept;
  std::vector<GridPoint> points;  // the first parameter outermost
};

SweepPlan planSweep(const SweepRequest& request, const std::string& paramLabel) {
  if (request.error != "ssim" && request.error != "energy")
    throw Error("--error '" + request.error + "' is not valid; valid: ssim (1 - SSIM), energy (|1 - energy ratio|)");
  const auto declared = createTechnique(request.technique);  // unknown id: one line listing the valid ones
  const ParamSet defaults = declared->defaultParams();
  for (const std::string& id : request.timeStages) {
    try {
      declared->stageIndex(id);
    } catch (const Error& e) {
      throw Error(std::string("--time-stage: ") + e.what());
    }
  }
  if (request.params.empty() || request.params.size() > 2)
    throw Error("'sweep' needs one or two " + paramLabel + " NAME=V1,V2,... (or NAME=FROM:TO:STEPS); got " +
                std::to_string(request.params.size()));
  SweepPlan plan;
  for (const std::string& text : request.params) plan.swept.push_back(parseSweptParam(text, defaults, paramLabel));
  const std::vector<SweptParam>& swept = plan.swept;
  if (swept.size() == 2 && swept[0].desc.name == swept[1].desc.name)
    throw Error(paramLabel + " " + swept[0].desc.name + " is given twice; sweep two different parameters");
  ParamSet fixed = defaults;
  for (const std::string& set : request.sets) {
    fixed.setAssignment(set);  // one line naming the parameter and its valid values
    const std::string name = set.substr(0, set.find('='));
    for (const SweptParam& p : swept)
      if (p.desc.name == name || name.rfind(p.desc.name + ".", 0) == 0)
        throw Error("--set " + set + ": " + p.desc.name + " is the swept parameter (" + paramLabel +
                    "); drop one of them");
  }
  const size_t n0 = swept[0].values.size(), n1 = swept.size() > 1 ? swept[1].values.size() : 1;
  if (n0 * n1 > size_t(kMaxRuns))
    throw Error("the sweep has " + std::to_string(n0 * n1) + " runs; at most " + std::to_string(kMaxRuns));
  for (size_t i0 = 0; i0 < n0; ++i0)
    for (size_t i1 = 0; i1 < n1; ++i1) {
      GridPoint p{i0, i1, request.sets};
      p.sets.push_back(swept[0].desc.name + "=" + swept[0].text(i0));
      if (swept.size() > 1) p.sets.push_back(swept[1].desc.name + "=" + swept[1].text(i1));
      ParamSet check = fixed;
      for (const std::string& s : p.sets) check.setAssignment(s);
      plan.points.push_back(p);
    }
  return plan;
}

}  // namespace

void validateSweep(const SweepRequest& request, const std::string& paramLabel) { planSweep(request, paramLabel); }

std::vector<std::string> sweepValueTexts(const std::string& technique, const std::string& param,
                                         const std::string& paramLabel) {
  const SweptParam p = parseSweptParam(param, createTechnique(technique)->defaultParams(), paramLabel);
  std::vector<std::string> texts;
  for (size_t i = 0; i < p.values.size(); ++i) texts.push_back(p.text(i));
  return texts;
}

std::vector<std::string> sweepArguments(const SweepRequest& request, const std::string& outDir) {
  std::vector<std::string> args = {"--technique", request.technique, "--scene", request.scene};
  for (const std::string& p : request.params) args.insert(args.end(), {"--param", p});
  for (const std::string& s : request.sets) args.insert(args.end(), {"--set", s});
  args.insert(args.end(), {"--size", std::to_string(request.width) + "x" + std::to_string(request.height)});
  if (request.repeats != 1) args.insert(args.end(), {"--repeat", std::to_string(request.repeats)});
  if (request.error != "ssim") args.insert(args.end(), {"--error", request.error});
  for (const std::string& t : request.timeStages) args.insert(args.end(), {"--time-stage", t});
  args.insert(args.end(), {"--out", outDir});
  return args;
}

json runSweep(const SweepRequest& request, const std::string& out, const SweepProgress& progress,
              const SweepFailure& onFailure) {
  const SweepPlan plan = planSweep(request, "--param");
  const std::vector<SweptParam>& swept = plan.swept;
  const std::vector<GridPoint>& points = plan.points;
  const Scene scene = loadScene(resolveScenePath(request.scene));  // bad scene: one line listing the valid ones
  RunRequest base;
  base.technique = request.technique;
  base.scene = request.scene;
  base.width = request.width;
  base.height = request.height;
  const std::vector<std::string>& timedStages = request.timeStages;
  const int repeats = request.repeats;

  json report = {{"technique", request.technique},
                 {"scene", scene.name},
                 {"size", std::to_string(base.width) + "x" + std::to_string(base.height)},
                 {"sets", request.sets},
                 {"parameters", json::array()},
                 {"time", (timedStages.empty() ? std::string("total CPU time of the stages")
                                               : "CPU time of " + joinNames(timedStages)) +
                              " (ms; each stage's execute() with a glFinish" +
                              std::string(repeats > 1 ? ", its median over the repeats" : "") +
                              "; after one untimed run that compiles the shaders)"},
                 {"time_stages", timedStages},
                 {"repeat", repeats},
                 {"runs", json::array()}};
  for (const SweptParam& p : swept) {
    json values = json::array();
    for (size_t i = 0; i < p.values.size(); ++i) values.push_back(p.text(i));
    report["parameters"].push_back({{"name", p.desc.name}, {"type", p.desc.typeName()}, {"unit", p.desc.unit},
                                    {"range", p.desc.rangeText()}, {"values", values}});
  }

  int failed = 0;
  const auto start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < points.size(); ++k) {
    const GridPoint& p = points[k];
    std::string label = swept[0].desc.name + "=" + swept[0].text(p.i0);
    if (swept.size() > 1) label += ", " + swept[1].desc.name + "=" + swept[1].text(p.i1);
    if (progress) progress(int(k), int(points.size()), label);
    RunRequest run1 = base;
    run1.sets = p.sets;
    json run;
    try {
      run = runOne(run1, out, "runs/" + fmt("%02.0f", double(k)), repeats);
    } catch (const std::exception& e) {
      run = {{"failed", e.what()}};
      ++failed;
      if (onFailure) onFailure(label, e.what());
      else std::fprintf(stderr, "voxlab sweep: %s failed: %s\n", label.c_str(), e.what());
    }
    if (!run.contains("failed")) run["time_ms"] = timeOfStages(run, timedStages);
    run["index"] = int(k);
    run["values"] = json::object();
    run["values"][swept[0].desc.name] = swept[0].text(p.i0);
    if (swept.size() > 1) run["values"][swept[1].desc.name] = swept[1].text(p.i1);
    report["runs"].push_back(run);
  }
  if (progress) progress(int(points.size()), int(points.size()), "done");
  report["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  report["failed_runs"] = failed;

  assignErrors(report, request.error);
  const std::vector<std::string> pages = plotSweep(
      report, swept, points,
      (timedStages.empty() ? std::string("CPU time of the stages") : "CPU time of " + joinNames(timedStages)) + " (ms)");

  fs::create_directories(out);
  const char* files[] = {"error-by-value.svg", "time-by-value.svg", "error-by-time.svg"};
  for (size_t i = 0; i < 3; ++i) std::ofstream(fs::path(out) / files[i]) << pages[i];
  report["plots"] = {files[0], files[1], files[2]};
  std::ofstream(fs::path(out) / "sweep.json") << report.dump(2) << "\n";
  std::ofstream(fs::path(out) / "sweep.html") << htmlPage(report, pages);
  return report;
}

}  // namespace voxlab
