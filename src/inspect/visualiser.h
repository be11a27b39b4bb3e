// Visualiser: how one kind of data is shown and saved. One file per visualiser: the generic ones
// (images, volumes, buffers, points, cone samples) under src/inspect/visualisers/, those of one
// technique's semantics beside it under src/techniques/<technique>/views/ (which its stages never
// include). Each is registered with VOXLAB_REGISTER_VISUALISER by output kind and semantic, the
// semantic being the constant the technique's output declaration names (or by kind alone, the
// fallback for every semantic without its own). A visualiser is an
// OutputHandler (capture/output_handler.h: the files `voxlab run` writes, statistics, the golden
// tier and comparison, used headless) plus the viewer's views of it:
//   2D view      the image the view panel shows, the element under the cursor and its value
//   3D view      content for View3D (ray-marched volume, cubes, points, spheres and lines)
//   inspector    controls (level, slice, channel, ...) and the statistics / records tables
//   record view  probe records in the Probe tab (cone plots, a table, ...)
// The viewer, `voxlab run` and the snapshot suite look visualisers up by (kind, semantic) and
// never name one; docs/architecture.md says how to add one.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "capture/output_handler.h"
#include "inspect/inspect_logic.h"

namespace voxlab {

class View3D;

// What the user chose to look at in an output (kept by the viewer across frames).
struct ViewSettings {
  int level = 0;
  SliceSpec slice;
  DisplaySettings display;
};

// One captured output and what the viewer knows around it.
struct VisualiserContext {
  const CapturedOutput& out;
  const nlohmann::json& statistics;  // outputStatistics(out), computed once per capture
  const nlohmann::json& records;     // buffers: the first records decoded (recordsJson)
  ViewSettings& view;
  // The latest volume output (of a stage before this one that has run), for data placed in a
  // volume (buffer positions, cone samples); false when there is none. 'name' is "stage/output".
  std::function<bool(CapturedOutput& volume, std::string& name)> contextVolume;
  // The output whose semantic (or, failing that, name) is 'what', of this stage or the latest one
  // before it that has run, for a view that needs another output's data (the clip atlas reads the
  // clip-levels records to know each level's origin); false when there is none (or unset).
  std::function<bool(const char* what, CapturedOutput& out)> contextOutput;
  // The step a record view that can be stepped shows (its step slider, recordSteps() below), kept
  // by the viewer per probe-record output so the script verb `record-step` moves the same slider;
  // nullptr outside the Probe tab (the view then keeps its own).
  int* recordStep = nullptr;
};

// 3D content a visualiser built, in view units (docs in inspect/view3d.h).
struct Content3D {
  glm::vec3 lo{0.0f}, hi{1.0f};  // bounds shown as a box and framed by the orbit camera
  std::string info;              // one line under the view
  std::string message;           // a warning ("" = none)
};

// What a probe record check found (script `expect-probe-records`).
struct RecordCheck {
  size_t elements = 0;  // records, samples, nodes, ... (0 fails the check)
  std::string summary;  // "6 cones, 212 samples"
  std::string error;    // "" when the records are consistent
};

class Visualiser : public OutputHandler {
 public:
  // --- 2D view ---
  // The image the view panel shows (RGBA8, top row first); empty (width 0) for none.
  virtual SliceImage image2D(const VisualiserContext& ctx) const = 0;
  // The element shown at image pixel (px, py): a texel (x, y, z) for levels; false for none.
  virtual bool elementAt(const VisualiserContext& ctx, int px, int py, glm::ivec3& element) const { return false; }
  // "pixel (x, y, z) = (values)" of an element elementAt returned.
  virtual std::string describeElement(const VisualiserContext& ctx, const glm::ivec3& element) const { return ""; }
  // One line under the image when nothing is hovered ("" = the viewer's hint).
  virtual std::string caption(const VisualiserContext& ctx) const { return ""; }

  // --- 3D view ---
  virtual bool has3D(const OutputDesc& desc) const { return false; }
  // Fills 'view' (cleared by the caller) and returns its bounds and captions.
  virtual Content3D build3D(const VisualiserContext& ctx, View3D& view) const { return {}; }

  // --- inspector: controls and tables (ImGui) ---
  virtual void drawInspector(const VisualiserContext& ctx) const = 0;

  // --- probe records ---
  // The Probe tab's view of a probe record output (ImGui); the table by default.
  virtual void drawRecordView(const VisualiserContext& ctx) const;
  virtual RecordCheck checkRecords(const CapturedOutput& out) const;
  // A record that is a sequence of steps (a walk, a descent) can be stepped through one at a time
  // in its record view: how many steps it has (0: not steppable) and one line saying what step k
  // shows (script verbs `record-step`, `expect-record-step`).
  virtual size_t recordSteps(const CapturedOutput& out) const { return 0; }
  virtual std::string describeRecordStep(const CapturedOutput& out, size_t k) const { return ""; }
};

// The visualiser for (kind, semantic), else for the kind. Throws Error for a kind without one.
const Visualiser& visualiserFor(OutputKind kind, Semantic semantic);
inline const Visualiser& visualiserFor(const OutputDesc& d) { return visualiserFor(d.kind, d.semantic); }
// Registers in both registries (this one and capture's OutputHandler registry). semantic nullptr:
// the kind's fallback. Returns true (for the macro's static).
bool registerVisualiser(OutputKind kind, const char* semantic, std::unique_ptr<Visualiser> visualiser);

inline constexpr const char* kAnySemantic = nullptr;

// A semantic a visualiser is registered for, or one an output declares, with its output kind.
struct SemanticUse {
  OutputKind kind = OutputKind::Image2D;
  std::string semantic;
  std::string where;  // who: "technique/stage/output" for a declaration, the visualiser's name()
};
// The (kind, semantic) of every visualiser registered for a semantic (the kinds' fallbacks left out).
std::vector<SemanticUse> registeredVisualiserSemantics();
// One line for each registered visualiser that no declared output of its kind and semantic reaches
// (a misspelt semantic, a view left behind by a renamed output, a view for the wrong kind), and for
// each declared output whose semantic has a visualiser for another kind only (it gets the generic
// view of its own kind). Empty when every registered view is reached.
std::vector<std::string> semanticMismatches(const std::vector<SemanticUse>& declared,
                                            const std::vector<SemanticUse>& registered);

#define VOXLAB_VISUALISER_CAT2(a, b) a##b
#define VOXLAB_VISUALISER_CAT(a, b) VOXLAB_VISUALISER_CAT2(a, b)
// VOXLAB_REGISTER_VISUALISER(ConeSamplesVisualiser, OutputKind::Buffer, Semantic::ConeSamples.name());
// VOXLAB_REGISTER_VISUALISER(ImageVisualiser, OutputKind::Image2D, kAnySemantic);
#define VOXLAB_REGISTER_VISUALISER(Class, kind, semantic)                                          \
  static const bool VOXLAB_VISUALISER_CAT(voxlabVisualiserRegistered_, __LINE__) =                 \
      ::voxlab::registerVisualiser(kind, semantic, std::make_unique<Class>())

// The lookups of a VisualiserContext for an output shown at stage 'selected' of 'cursor' (the
// viewer's and the handout's): contextVolume finds the first volume output of the last stage
// before it that wrote volumes and has run (its level 0 spans the voxel space that buffer
// positions use); contextOutput an output by semantic (or, failing that, name) of that stage or
// the latest earlier one that has run. Both keep a reference to 'cursor'.
class StepCursor;
std::function<bool(CapturedOutput&, std::string&)> contextVolumeLookup(StepCursor& cursor, int selected);
std::function<bool(const char*, CapturedOutput&)> contextOutputLookup(StepCursor& cursor, int selected);

// --- ImGui helpers the visualisers share (visualiser.cpp) ----------------------------------------------

// A two-column table of a statistics object (key, value; arrays joined).
void drawStatisticsTable(const char* id, const nlohmann::json& stats);
// A table of decoded records (recordsJson: an array of objects, one column per field), numbers
// with 4 significant digits.
void drawRecordsTable(const char* id, const nlohmann::json& records, float height);

// A line plot with axes: y from yLo to yHi (NaN: the data's range) labelled at both ends, x the
// values 'xs' labelled at both ends, each axis named with its unit ("distance [m]"); the point
// under the cursor is shown with both its values. xs and ys have the same length.
void drawAxesPlot(const char* id, const std::vector<float>& xs, const std::vector<float>& ys, const std::string& xAxis,
                  const std::string& yAxis, float yLo, float yHi, float height = 90.0f);
// Horizontal bars from 0, one per value, each labelled with its name and value; the axis spans
// 0..max(values) and is labelled with 'unit'.
void drawValueBars(const char* id, const std::vector<std::string>& names, const std::vector<float>& values,
                   const std::string& unit);

}  // namespace voxlab
