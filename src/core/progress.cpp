#include "core/progress.h"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace voxlab {

std::string progressBar(int done, int total, int width, const std::string& label) {
  total = std::max(total, 1);
  done = std::clamp(done, 0, total);
  int filled = int((long long)done * width / total);
  std::string bar = "[" + std::string(size_t(filled), '#') + std::string(size_t(width - filled), '.') + "] ";
  std::string count = std::to_string(done) + "/" + std::to_string(total);
  std::string pad(std::to_string(total).size() * 2 + 1 - count.size(), ' ');
  return bar + pad + count + "  " + label;
}

ProgressBar::ProgressBar(std::string label, bool linesWithoutTerminal)
    : label_(std::move(label)), tty_(isatty(STDERR_FILENO) != 0), lines_(linesWithoutTerminal) {}

void ProgressBar::update(int done, int total, const std::string& what) {
  if (tty_) {
    std::string line = label_ + " " + progressBar(done, total, 30, what);
    if (line == lastLine_) return;
    lastLine_ = line;
    if (line.size() > 100) line.resize(100);
    std::fprintf(stderr, "\r%-100s", line.c_str());
    drawn_ = true;
  } else if (lines_) {
    const int step = total > 0 ? done * 100 / total / 10 * 10 : 0;
    if (step < 10 || step <= lastShown_) return;  // 10%, 20%, ..., 100%: ten lines at most
    lastShown_ = step;
    std::fprintf(stderr, "%s: %d%%\n", label_.c_str(), step);
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (tty_ && drawn_) std::fputc('\n', stderr);
  drawn_ = false;
  lastLine_.clear();
  std::fflush(stderr);
}

}  // namespace voxlab
