// The viewer's logic that needs no window: display mapping of captured levels (with channel,
// exposure and volume slices), what the viewer demands of a run, the `voxlab run` command
// line that reproduces a viewer state, and the viewer's script format. Unit-tested in
// tests/unit/test_lesson.cpp; the viewer's panels and visualisers only draw what these return.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "capture/capture.h"
#include "graph/param.h"
#include "graph/technique.h"
#include "scene/scene.h"

namespace voxlab {

// --- Display mapping -----------------------------------------------------------------------------

// Which 2D slice of a level to show: images are one slice (axis 2, index 0).
struct SliceSpec {
  int axis = 2;   // 0 = x (shows z,y), 1 = y (shows x,z), 2 = z (shows x,y)
  int index = -1;  // clamped to the level's extent along 'axis'; -1 = the middle slice
};

// The slice of a level to show: the chosen one for volumes (a negative index means the middle
// slice, where a scene usually has content), the whole image (z = 0) for images.
SliceSpec sliceToShow(const LevelData& level, const SliceSpec& chosen);

struct DisplaySettings {
  int channel = -1;       // -1 = the semantic's mapping of all channels; 0..3 = that channel in grey
  float exposure = 1.0f;  // multiplies values before the semantic's mapping
};

// RGBA8 image of one slice, top row first, plus the texel coordinates of each pixel's source.
struct SliceImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  std::vector<int32_t> pick;  // optional, per pixel: the element drawn there (-1 none), e.g. a record
};
glm::ivec2 sliceExtent(const LevelData& level, const SliceSpec& slice);
SliceImage mapSlice(const LevelData& level, Semantic semantic, const SliceSpec& slice, const DisplaySettings& ds);
// Its RGB (alpha dropped), as the image files and the handout's pictures hold it.
DisplayImage rgbOf(const SliceImage& slice);
// The range a normalised (false-colour) semantic maps onto its ramp: channel c's finite min and max
// over the whole level, as mapSlice takes it.
void normalisedRange(const LevelData& level, int channel, float& lo, float& hi);
// Texel (x, y, z) shown at image pixel (px, py) (top-row-first image coordinates).
glm::ivec3 sliceTexel(const LevelData& level, const SliceSpec& slice, int px, int py);

// --- 3D views -------------------------------------------------------------------------------------

// One volume level mapped for the 3D views: RGBA8 texels (x fastest, GL order), rgb as the slice
// view shows the texel (semantic, channel, exposure), alpha the texel's opacity: the alpha channel
// for Color/RadianceHDR/Opacity semantics of 4-channel levels (with channel = -1), otherwise 255
// for non-empty texels (any shown channel non-zero) and 0 for empty ones.
struct VolumeRGBA {
  glm::ivec3 size{0};
  std::vector<uint8_t> rgba;
  size_t nonEmpty = 0;  // texels with alpha > 0
};
VolumeRGBA mapVolume(const LevelData& level, Semantic semantic, const DisplaySettings& ds);

// Orbit camera of the 3D views: looks at 'target' from 'distance' bounding radii, perspective.
struct OrbitCamera {
  glm::vec3 target{0.0f};
  float radius = 1.0f;     // bounding radius of what is shown
  float yaw = 0.6f;        // radians about +y; 0 looks along -z
  float pitch = 0.35f;     // radians, clamped to +-85 degrees
  float distance = 2.6f;   // in radii
  float yfov = 0.7f;       // radians
  glm::vec3 eye() const;
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const;
  void rotate(float yawDeg, float pitchDeg);
  void lookAlong(const glm::vec3& forward);  // sets yaw/pitch so the view direction is 'forward'
};

// Scene camera moves of the viewer (no roll: up stays in the plane of forward and world +y; pitch
// is kept within +-85 degrees). Angles in degrees, distances in metres.
Camera orbitCamera(const Camera& c, glm::vec3 target, float yawDeg, float pitchDeg);  // about target
Camera lookCamera(const Camera& c, float yawDeg, float pitchDeg);                     // about the eye
Camera flyCamera(const Camera& c, float right, float up, float forward);             // in camera axes

// --- Script image checks ----------------------------------------------------------------------------

// How two images differ, per pixel (a pixel differs when any of its channels does). Images of
// different sizes or channel counts differ everywhere (fraction 1).
struct ImageDifference {
  size_t pixels = 0;     // pixels compared (the larger image's when the sizes differ)
  size_t differing = 0;  // pixels with any channel different
  double fraction() const { return pixels ? double(differing) / double(pixels) : 0.0; }
};
ImageDifference imageDifference(const std::vector<uint8_t>& a, int aw, int ah, const std::vector<uint8_t>& b, int bw,
                                int bh);

// What a rendered view shows beyond its background: the fraction of pixels that are content (not
// within 2 of 255 per channel of 'background' or of 'frame', the colour the bounds are drawn
// in), and the standard deviation of the content pixels' luma (Rec. 709, 0..255). A view of a
// volume whose texels all map to one colour (exposure 0, a constant channel) has content but
// a spread near 0; a view that draws nothing has fraction 0.
struct ViewContent {
  size_t pixels = 0, content = 0;
  double lumaStdDev = 0.0;
  double fraction() const { return pixels ? double(content) / double(pixels) : 0.0; }
};
ViewContent viewContent(const std::vector<uint8_t>& rgba, const uint8_t background[3], const uint8_t frame[3]);

// --- Outputs on demand ------------------------------------------------------------------------------

// What the viewer (and a lesson step's picture) asks a run to compute (StepCursor::demandOutputs):
// the technique's final output, the outputs shown ('shown': stage id, output name; the view, the
// compare view's other image, the overlaid volume) and every probe record of a stage that declares
// a probe (the Probe tab's records). In the technique's order, each once. An output declared
// onDemand that is not shown is not computed; a stage neither the final image nor a shown output
// depends on does not run.
std::vector<std::pair<std::string, std::string>> viewerDemand(const Technique& technique,
                                                              const std::vector<std::pair<std::string, std::string>>& shown);

// --- Reproduction ----------------------------------------------------------------------------------

// "voxlab run --technique T --scene S [--set n=v]... [--size WxH] [--camera N] [--look-from P --look-at Q]
// [--until STAGE] --out OUT" with a --set for every parameter that differs from its default (sorted by
// name). freeCamera (an orbit or fly camera, not a scene camera) adds --look-from/--look-at; the field
// of view stays scene camera N's.
std::string reproduceCommand(const std::string& technique, const std::string& scene, const ParamSet& params,
                             const ParamSet& defaults, int width, int height, int camera,
                             const std::string& until, const std::string& out = "out",
                             const Camera* freeCamera = nullptr);

// --- Presenter narrative ---------------------------------------------------------------------------

// One block of a lesson step's narrative as presenter mode sets it.
struct NarrativeBlock {
  enum class Kind { Heading, Paragraph, Item } kind;
  std::string text;
};
// Headings, paragraphs (hard-wrapped lines joined) and list items ("- ", "* ", "N. "), with inline
// Markdown reduced to its words (**, *, ` dropped; [text](url) as text); fenced code is left out.
std::vector<NarrativeBlock> narrativeBlocks(const std::string& markdown);

// --- Scripts -----------------------------------------------------------------------------------------

struct ScriptAction {
  int line = 0;
  std::string verb;
  std::vector<std::string> args;
};
// One action per line; '#' starts a comment; ${NAME} is replaced by the environment variable NAME.
// Unknown verbs or wrong argument counts are Errors naming "file:line".
std::vector<ScriptAction> parseScript(const std::string& text, const std::string& path);
// The verbs with their usage, for messages and `voxlab help view`.
std::string scriptVerbsHelp();

}  // namespace voxlab
