// Figures: a labelled picture of one output for a paper, a slide or a report, written as SVG by
// `voxlab figure` and by the viewer's Camera/Export tab (the same code: outputFigure, figureSvg).
//
// A figure holds a title (the output's address), lines naming the scene, camera, size and the
// parameters that differ from the technique's defaults, the output as the viewer's view shows it
// (mapSlice: the same display mapping, slice and exposure), a colour bar with its range when that
// mapping is the normalised false-colour ramp, and the reference (the path tracer's image of the
// output's reference mode, through the same mapping) beside it when the output declares a
// reference mode and the scene has that reference. Images are embedded as PNG (data: URIs), so the
// SVG is one self-contained file; they are drawn with nearest filtering at a chosen width.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "capture/capture.h"
#include "graph/step_cursor.h"
#include "inspect/inspect_logic.h"

namespace voxlab {

struct FigureImage {
  DisplayImage image;
  std::string caption;
};

struct ColourBar {
  float lo = 0, hi = 1;  // the values at the ramp's ends
  std::string label;     // what the values are
};

struct Figure {
  std::string title;
  std::vector<std::string> notes;   // lines under the title
  std::vector<FigureImage> images;  // side by side, left to right
  std::optional<ColourBar> colourBar;
};

struct FigureRequest {
  std::string stage, output;       // of the cursor's technique
  int level = 0;
  SliceSpec slice;                 // volumes: the slice shown (default the middle z slice)
  DisplaySettings display;         // channel and exposure, as the viewer's view
  bool withReference = true;       // the reference beside it, when there is one
};

// The figure of an output of 'cursor' (its stage must have run). Throws Error naming valid
// values for a level the output lacks or a buffer without positions.
Figure outputFigure(StepCursor& cursor, const FigureRequest& request);

// The figure as SVG, 'width' pixels wide (each image scaled to fit side by side; at least 64).
std::string figureSvg(const Figure& figure, int width);

}  // namespace voxlab
