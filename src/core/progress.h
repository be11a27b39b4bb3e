// Progress on stderr for long commands (`voxlab reference`, `voxlab fidelity`, `voxlab handout`):
// a bar redrawn in place on a terminal; otherwise nothing, or (linesWithoutTerminal) at most ten
// "label: NN%" lines, so logs stay short.
#pragma once
#include <string>

namespace voxlab {

// "[##########..........]  7/14  label", 'width' characters of bar.
std::string progressBar(int done, int total, int width, const std::string& label);

class ProgressBar {
 public:
  explicit ProgressBar(std::string label, bool linesWithoutTerminal = false);
  // 'done' of 'total' items; 'what' (may be empty) is shown after the count on a terminal, e.g.
  // the item now running.
  void update(int done, int total, const std::string& what = "");
  void update(double fraction) { update(int(fraction * 100.0 + 1e-9), 100); }  // per cent
  void finish();  // ends the terminal line (when one was drawn)

 private:
  std::string label_;
  bool tty_;
  bool lines_;
  int lastShown_ = -1;
  std::string lastLine_;
  bool drawn_ = false;
};

}  // namespace voxlab
