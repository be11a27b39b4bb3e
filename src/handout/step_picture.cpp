#include "handout/step_picture.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "inspect/inspect_logic.h"
#include "inspect/scene_overlay.h"
#include "inspect/visualiser.h"
#include "run/reference_error.h"
#include "run/session.h"

namespace voxlab {

DisplayImage shrink(const DisplayImage& image, int width) {
  if (image.width <= width) return image;
  DisplayImage out;
  out.width = width;
  out.height = std::max(1, int(std::lround(double(image.height) * width / image.width)));
  out.rgb.resize(size_t(out.width) * out.height * 3);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      int x0 = x * image.width / out.width, x1 = std::max(x0 + 1, (x + 1) * image.width / out.width);
      int y0 = y * image.height / out.height, y1 = std::max(y0 + 1, (y + 1) * image.height / out.height);
      for (int c = 0; c < 3; ++c) {
        long sum = 0;
        for (int yy = y0; yy < y1; ++yy)
          for (int xx = x0; xx < x1; ++xx) sum += image.rgb[(size_t(yy) * image.width + xx) * 3 + c];
        out.rgb[(size_t(y) * out.width + x) * 3 + c] = uint8_t(sum / ((x1 - x0) * (y1 - y0)));
      }
    }
  return out;
}

StepRenderer::StepRenderer(int width, int height) : width_(width), height_(height) {}

StepRenderer::~StepRenderer() { release(); }

void StepRenderer::release() {
  overlay_.reset();  // its GL objects belong to the session's context
  session_.reset();
}

StepPicture StepRenderer::render(const Lesson& lesson, const LessonStep& step) {
  try {
    if (step.frameCount <= 0) return renderStep(step);
    const FrameValues last = stepFrame(step, step.frameCount - 1);
    return renderStep(step, &last);
  } catch (const Error& e) {
    // A failed step may leave the session half-run; start the next one afresh.
    overlay_.reset();
    session_.reset();
    throw Error(lesson.path + ":" + std::to_string(step.line) + ": " + e.what());
  }
}

std::vector<DisplayImage> StepRenderer::renderFrames(const Lesson& lesson, const LessonStep& step) {
  std::vector<DisplayImage> images;
  try {
    for (int k = 0; k < step.frameCount; ++k) {
      const FrameValues frame = stepFrame(step, k);
      images.push_back(renderStep(step, &frame).image);
    }
  } catch (const Error& e) {
    overlay_.reset();
    session_.reset();
    throw Error(lesson.path + ":" + std::to_string(step.line) + ": frames: " + e.what());
  }
  return images;
}

FrameValues StepRenderer::stepFrame(const LessonStep& step, int k) {
  HeadlessSession& session = sessionFor(step);
  const SceneAnimation& animation = session.animation();
  const std::optional<std::pair<double, double>> sceneTimes =
      animation.animated() ? std::optional<std::pair<double, double>>({0.0, double(animation.duration)}) : std::nullopt;
  return animatedFrame(session.cursor().technique().defaultParams(), step.frameAnimations, k, step.frameCount, sceneTimes);
}

HeadlessSession& StepRenderer::sessionFor(const LessonStep& step) {
  std::vector<std::string> sets;
  for (const auto& [n, v] : step.sets) sets.push_back(n + "=" + v);
  if (!session_ || technique_ != step.technique || scene_ != step.scene) {
    overlay_.reset();
    session_.reset();
    RunRequest req;
    req.technique = step.technique;
    req.scene = step.scene;
    req.sets = sets;
    req.width = width_;
    req.height = height_;
    req.camera = step.camera;
    session_ = std::make_unique<HeadlessSession>(req);
    technique_ = step.technique;
    scene_ = step.scene;
  }
  return *session_;
}

StepPicture StepRenderer::renderStep(const LessonStep& step, const FrameValues* frame) {
  HeadlessSession& session = sessionFor(step);
  // The step's state is absolute, as the viewer applies it: defaults plus the step's "set", an
  // animated scene at the frame's time (at rest without frames), the step's camera.
  StepCursor& cursor = session.cursor();
  const Technique& t = cursor.technique();
  ParamSet params = t.defaultParams();
  for (const auto& [n, v] : step.sets) params.setText(n, v);
  const ParamSet stepParams = params;
  if (frame)
    for (const auto& [n, v] : frame->params) params.set(n, v);
  cursor.setParams(params);
  if (session.animation().animated())
    poseCursorScene(cursor, session.scene(), session.animation(), frame && frame->sceneTime ? *frame->sceneTime : 0.0,
                    step.camera);
  cursor.useSceneCamera(step.camera);

  const int stage = t.stageIndex(step.stage);
  if (step.output.empty()) throw Error("stage " + step.stage + " has no outputs to show");
  auto [outStage, desc] = t.findOutput(step.stage, step.output);
  (void)outStage;
  std::string volume;
  int overlayLevel = -1;
  if (!step.overlay.empty()) {
    size_t at = step.overlay.find('@');
    volume = step.overlay.substr(0, at);
    if (at != std::string::npos) overlayLevel = std::stoi(step.overlay.substr(at + 1));
    int writer = t.stageIndex(volume.substr(0, volume.find('/')));
    if (writer > stage)
      throw Error("overlay " + step.overlay + " is written by stage " + t.stage(writer).id() +
                  ", which runs after the step's stage " + step.stage);
  }

  StepPicture pic;
  if (step.iterations > 0) {  // stop the stage after that many iterations: earlier stages, then step it
    if (stage > 0) cursor.runThrough(stage - 1);
    cursor.invalidate(stage);
    for (int i = 0; i < step.iterations; ++i) cursor.runIteration(stage);
    pic.notes = "after " + std::to_string(step.iterations) + " of " + std::to_string(cursor.iterations(stage)) +
                " iterations of " + step.stage + " (the viewer's I key; the run line runs them all)";
  } else {
    cursor.runThrough(stage);
  }

  CapturedOutput cap = captureOutput(cursor.board(), *desc);
  const std::string address = t.id() + "/" + step.stage + "/" + step.output;
  // The picture is the view the viewer's visualiser for the output draws (its 2D view at the
  // step's level and slice, default display settings), with the same context lookups.
  const Visualiser& vis = visualiserFor(*desc);
  if (desc->kind != OutputKind::Buffer && step.level >= int(cap.levels.size()))
    throw Error("output " + address + " has levels 0.." + std::to_string(int(cap.levels.size()) - 1) + ", not " +
                std::to_string(step.level));
  const nlohmann::json stats = outputStatistics(cap);
  const nlohmann::json records = desc->kind == OutputKind::Buffer ? recordsJson(cap, 32) : nlohmann::json();
  ViewSettings view{step.level, SliceSpec{step.sliceAxis, step.sliceIndex}, DisplaySettings{}};
  VisualiserContext ctx{cap, stats, records, view, contextVolumeLookup(cursor, stage), contextOutputLookup(cursor, stage)};
  SliceImage s = vis.image2D(ctx);
  if (s.width == 0)
    throw Error("output " + address + " has no 2D view (a buffer without a position field: the viewer shows it as a "
                "table); a handout needs a picture (choose an image, a volume or a point buffer)");
  pic.image = rgbOf(s);
  pic.address = desc->kind == OutputKind::Buffer ? address : address + "@" + std::to_string(step.level);
  if (desc->kind == OutputKind::Volume3D) {
    const LevelData& L = cap.levels[step.level];
    SliceSpec slice = sliceToShow(L, SliceSpec{step.sliceAxis, step.sliceIndex});
    const char* axis = slice.axis == 0 ? "x" : slice.axis == 1 ? "y" : "z";
    std::string n = "slice " + std::string(axis) + " = " + std::to_string(slice.index) + " of " +
                    std::to_string(L.size[slice.axis]) + (step.sliceIndex < 0 ? " (the viewer's default slice)" : "");
    pic.notes += (pic.notes.empty() ? "" : "; ") + n;
  }

  // The viewer fits a picture to its panel with nearest filtering (voxels stay squares); a page
  // shows a coarse slice enlarged the same way, by a whole factor, up to the picture size.
  pic.displayScale = std::max(1, std::min(width_ / std::max(pic.image.width, 1), height_ / std::max(pic.image.height, 1)));

  const bool wantsOverlay = step.bounds || !step.overlay.empty();
  if (wantsOverlay && isCameraImage(cursor, stage, cap)) {
    OverlayContent content = overlayContent(cursor, volume, overlayLevel, !step.overlay.empty());
    if (!overlay_) overlay_ = std::make_unique<SceneOverlay>(cursor.shaders());
    overlay_->setCubes(content.cubes);
    overlay_->setBox(content.box);
    SceneOverlay::Options o{!step.overlay.empty(), step.bounds, false, 0.6f};
    const Camera& cam = cursor.camera();
    glm::mat4 viewProj = cam.projection(float(width_) / float(height_)) * cam.view();
    overlay_->render(width_, height_, viewProj, cursor.gpuScene(), o);
    blendOverlay(pic.image, overlay_->readPixels());
    std::string n = step.overlay.empty() ? std::string("volume bounds overlaid")
                                         : "overlay: " + content.message + (step.bounds ? ", with the volume bounds" : "");
    pic.notes += (pic.notes.empty() ? "" : "; ") + n;
  } else if (wantsOverlay) {
    pic.notes += std::string(pic.notes.empty() ? "" : "; ") + "overlay not drawn: " + address +
                 " is not a camera image";
  }

  if (step.besideReference) {
    // The reference beside the image, mapped through the shown output's display mapping, as the
    // viewer's compare view maps it.
    const DisplayImage right = referenceDisplayImage(*desc, step.referenceImage);
    pic.image = besideImage(pic.image, right);
    pic.displayScale = 1;
    pic.notes += std::string(pic.notes.empty() ? "" : "; ") + "right: the reference path tracer's " + step.referenceMode +
                 " image of the same scene and camera";
  }

  const ParamSet defaults = t.defaultParams();
  for (const auto& [name, d] : params.descs())
    if (!defaults.has(name) || !ParamDesc::sameValue(defaults.value(name), params.value(name)))
      pic.changed.push_back(name + "=" + d.format(params.value(name)));
  std::string until = stage == t.stageCount() - 1 ? "" : step.stage;
  pic.command = reproduceCommand(t.id(), step.scene, params, defaults, width_, height_, step.camera, until, "out");
  if (frame) {
    pic.framesCommand = reproduceCommand(t.id(), step.scene, stepParams, defaults, width_, height_, step.camera, until,
                                         "out") + " --frames " + std::to_string(step.frameCount);
    for (const std::string& a : step.frameAnimate) pic.framesCommand += " --animate " + a;
    std::string n = "the last of the step's " + std::to_string(step.frameCount) +
                    " frames, where the viewer stops playing them";
    if (frame->sceneTime) {
      char time[64];
      std::snprintf(time, sizeof time, " (the scene's animation at %.3g s)", *frame->sceneTime);
      n += time;
    }
    pic.notes = n + (pic.notes.empty() ? "" : "; " + pic.notes);
  }
  return pic;
}

}  // namespace voxlab
