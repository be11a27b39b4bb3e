// voxlab list [--json]: every technique with its stages, outputs and parameters, and the scenes.
#include <cstdio>

#include <nlohmann/json.hpp>

#include "app/command.h"
#include "core/args.h"
#include "core/error.h"
#include "graph/reference_mode.h"
#include "graph/resource_budget.h"
#include "graph/technique.h"
#include "scene/scene.h"

namespace voxlab {
namespace {

using nlohmann::json;

// What the technique allocates (graph/resource_budget.h) for a 512x512 view: at the defaults, per
// resource, and the total at every value of each power-of-two parameter that changes it.
json describeResources(const Technique& t) {
  ViewState view;  // 512x512, as `voxlab run` by default
  const ParamSet defaults = t.defaultParams();
  auto totalJson = [](const ResourceEstimate& e) { return json(e.totalBytes); };
  const ResourceEstimate atDefaults = estimateResources(t, defaults, view);
  json r;
  r["view"] = {view.width, view.height};
  r["memory_budget_bytes"] = size_t(defaults.getInt(memoryBudgetParam().name)) << 20;
  r["total_bytes"] = atDefaults.totalBytes;
  r["total"] = formatBytes(atDefaults.totalBytes);
  for (const auto& item : atDefaults.items) {
    json i = {{"stage", item.stage}, {"resource", item.resource}, {"bytes", item.bytes}};
    if (item.isTexture) i["size"] = item.is3D ? json{item.size.x, item.size.y, item.size.z} : json{item.size.x, item.size.y};
    if (item.pool) i["pool"] = true;  // a starting size: grows with the scene
    r["resources"].push_back(i);
  }
  for (const auto& [name, desc] : defaults.descs()) {
    if (desc.type != ParamType::Int || !desc.powerOfTwo) continue;
    json byValue = json::object();
    bool changes = false;
    for (long long v = 1; v <= (long long)desc.maxValue; v *= 2) {
      if (v < (long long)desc.minValue) continue;
      ParamSet p = defaults;
      p.set(name, double(v));
      const ResourceEstimate e = estimateResources(t, p, view);
      changes = changes || e.totalBytes != atDefaults.totalBytes;
      byValue[std::to_string(v)] = totalJson(e);
    }
    if (changes) r["total_bytes_by_parameter"][name] = byValue;
  }
  return r;
}

json describeTechnique(const Technique& t) {
  json j;
  j["id"] = t.id();
  j["title"] = t.title();
  j["summary"] = t.summary();
  j["final_output"] = t.id() + "/" + t.finalStage() + "/" + t.finalOutput();
  for (int i = 0; i < t.stageCount(); ++i) {
    const StageDecl& d = t.decl(i);
    json s;
    s["id"] = t.stage(i).id();
    s["title"] = t.stage(i).title();
    s["summary"] = t.stage(i).summary();
    s["reads"] = d.reads;
    s["iterations"] = t.stage(i).iterations(t.defaultParams());  // at the default parameters
    for (const auto& o : d.outputs) {
      json oj = {{"name", o.name}, {"address", t.id() + "/" + t.stage(i).id() + "/" + o.name},
                 {"kind", kindName(o.kind)}, {"semantic", semanticName(o.semantic)}, {"help", o.help}};
      if (!o.referenceMode.empty()) {
        // At the default parameters, as "iterations"; the declared form too when it names parameters.
        oj["reference_mode"] = referenceModeUnder(o, t.defaultParams());
        if (!referenceModeParams(o).empty()) oj["reference_mode_declared"] = o.referenceMode;
      }
      if (o.probeRecord) oj["probe_record"] = true;
      s["outputs"].push_back(oj);
    }
    for (const auto& p : d.probes) {
      json pj = {{"space", probeSpaceName(p.space)}, {"parameters", p.paramNames()}};
      if (!p.resource.empty()) pj["resource"] = p.resource;
      s["probes"].push_back(pj);
    }
    for (const auto& p : d.params)
      s["parameters"].push_back({{"name", p.name}, {"type", p.typeName()}, {"default", p.format(p.defaultValue)},
                                 {"range", p.rangeText()}, {"unit", p.unit}, {"help", p.help}});
    j["stages"].push_back(s);
  }
  j["resource_estimate"] = describeResources(t);
  return j;
}

int runList(const std::vector<std::string>& argv) {
  Args args("list", argv, {{"--json", false, false, "print JSON instead of text"}});
  json all;
  for (const auto& e : techniqueRegistry()) all["techniques"].push_back(describeTechnique(*createTechnique(e.id)));
  all["scenes"] = listScenes();
  if (args.has("--json")) {
    std::printf("%s\n", all.dump(2).c_str());
    return 0;
  }
  for (const auto& t : all["techniques"]) {
    std::printf("%s  %s\n  final output: %s\n  GPU memory at the defaults (512x512): %s\n",
                t["id"].get<std::string>().c_str(), t["title"].get<std::string>().c_str(),
                t["final_output"].get<std::string>().c_str(),
                t["resource_estimate"]["total"].get<std::string>().c_str());
    int n = 1;
    for (const auto& s : t["stages"]) {
      const int iterations = s["iterations"].get<int>();
      std::printf("  %d. %-14s %s%s\n", n++, s["id"].get<std::string>().c_str(), s["title"].get<std::string>().c_str(),
                  iterations > 1 ? (" (" + std::to_string(iterations) + " iterations at defaults)").c_str() : "");
      if (s.contains("outputs"))
        for (const auto& o : s["outputs"])
          std::printf("       output %-22s %-9s %-13s %s\n", o["name"].get<std::string>().c_str(),
                      o["kind"].get<std::string>().c_str(), o["semantic"].get<std::string>().c_str(),
                      o["help"].get<std::string>().c_str());
      if (s.contains("probes"))
        for (const auto& p : s["probes"])
          std::printf("       probe  %-22s %s%s\n", p["space"].get<std::string>().c_str(), joinNames(p["parameters"].get<std::vector<std::string>>()).c_str(),
                      p.contains("resource") ? (" in " + p["resource"].get<std::string>()).c_str() : "");
      if (s.contains("parameters"))
        for (const auto& p : s["parameters"])
          std::printf("       param  %-22s = %-8s [%s%s%s] %s\n", p["name"].get<std::string>().c_str(),
                      p["default"].get<std::string>().c_str(), p["range"].get<std::string>().c_str(),
                      p["unit"].get<std::string>().empty() ? "" : " ", p["unit"].get<std::string>().c_str(),
                      p["help"].get<std::string>().c_str());
    }
    std::printf("\n");
  }
  std::printf("scenes:");
  for (const auto& s : all["scenes"]) std::printf(" %s", s.get<std::string>().c_str());
  std::printf("\n");
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("list", "voxlab list [--json]",
                        "list techniques (stages, outputs, parameters) and scenes", &runList);

}  // namespace voxlab
