// The timed runs behind `voxlab bench`, shared with `voxlab gallery` (time per frame beside each
// technique): a first run of every stage (shader compilation included), then 'runs' timed runs of
// all stages from scratch.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "graph/step_cursor.h"

namespace voxlab {

struct StageTimes {
  std::vector<std::vector<double>> cpu, gpu;  // per stage, one value per timed run (ms)
  std::vector<double> first;                  // per stage, the first run's CPU ms
  std::vector<double> totalCpu, totalGpu;     // per timed run, all stages (ms)
  // Per stage, the timings it reports itself (statistics named *_ms: clipmap's update per level
  // and per phase), one value per timed run; and the last run's statistics.
  std::vector<std::map<std::string, std::vector<double>>> sub;
  std::vector<StageStats> lastStats;
};

// A statistic that is a timing a stage reports about its own work (e.g. "level0_ms"): its name
// ends in "_ms". bench reports their medians beside the stage's.
bool isSubTiming(const std::string& statistic);

StageTimes timeStages(StepCursor& cursor, int runs);
double median(std::vector<double> values);

}  // namespace voxlab
