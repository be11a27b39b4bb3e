#include "run/bench_runs.h"

#include <algorithm>

namespace voxlab {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

bool isSubTiming(const std::string& statistic) {
  return statistic.size() > 3 && statistic.compare(statistic.size() - 3, 3, "_ms") == 0;
}

StageTimes timeStages(StepCursor& cursor, int runs) {
  const int n = cursor.stageCount();
  StageTimes t;
  t.cpu.resize(n);
  t.gpu.resize(n);
  t.first.resize(n);
  t.sub.resize(n);
  t.lastStats.resize(n);
  for (int run = 0; run <= runs; ++run) {
    cursor.invalidateAll();
    cursor.runAll();
    double tc = 0, tg = 0;
    for (int i = 0; i < n; ++i) {
      const StageRecord& rec = cursor.record(i);
      if (run == 0) {
        t.first[i] = rec.cpuMs;  // includes shader compilation
        continue;
      }
      for (const auto& [name, value] : rec.stats)
        if (isSubTiming(name)) t.sub[i][name].push_back(value);
      t.lastStats[i] = rec.stats;
      t.cpu[i].push_back(rec.cpuMs);
      t.gpu[i].push_back(rec.gpuMs);
      tc += rec.cpuMs;
      tg += rec.gpuMs;
    }
    if (run > 0) {
      t.totalCpu.push_back(tc);
      t.totalGpu.push_back(tg);
    }
  }
  return t;
}

}  // namespace voxlab
