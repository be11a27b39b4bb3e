// The timed runs behind `voxlab bench`, shared with `voxlab gallery` (time per frame beside each
// technique): a first run of every stage (shader compilation included), then 'runs' timed runs of
// all stages from scratch.
#pragma once
#include <vector>

#include "graph/step_cursor.h"

namespace voxlab {

struct StageTimes {
  std::vector<std::vector<double>> cpu, gpu;  // per stage, one value per timed run (ms)
  std::vector<double> first;                  // per stage, the first run's CPU ms
  std::vector<double> totalCpu, totalGpu;     // per timed run, all stages (ms)
};

StageTimes timeStages(StepCursor& cursor, int runs);
double median(std::vector<double> values);

}  // namespace voxlab
