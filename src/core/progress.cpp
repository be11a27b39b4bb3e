#include "core/progress.h"

#include <cstdio>
#include <unistd.h>

namespace voxlab {

ProgressBar::ProgressBar(std::string label, bool linesWithoutTerminal)
    : label_(std::move(label)), tty_(isatty(STDERR_FILENO) != 0), lines_(linesWithoutTerminal) {}

void ProgressBar::update(double fraction, const std::string& what) {
  const int pct = int(fraction * 100.0 + 1e-9);
  if (tty_) {
    if (pct == lastShown_ && what == lastWhat_) return;
    lastShown_ = pct;
    lastWhat_ = what;
    const int width = 40;
    const int fill = pct * width / 100;
    std::fprintf(stderr, "\r%s [%s%s] %3d%% %-40.40s", label_.c_str(), std::string(size_t(fill), '#').c_str(),
                 std::string(size_t(width - fill), ' ').c_str(), pct, what.c_str());
    drawn_ = true;
  } else if (lines_) {
    const int step = pct / 10 * 10;
    if (step < 10 || step <= lastShown_) return;  // 10%, 20%, ..., 100%: ten lines at most
    lastShown_ = step;
    std::fprintf(stderr, "%s: %d%%\n", label_.c_str(), step);
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (tty_ && drawn_) std::fputc('\n', stderr);
  drawn_ = false;
  std::fflush(stderr);
}

}  // namespace voxlab
