// Lesson tab: the step's narrative (Markdown headings and paragraphs), previous / next; and what a
// lesson step does to the viewer (technique, scene, parameters, camera, stage, overlay, iterations,
// the reference beside the image, the frames it plays on the Frames tab's timeline).
#include <cstdio>

#include "core/error.h"
#include "inspect/inspect_logic.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

void Viewer::applyLessonStep(int i) {
  if (lesson.steps.empty()) return;
  i = std::clamp(i, 0, int(lesson.steps.size()) - 1);
  const LessonStep& s = lesson.steps[i];
  if (s.technique != cursor->technique().id()) switchTechnique(s.technique);
  if (s.scene != sceneName && !loadSceneNamed(s.scene))
    throw Error(lesson.path + ":" + std::to_string(s.line) + ": " + sceneError);
  ParamSet p = cursor->technique().defaultParams();
  for (const auto& [n, v] : s.sets) p.setText(n, v);
  cursor->setParams(p);
  // An animated scene starts at rest (a frames step plays it from there), as the handout pictures it.
  frames.sceneTimes = {0.0, double(sceneAnimation.duration)};
  if (sceneAnimation.animated()) poseCursorScene(*cursor, *scene, sceneAnimation, 0.0, s.camera);
  if (s.camera != cameraIndex || pendingCamera) {
    cursor->useSceneCamera(s.camera);
    pendingCamera.reset();
    cameraIndex = s.camera;
  }
  selectStage(cursor->technique().stageIndex(s.stage));
  if (!s.output.empty()) selectOutput(s.output);
  view.level = s.level;
  view.slice = SliceSpec{s.sliceAxis, s.sliceIndex};
  if (lessonStep < 0) wantTab = "lesson";
  lessonStep = i;
  presenter.page = 0;  // a new step opens at its first page in presenter mode
  presenter.pages = 1;
  overlay.options.bounds = s.bounds;
  overlay.options.voxels = !s.overlay.empty();
  if (!s.overlay.empty()) {
    size_t at = s.overlay.find('@');
    overlay.volume = s.overlay.substr(0, at);
    overlay.level = at == std::string::npos ? -1 : std::stoi(s.overlay.substr(at + 1));
  }
  // "beside": "reference": the compare view, side by side with the reference image.
  if (s.besideReference) {
    compare.on = compare.setByLesson = true;
    compare.source = CompareState::Source::File;
    compare.mode = CompareState::Mode::SideBySide;
    std::snprintf(compare.file, sizeof compare.file, "%s", s.referenceImage.c_str());
    compare.key.clear();
  } else if (compare.setByLesson) {
    compare.on = compare.setByLesson = false;
  }
  // "frames": the timeline takes the step's animations and plays them once from frame 0.
  frames.playing = frames.scriptWaits = false;
  frames.running = frames.pauseAt = frames.frame = -1;  // no frame shown: the stage list marks nothing
  frames.reran.clear();
  if (s.frameCount > 0) {
    frames.animations = s.frameAnimations;
    frames.count = s.frameCount;
    frames.looping = false;
    frames.stageMs.clear();
    frames.playing = true;
    selectStage(cursor->technique().stageIndex(s.stage));
    showFrame(0);
    return;
  }
  if (s.iterations > 0) {
    // Stop the stage after that many iterations: run what comes before, then step it.
    cursor->invalidate(selected);
    stepIteration(s.iterations);
    return;
  }
  runs.lastRequest = selected;
  requestRun(selected);
}

void Viewer::drawLesson() {
  ImGui::TextWrapped("%s", lesson.title.c_str());
  ImGui::Text("step %d of %zu", lessonStep + 1, lesson.steps.size());
  if (ImGui::Button("< Previous step")) applyLessonStep(lessonStep - 1);
  ImGui::SameLine();
  if (ImGui::Button("Next step >")) applyLessonStep(lessonStep + 1);
  ImGui::Separator();
  if (lessonStep >= 0 && !lesson.steps[size_t(lessonStep)].sweep.empty()) {
    drawLessonSweep(lesson.steps[size_t(lessonStep)]);
    ImGui::Separator();
  }
  ImGui::BeginChild("narrative");
  // The narrative as presenter mode sets it (headings, paragraphs, list items; inline markup
  // reduced to its words), so that neither shows "**" or backticks.
  auto markdown = [](const std::string& text) {
    for (const NarrativeBlock& block : narrativeBlocks(text)) {
      switch (block.kind) {
        case NarrativeBlock::Kind::Heading:
          ImGui::Spacing();
          ImGui::TextColored(ImVec4(0.6f, 0.8f, 1.0f, 1), "%s", block.text.c_str());
          break;
        case NarrativeBlock::Kind::Item:
          ImGui::Bullet();
          ImGui::TextWrapped("%s", block.text.c_str());
          break;
        case NarrativeBlock::Kind::Paragraph:
          ImGui::TextWrapped("%s", block.text.c_str());
          ImGui::Spacing();
          break;
      }
    }
  };
  if (lessonStep >= 0) {
    markdown(lesson.steps[lessonStep].narrative);
    if (lessonStep + 1 == int(lesson.steps.size()) && !lesson.epilogue.empty()) {
      ImGui::Separator();
      markdown(lesson.epilogue);
    }
  }
  ImGui::EndChild();
}

VOXLAB_REGISTER_DETAILS_TAB(lesson, "lesson", "Lesson", 40, [](const Viewer& v) { return !v.lesson.steps.empty(); },
                            [](Viewer& v) { v.drawLesson(); });

// --- Script verbs: lessons --------------------------------------------------------------------------

namespace {

void printLessonStep(const Viewer& viewer) {
  const LessonStep& step = viewer.lesson.steps[size_t(viewer.lessonStep)];
  std::printf("lesson step %d/%zu: %s/%s\n", viewer.lessonStep + 1, viewer.lesson.steps.size(),
              step.stage.c_str(), step.output.c_str());
}

void moveLessonStep(Viewer& viewer, const ScriptCall& call) {
  if (viewer.lesson.steps.empty()) call.fail("no lesson is open");
  const int next = viewer.lessonStep + (call.verb() == "lesson-next" ? 1 : -1);
  if (next < 0 || next >= int(viewer.lesson.steps.size()))
    call.fail("no step " + std::to_string(next + 1) + "; the lesson has " + std::to_string(viewer.lesson.steps.size()));
  viewer.applyLessonStep(next);
  printLessonStep(viewer);
}

void playLessonToEnd(Viewer& viewer, const ScriptCall& call) {
  if (viewer.lesson.steps.empty()) call.fail("no lesson is open");
  if (viewer.lessonStep + 1 >= int(viewer.lesson.steps.size())) return;
  viewer.applyLessonStep(viewer.lessonStep + 1);
  printLessonStep(viewer);
  --viewer.script.next;  // repeat this action after the step has run
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(lesson, 80,
  {"lesson", 1, 1, "lesson FILE (load it and apply step 1)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.lesson = loadLesson(call.arg(0));
     viewer.applyLessonStep(0);
   }},
  {"lesson-next", 0, 0, "lesson-next", moveLessonStep},
  {"lesson-prev", 0, 0, "lesson-prev", moveLessonStep},
  {"lesson-end", 0, 0, "lesson-end (play every remaining step, running each)", playLessonToEnd},
  {"expect-lesson-step", 1, 1, "expect-lesson-step N (the lesson is at step N, counted from 1)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (viewer.lesson.steps.empty()) call.fail("no lesson is open");
     if (viewer.lessonStep + 1 != call.intArg(0))
       call.fail("the lesson is at step " + std::to_string(viewer.lessonStep + 1) + ", expected " + call.arg(0));
   }});

}  // namespace voxlab
