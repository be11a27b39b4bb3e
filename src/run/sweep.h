// Sweeps: one technique on one scene at every value of one parameter (or every pair of values of
// two), to answer "what does this parameter buy, and what does it cost". `voxlab sweep` runs one
// from the command line; a lesson step that declares a sweep, and the gallery's error-against-time
// plot per technique, run one through the same code (docs/sweeps.md).
//
// Each run goes through HeadlessSession, the code path of `voxlab run` and `voxlab fidelity`, and
// writes the final image and every output that declares a reference mode (the outputs fidelity
// compares) into DIR/runs/NN/, with the run's manifest. Per run sweep.json records the values,
// per compared output its mode, role (direct, indirect, full), energy ratio (mean_ratio), RMSE and
// SSIM against tests/golden/reference/<scene>/<mode>.exr, the CPU time of every stage (wall time
// of its execute() with a glFinish) and their total, the GPU time, and the bytes of the GPU
// resources the run holds (the manifest's resource_bytes).
//
// The plots use one number for the error: 1 - SSIM (default) or |1 - energy ratio| (error
// "energy"), of the main compared output: the indirect light when the technique has such an output
// (what a GI technique's parameters change), else the combined image, else the direct light. The
// time is the total CPU time of the stages (timeStages: of the named stages only, to keep the
// noise of the stages the parameter does not change off the plot), measured as `voxlab bench`
// does: one untimed run that compiles the shaders, then one timed run (repeats N: N, each stage's
// median). DIR/*.svg: error against the value, time against the value, error against time with
// the Pareto front (the runs no other run beats on both); with two parameters one line per value
// of the second. DIR/sweep.html shows the plots and a slider that swaps the images and moves a
// marker on every plot; "#run=K" in the address opens run K.
//
// Every run opens its own offscreen GL context and closes it before the next: a caller that holds a
// context of its own makes it current again after a sweep.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace voxlab {

struct SweepRequest {
  std::string technique;
  std::string scene = "cornell-box";    // name in scenes/ or a path
  std::vector<std::string> params;      // one or two "NAME=V1,V2,..." or "NAME=FROM:TO:STEPS"
  std::vector<std::string> sets;        // "NAME=VALUE" held for every run
  int width = 256, height = 256;        // the references' size or a divisor of it
  int repeats = 1;                      // timed runs per value; a stage's time is their median
  std::string error = "ssim";           // "ssim" (1 - SSIM) or "energy" (|1 - energy ratio|)
  std::vector<std::string> timeStages;  // the stages whose time is plotted; empty: all
};

// Checks a request before anything runs: the technique, the stages named in timeStages, the
// parameters (declared by the technique, values in range, ranges well formed), the sets (valid,
// none of a swept parameter), the error kind and the number of runs. Throws Error, one line naming
// what is wrong and what is valid; 'paramLabel' is what the messages call a swept parameter's text
// ("--param" for the command, "sweep" for a lesson step). Does not load the scene.
void validateSweep(const SweepRequest& request, const std::string& paramLabel = "--param");

// The value texts of a swept parameter as the runs are given them ("30", "45", ...; a range
// expanded), after validateSweep's checks.
std::vector<std::string> sweepValueTexts(const std::string& technique, const std::string& param,
                                         const std::string& paramLabel = "--param");

// The arguments of the `voxlab sweep` command line that runs 'request' into 'outDir' (after
// "sweep": --technique, --scene, --param, --set, --size, --repeat, --error, --time-stage, --out).
std::vector<std::string> sweepArguments(const SweepRequest& request, const std::string& outDir);

// Called before each run (done = runs finished so far) and once at the end (done = total).
using SweepProgress = std::function<void(int done, int total, const std::string& label)>;

// Called when a run throws, with the run's label ("cone.aperture=30") and the message.
using SweepFailure = std::function<void(const std::string& label, const std::string& message)>;

// Validates, runs every value and writes DIR/sweep.json, DIR/sweep.html, the plots
// (error-by-value.svg, time-by-value.svg, error-by-time.svg), DIR/runs/NN/ and DIR/reference/.
// Returns sweep.json's content; "failed_runs" counts the runs that threw (each run's "failed"
// holds its message; without onFailure it is also printed on stderr).
nlohmann::json runSweep(const SweepRequest& request, const std::string& outDir, const SweepProgress& progress = {},
                        const SweepFailure& onFailure = {});

}  // namespace voxlab
