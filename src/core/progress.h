// A progress bar on stderr for long commands (`voxlab reference`, `voxlab fidelity`): redrawn in
// place on a terminal; otherwise nothing, or (linesWithoutTerminal) at most ten "label: NN%"
// lines, so logs stay short.
#pragma once
#include <string>

namespace voxlab {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label, bool linesWithoutTerminal = false);
  // fraction in [0, 1]; 'what' (may be empty) is shown after the bar on a terminal, e.g. the item
  // now running.
  void update(double fraction, const std::string& what = "");
  void finish();  // ends the terminal line (when one was drawn)

 private:
  std::string label_;
  bool tty_;
  bool lines_;
  int lastShown_ = -1;
  std::string lastWhat_;
  bool drawn_ = false;
};

}  // namespace voxlab
