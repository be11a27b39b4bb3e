// voxlab bench: per-stage timings (medians over repeated runs, CPU wall and GPU timestamps),
// memory per resource, and the wall time of whole `voxlab run --final-only` processes
// (start-up and shader compilation included); with --frames N, the per-frame cost by stage of a
// light move, a camera move and a moving object (run/frame_costs.h). Prints Markdown; writes JSON
// and Markdown files.
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "run/bench_runs.h"
#include "run/frame_costs.h"
#include "app/command.h"
#include "run/session.h"
#include "core/args.h"
#include "core/error.h"

namespace voxlab {
namespace {

using nlohmann::json;

// Wall time of one child process running argv, in milliseconds; throws if it fails.
double timeProcess(const std::vector<std::string>& argv) {
  auto t0 = std::chrono::steady_clock::now();
  pid_t pid = fork();
  if (pid == 0) {
    std::vector<char*> cargs;
    for (const auto& a : argv) cargs.push_back(const_cast<char*>(a.c_str()));
    cargs.push_back(nullptr);
    int devnull = open("/dev/null", 1);
    if (devnull >= 0) dup2(devnull, 1);
    execv("/proc/self/exe", cargs.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  auto t1 = std::chrono::steady_clock::now();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) throw Error("a timed 'voxlab run' failed; run it by hand to see why");
  return std::chrono::duration<double, std::milli>(t1 - t0).count();
}

std::string markdown(const json& r) {
  std::ostringstream md;
  char line[512];
  md << "### " << r["technique"].get<std::string>() << " on " << r["scene"].get<std::string>() << " ("
     << r["view"].get<std::string>() << ", " << r["runs"].get<int>() << " runs)\n\n";
  md << "Renderer: " << r["gl_renderer"].get<std::string>() << ", " << r["gl_version"].get<std::string>() << "\n\n";
  md << "Parameters: " << r["parameters_changed"].get<std::string>() << "\n\n";
  std::snprintf(line, sizeof line, "Scene load (parse, decode textures, flatten; CPU): %.0f ms for %zu triangles.\n\n",
                r["scene_load_ms"].get<double>(), r["scene_triangles"].get<size_t>());
  md << line;
  md << "| stage | median CPU ms | median GPU ms | first run CPU ms |\n|---|---:|---:|---:|\n";
  for (const auto& s : r["stages"]) {
    std::snprintf(line, sizeof line, "| %s | %.1f | %.1f | %.1f |\n", s["id"].get<std::string>().c_str(),
                  s["cpu_ms_median"].get<double>(), s["gpu_ms_median"].get<double>(), s["cpu_ms_first"].get<double>());
    md << line;
  }
  std::snprintf(line, sizeof line, "| **all stages** | **%.1f** | **%.1f** | %.1f |\n\n", r["total_cpu_ms_median"].get<double>(),
                r["total_gpu_ms_median"].get<double>(), r["total_cpu_ms_first"].get<double>());
  md << line;
  bool anySub = false;
  for (const auto& s : r["stages"]) anySub = anySub || s.contains("sub_ms_median");
  if (anySub) {
    md << "Timings the stages report about their own work (statistics named `*_ms`; medians of the timed runs):\n\n";
    md << "| stage | timing | median ms |\n|---|---|---:|\n";
    for (const auto& s : r["stages"]) {
      if (!s.contains("sub_ms_median")) continue;
      for (const auto& [name, value] : s["sub_ms_median"].items()) {
        std::snprintf(line, sizeof line, "| %s | %s | %.1f |\n", s["id"].get<std::string>().c_str(), name.c_str(),
                      value.get<double>());
        md << line;
      }
    }
    md << "\n";
  }
  if (r.contains("process_wall_ms_median")) {
    std::snprintf(line, sizeof line,
                  "Whole `voxlab run --final-only` process, start-up and shader compilation included: median %.0f ms "
                  "of %d (min %.0f, max %.0f).\n\n",
                  r["process_wall_ms_median"].get<double>(), int(r["process_wall_ms"].size()),
                  r["process_wall_ms_min"].get<double>(), r["process_wall_ms_max"].get<double>());
    md << line;
  }
  if (r.contains("frame_changes")) {
    md << "Per frame of change (" << r["frames"].get<int>()
       << " frames of each; a frame re-runs only the stages its change invalidates; medians over the frames):\n\n";
    md << "| change | what changed | stages re-run | median frame CPU ms | median frame GPU ms |\n|---|---|---|---:|---:|\n";
    for (const auto& c : r["frame_changes"]) {
      std::string stages;
      for (const auto& s : c["stages"]) stages += (stages.empty() ? "" : ", ") + s.get<std::string>();
      std::snprintf(line, sizeof line, "| %s | %s | %s | %.1f | %.1f |\n", c["change"].get<std::string>().c_str(),
                    c["how"].get<std::string>().c_str(), stages.empty() ? "none" : stages.c_str(),
                    c["frame_cpu_ms_median"].get<double>(), c["frame_gpu_ms_median"].get<double>());
      md << line;
    }
    md << "\n| change | stage | median CPU ms | median GPU ms |\n|---|---|---:|---:|\n";
    for (const auto& c : r["frame_changes"])
      for (const auto& s : c["per_stage"]) {
        std::snprintf(line, sizeof line, "| %s | %s | %.1f | %.1f |\n", c["change"].get<std::string>().c_str(),
                      s["id"].get<std::string>().c_str(), s["cpu_ms_median"].get<double>(), s["gpu_ms_median"].get<double>());
        md << line;
      }
    md << "\n";
  }
  md << "| resource | kind | size | MiB |\n|---|---|---|---:|\n";
  for (const auto& m : r["memory"]) {
    std::snprintf(line, sizeof line, "| %s | %s | %s | %.2f |\n", m["name"].get<std::string>().c_str(),
                  m["kind"].get<std::string>().c_str(), m["shape"].get<std::string>().c_str(), m["mib"].get<double>());
    md << line;
  }
  std::snprintf(line, sizeof line, "| **total** | | | **%.2f** |\n", r["memory_total_mib"].get<double>());
  md << line;
  return md.str();
}

int runBench(const std::vector<std::string>& argv) {
  Args args("bench", argv,
            {{"--technique", true, false, "technique id"},
             {"--scene", true, false, "scene name or path (default cornell-box)"},
             {"--set", true, true, "NAME=VALUE parameter override, repeatable"},
             {"--size", true, false, "output size WIDTHxHEIGHT (default 512x512)"},
             {"--runs", true, false, "timed runs of all stages in one process (default 5)"},
             {"--process-runs", true, false, "whole `voxlab run --final-only` processes to time (default 5, 0 = skip)"},
             {"--final-only", false, false, "time only the stages and outputs the final image needs (outputs on demand)"},
             {"--frames", true, false, "N: also time N frames each of a light move, a camera move and a moving object, by stage"},
             {"--out", true, false, "folder for bench.json and bench.md (default: print only)"}});
  RunRequest req;
  req.technique = args.require("--technique");
  req.scene = args.get("--scene", "cornell-box");
  req.sets = args.all("--set");
  std::string size = args.get("--size", "512x512");
  Args::parseSize(size, req.width, req.height);
  int runs = Args::parseInt("--runs", args.get("--runs", "5"), 1, 1000);
  int processRuns = Args::parseInt("--process-runs", args.get("--process-runs", "5"), 0, 1000);
  const int frames = args.has("--frames") ? Args::parseInt("--frames", args.get("--frames"), 1, 1000) : 0;

  json r;
  {
    HeadlessSession session(req);
    StepCursor& cursor = session.cursor();
    int n = cursor.stageCount();
    session.demand(args.has("--final-only"));
    StageTimes times = timeStages(cursor, runs);
    const auto &cpu = times.cpu, &gpu = times.gpu;
    const auto &first = times.first, &totalCpu = times.totalCpu, &totalGpu = times.totalGpu;
    json header = session.manifestHeader();
    r["technique"] = req.technique;
    r["scene"] = header["scene"];
    r["view"] = size;
    r["runs"] = runs;
    r["demand"] = args.has("--final-only") ? "final image" : "every output";
    r["gl_renderer"] = header["gl"]["renderer"];
    r["gl_version"] = header["gl"]["version"];
    r["parameters"] = header["parameters"];
    r["parameters_changed"] = req.sets.empty() ? std::string("defaults") : joinNames(req.sets);
    r["scene_load_ms"] = session.sceneLoadMs();
    r["scene_triangles"] = cursor.scene().triangleCount();
    double firstTotal = 0;
    for (int i = 0; i < n; ++i) {
      r["stages"].push_back({{"id", cursor.technique().stage(i).id()},
                             {"cpu_ms_median", median(cpu[i])},
                             {"gpu_ms_median", median(gpu[i])},
                             {"cpu_ms_first", first[i]},
                             {"cpu_ms", cpu[i]},
                             {"gpu_ms", gpu[i]}});
      json& stage = r["stages"].back();
      stage["stats_last_run"] = json::object();
      for (const auto& [name, value] : times.lastStats[i]) stage["stats_last_run"][name] = value;
      if (!times.sub[i].empty()) {
        // Timings the stage reports about its own work (statistics named *_ms; StageTimes::sub).
        stage["sub_ms_median"] = json::object();
        stage["sub_ms"] = json::object();
        for (const auto& [name, values] : times.sub[i]) {
          stage["sub_ms_median"][name] = median(values);
          stage["sub_ms"][name] = values;
        }
      }
      firstTotal += first[i];
    }
    r["total_cpu_ms_median"] = median(totalCpu);
    r["total_gpu_ms_median"] = median(totalGpu);
    r["total_cpu_ms_first"] = firstTotal;
    double total = 0;
    for (const auto& [name, t] : cursor.board().textures()) {
      glm::ivec3 s = t->desc().size;
      double mib = double(t->byteSize()) / (1024.0 * 1024.0);
      total += mib;
      std::string shape = std::to_string(s.x) + "x" + std::to_string(s.y) + (t->is3D() ? "x" + std::to_string(s.z) : "") +
                          " " + formatName(t->desc().format) + (t->levels() > 1 ? ", " + std::to_string(t->levels()) + " levels" : "");
      r["memory"].push_back({{"name", name}, {"kind", t->is3D() ? "texture3d" : "texture2d"}, {"shape", shape}, {"mib", mib}});
    }
    for (const auto& [name, b] : cursor.board().buffers()) {
      double mib = double(b->size()) / (1024.0 * 1024.0);
      total += mib;
      r["memory"].push_back({{"name", name}, {"kind", "buffer"}, {"shape", std::to_string(b->size()) + " bytes"}, {"mib", mib}});
    }
    r["memory_total_mib"] = total;
    if (frames > 0) {
      r["frames"] = frames;
      r["frame_changes"] = json::array();
      for (const FrameChangeCost& c : timeFrameChanges(session, frames)) {
        json change = {{"change", c.change}, {"how", c.how}, {"stages", c.stages},
                       {"frame_cpu_ms", c.frameCpuMs}, {"frame_gpu_ms", c.frameGpuMs},
                       {"frame_cpu_ms_median", median(c.frameCpuMs)}, {"frame_gpu_ms_median", median(c.frameGpuMs)},
                       {"per_stage", json::array()}};
        for (const std::string& id : c.stages)
          change["per_stage"].push_back({{"id", id}, {"cpu_ms_median", median(c.cpuMs.at(id))},
                                         {"gpu_ms_median", median(c.gpuMs.at(id))}});
        r["frame_changes"].push_back(change);
      }
    }
  }
  if (processRuns > 0) {
    std::string tmp = (std::filesystem::temp_directory_path() / ("voxlab-bench-" + std::to_string(getpid()))).string();
    std::vector<std::string> cmd = {"voxlab", "run", "--technique", req.technique, "--scene", req.scene, "--size", size,
                                    "--final-only", "--out", tmp};
    for (const auto& s : req.sets) { cmd.push_back("--set"); cmd.push_back(s); }
    std::vector<double> walls;
    for (int i = 0; i < processRuns; ++i) walls.push_back(timeProcess(cmd));
    std::filesystem::remove_all(tmp);
    r["process_wall_ms"] = walls;
    r["process_wall_ms_median"] = median(walls);
    r["process_wall_ms_min"] = *std::min_element(walls.begin(), walls.end());
    r["process_wall_ms_max"] = *std::max_element(walls.begin(), walls.end());
  }
  std::string md = markdown(r);
  std::printf("%s", md.c_str());
  if (args.has("--out")) {
    std::string dir = args.get("--out");
    std::filesystem::create_directories(dir);
    std::ofstream(dir + "/bench.json") << r.dump(2) << "\n";
    std::ofstream(dir + "/bench.md") << md;
    std::printf("\nwritten: %s/bench.json, %s/bench.md\n", dir.c_str(), dir.c_str());
  }
  return 0;
}

}  // namespace

VOXLAB_REGISTER_COMMAND("bench",
                        "voxlab bench --technique T [--scene S] [--set name=value]... [--size WxH] [--runs N] "
                        "[--process-runs N] [--frames N] [--out DIR]",
                        "time every stage (medians, CPU and GPU) and whole runs; memory per resource", &runBench);

}  // namespace voxlab
