// Frames tab: the technique played as frames while parameters move and an animated scene plays its
// own glTF animation (the timeline: play, pause, scrub, step a frame, loop), the animations and
// their values at the shown frame, the scene's time, and each frame's stage times as a plot. Frame
// k's values, its scene time and the stages it re-runs come from run/frames.h, as `voxlab run
// --frames` gives them; the stage list (panel_timeline.cpp) highlights what the shown frame re-ran.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

std::optional<std::pair<double, double>> Viewer::frameSceneTimes() const {
  if (!sceneAnimation.animated()) return std::nullopt;
  return frames.sceneTimes;
}

bool Viewer::showFrame(int k) {
  if (!framesAnimate()) {
    status = "frames: nothing animates; add NAME=FROM:TO in the Frames tab or load an animated scene";
    frames.playing = false;
    return false;
  }
  k = std::clamp(k, 0, frames.count - 1);
  ParamSet candidate = cursor->params();
  FrameValues values;
  try {
    values = animatedFrame(candidate, frames.animations, k, frames.count, frameSceneTimes());
    for (const auto& [name, value] : values.params) candidate.set(name, value);
  } catch (const Error& e) {
    status = std::string("frames: ") + e.what();
    frames.playing = false;
    return false;
  }
  if (!applyParams(candidate)) {
    frames.playing = false;
    return false;
  }
  // The scene camera in use follows its node; an orbit or fly camera stays where the user put it.
  if (values.sceneTime)
    poseCursorScene(*cursor, *scene, sceneAnimation, *values.sceneTime, pendingCamera ? -1 : cameraIndex);
  const int last = cursor->stageCount() - 1;
  frames.queued = staleStages(*cursor, last);
  frames.frame = k;
  frames.running = k;
  runs.lastRequest = last;
  requestRun(last);
  return true;
}

bool Viewer::frameReran(int stage) const {
  return frames.frame >= 0 && frames.running < 0 &&
         std::find(frames.reran.begin(), frames.reran.end(), stage) != frames.reran.end();
}

void Viewer::updateFrames() {
  if (frames.running < 0 || runs.target >= 0 || runs.iterateStage >= 0) return;
  // The frame's stages have run (or the run stopped on an error: only what is Done counts).
  std::vector<float> ms(size_t(cursor->stageCount()), 0.0f);
  frames.reran.clear();
  for (int i : frames.queued)
    if (cursor->record(i).state == StageState::Done) {
      ms[size_t(i)] = float(cursor->record(i).cpuMs);
      frames.reran.push_back(i);
    }
  frames.stageMs[frames.running] = ms;
  const int done = frames.running;
  frames.running = -1;
  ++generation;
  if (!frames.playing) return;
  if (done == frames.pauseAt || (done + 1 >= frames.count && !frames.looping)) {
    frames.playing = frames.scriptWaits = false;
    frames.pauseAt = -1;
    return;
  }
  showFrame(done + 1 >= frames.count ? 0 : done + 1);
}

namespace {

// "NAME=FROM:TO" added to the timeline; false + the one-line reason in frames.error.
bool addAnimation(Viewer& v, const std::string& text) {
  try {
    ParamAnimation a = parseAnimation(v.cursor->params(), text);
    auto& list = v.frames.animations;
    list.erase(std::remove_if(list.begin(), list.end(), [&](const ParamAnimation& b) { return b.name == a.name; }),
               list.end());
    list.push_back(a);
    v.frames.error.clear();
    v.frames.stageMs.clear();
    return true;
  } catch (const Error& e) {
    v.frames.error = e.what();
    return false;
  }
}

// Stage times per frame: one line per stage that re-ran in some frame (0 where a frame did not
// re-run it), and the frame's total above them.
void drawFrameTimes(Viewer& v) {
  const Technique& t = v.cursor->technique();
  if (v.frames.stageMs.empty()) {
    ImGui::TextDisabled("no frame has run yet");
    return;
  }
  std::vector<float> total(size_t(v.frames.count), 0.0f);
  for (const auto& [k, ms] : v.frames.stageMs)
    if (k < v.frames.count)  // a frame that ran before the count was lowered is off the plot
      for (float m : ms) total[size_t(k)] += m;
  const float top = *std::max_element(total.begin(), total.end());
  const float width = std::max(120.0f, ImGui::GetContentRegionAvail().x);
  char label[96];
  std::snprintf(label, sizeof label, "total, max %.0f ms", top);
  ImGui::PlotHistogram("##frame-total", total.data(), int(total.size()), 0, label, 0.0f, top * 1.1f + 1e-3f,
                       ImVec2(width, 60));
  for (int i = 0; i < t.stageCount(); ++i) {
    std::vector<float> line(size_t(v.frames.count), 0.0f);
    bool any = false;
    for (const auto& [k, ms] : v.frames.stageMs) {
      if (k >= v.frames.count) continue;
      line[size_t(k)] = ms[size_t(i)];
      any = any || ms[size_t(i)] > 0.0f;
    }
    if (!any) continue;
    const float peak = *std::max_element(line.begin(), line.end());
    std::snprintf(label, sizeof label, "%s, max %.1f ms", t.stage(i).id(), peak);
    ImGui::PushID(i);
    ImGui::PlotLines("##stage-ms", line.data(), int(line.size()), 0, label, 0.0f, peak * 1.1f + 1e-3f, ImVec2(width, 34));
    ImGui::PopID();
  }
}

}  // namespace

void Viewer::drawFrames() {
  FramesTimeline& f = frames;
  ImGui::SetNextItemWidth(220);
  const bool entered = ImGui::InputTextWithHint("##animate", "light.0.azimuth=0:90", f.animateText, sizeof f.animateText,
                                                ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Animate") || entered) && addAnimation(*this, f.animateText)) f.animateText[0] = 0;
  if (!f.error.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kErrorColour);
    ImGui::TextWrapped("%s", f.error.c_str());
    ImGui::PopStyleColor();
  }
  FrameValues shown;
  if (f.frame >= 0 && framesAnimate())
    shown = animatedFrame(cursor->params(), f.animations, f.frame, f.count, frameSceneTimes());
  if (sceneAnimation.animated()) {
    // The scene's own animation plays over the same frames, over the time range set here.
    std::string names;
    for (const std::string& n : sceneAnimation.names) names += (names.empty() ? "" : ", ") + n;
    ImGui::Text("scene animation %s (%.2f s)", names.empty() ? "(unnamed)" : names.c_str(), sceneAnimation.duration);
    float range[2] = {float(f.sceneTimes.first), float(f.sceneTimes.second)};
    ImGui::SetNextItemWidth(160);
    if (ImGui::InputFloat2("time range, s", range, "%.2f", ImGuiInputTextFlags_EnterReturnsTrue)) {
      range[0] = std::max(range[0], 0.0f);
      range[1] = std::max(range[1], range[0]);
      f.sceneTimes = {double(range[0]), double(range[1])};
      f.stageMs.clear();
    }
    if (shown.sceneTime) {
      ImGui::SameLine();
      ImGui::Text("now %.3f s", *shown.sceneTime);
    }
  }
  for (size_t i = 0; i < f.animations.size(); ++i) {
    const ParamAnimation& a = f.animations[i];
    ImGui::PushID(int(i));
    if (ImGui::SmallButton("x")) {
      f.animations.erase(f.animations.begin() + long(i));
      f.stageMs.clear();
      ImGui::PopID();
      break;
    }
    ImGui::SameLine();
    if (i < shown.params.size())
      ImGui::Text("%s: %g to %g (now %g)", a.name.c_str(), a.from, a.to, shown.params[i].second);
    else
      ImGui::Text("%s: %g to %g", a.name.c_str(), a.from, a.to);
    ImGui::PopID();
  }
  if (!framesAnimate()) {
    ImGui::TextDisabled("nothing animates: type NAME=FROM:TO above (a number parameter), or load an animated scene");
    return;
  }
  ImGui::SetNextItemWidth(120);
  if (ImGui::InputInt("frames", &f.count)) {
    f.count = std::clamp(f.count, 2, 1024);
    f.stageMs.clear();
  }
  ImGui::SameLine();
  ImGui::Checkbox("loop", &f.looping);
  if (ImGui::Button("|<")) showFrame(0);
  ImGui::SameLine();
  if (ImGui::Button("<")) showFrame(f.frame - 1);
  ImGui::SameLine();
  if (ImGui::Button(f.playing ? "Pause" : "Play")) {
    f.playing = !f.playing;
    if (f.playing && f.running < 0) showFrame(f.frame + 1 >= f.count ? 0 : f.frame + 1);
  }
  ImGui::SameLine();
  if (ImGui::Button(">")) showFrame(f.frame + 1);
  ImGui::SameLine();
  if (ImGui::Button(">|")) showFrame(f.count - 1);
  int scrub = std::max(f.frame, 0);
  ImGui::SetNextItemWidth(-1);
  if (ImGui::SliderInt("##scrub", &scrub, 0, f.count - 1, "frame %d") && scrub != f.frame) showFrame(scrub);
  if (f.running >= 0)
    ImGui::TextColored(kWarningColour, "frame %d of %d: running %zu stages", f.running + 1, f.count, f.queued.size());
  else if (f.frame >= 0)
    ImGui::Text("frame %d of %d re-ran %zu of %d stages (highlighted in the stage list)", f.frame + 1, f.count,
                f.reran.size(), cursor->stageCount());
  ImGui::Separator();
  ImGui::TextUnformatted("CPU ms per stage, per frame");
  drawFrameTimes(*this);
}

VOXLAB_REGISTER_DETAILS_TAB(frames, "frames", "Frames", 45, nullptr, [](Viewer& v) { v.drawFrames(); });

// --- Script verbs: the frames timeline --------------------------------------------------------------

namespace {

void requireAnimations(const Viewer& viewer, const ScriptCall& call) {
  if (!viewer.framesAnimate())
    call.fail("nothing animates (frames-animate NAME=FROM:TO first, or a scene with an animation)");
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(frames, 85,
  {"frames-animate", 1, 1, "frames-animate NAME=FROM:TO (add an animated parameter, as the Frames tab)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (!addAnimation(viewer, call.arg(0))) call.fail(viewer.frames.error);
   }},
  {"frames-clear", 0, 0, "frames-clear (remove every animated parameter, as the x buttons; a scene animation stays)",
   [](Viewer& viewer, const ScriptCall&) {
     viewer.frames.animations.clear();
     viewer.frames.stageMs.clear();
   }},
  {"frames-count", 1, 1, "frames-count N (the timeline's frame count, 2 or more)",
   [](Viewer& viewer, const ScriptCall& call) {
     const int n = call.intArg(0);
     if (n < 2) call.badArgument("a timeline has 2 frames or more, got " + call.arg(0));
     viewer.frames.count = n;
     viewer.frames.stageMs.clear();
   }},
  {"frames-time-range", 1, 1, "frames-time-range FROM:TO (seconds of the scene's animation the frames span)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (!viewer.sceneAnimation.animated()) call.fail("scene '" + viewer.sceneName + "' has no animation");
     try {
       viewer.frames.sceneTimes = parseTimeRange(call.arg(0));
     } catch (const Error& e) {
       call.badArgument(e.what());
     }
     viewer.frames.stageMs.clear();
   }},
  {"frames-loop", 1, 1, "frames-loop on|off (play from the first frame again after the last)",
   [](Viewer& viewer, const ScriptCall& call) { viewer.frames.looping = call.onOff(0); }},
  {"frames-play", 0, 1, "frames-play [N] (play on from the shown frame; N: pause after N frames)",
   [](Viewer& viewer, const ScriptCall& call) {
     requireAnimations(viewer, call);
     FramesTimeline& f = viewer.frames;
     const int n = call.count() ? call.intArg(0) : 0;
     if (call.count() && n < 1) call.badArgument("N must be 1 or more, got " + call.arg(0));
     const int first = f.frame + 1 >= f.count ? 0 : f.frame + 1;
     f.pauseAt = n ? (first + n - 1) % f.count : -1;
     f.playing = f.scriptWaits = true;
     if (!viewer.showFrame(first)) call.fail(viewer.status);
   }},
  {"frames-wait", 0, 0, "frames-wait (wait until the timeline stops playing: a lesson step's frames have all run)",
   [](Viewer& viewer, const ScriptCall&) {
     if (viewer.frames.playing) viewer.frames.scriptWaits = true;
   }},
  {"frame", 1, 1, "frame K (scrub to frame K, counted from 0, and run what it re-runs)",
   [](Viewer& viewer, const ScriptCall& call) {
     requireAnimations(viewer, call);
     const int k = call.intArg(0);
     if (k < 0 || k >= viewer.frames.count)
       call.badArgument("frame " + call.arg(0) + " is not one of 0.." + std::to_string(viewer.frames.count - 1));
     viewer.frames.playing = false;
     if (!viewer.showFrame(k)) call.fail(viewer.status);
   }},
  {"frame-step", 1, 1, "frame-step +1|-1 (one frame forward or back, as the < and > buttons)",
   [](Viewer& viewer, const ScriptCall& call) {
     requireAnimations(viewer, call);
     const int d = call.intArg(0);
     if (d != 1 && d != -1) call.badArgument("the step is +1 or -1, got " + call.arg(0));
     viewer.frames.playing = false;
     if (!viewer.showFrame(viewer.frames.frame + d)) call.fail(viewer.status);
   }},
  {"expect-frame", 1, 1, "expect-frame K (the timeline shows frame K, its stages run)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (viewer.frames.frame != call.intArg(0))
       call.fail("the timeline shows frame " + std::to_string(viewer.frames.frame) + ", expected " + call.arg(0));
     std::printf("frame %d:", viewer.frames.frame);
     const FrameValues values = animatedFrame(viewer.cursor->params(), viewer.frames.animations, viewer.frames.frame,
                                              viewer.frames.count, viewer.frameSceneTimes());
     for (const auto& [name, value] : values.params) std::printf(" %s=%g", name.c_str(), value);
     if (values.sceneTime) std::printf(" scene time %g s", *values.sceneTime);
     std::printf("\n");
   }},
  {"expect-scene-time", 1, 1, "expect-scene-time SECONDS (the shown frame poses the scene at this time of its animation)",
   [](Viewer& viewer, const ScriptCall& call) {
     const std::optional<double> shown =
         viewer.frames.frame < 0 ? std::nullopt
                                 : animatedFrame(viewer.cursor->params(), viewer.frames.animations, viewer.frames.frame,
                                                 viewer.frames.count, viewer.frameSceneTimes()).sceneTime;
     if (!shown) call.fail("no frame of a scene animation is shown");
     char* end = nullptr;
     const double want = std::strtod(call.arg(0).c_str(), &end);
     if (end == call.arg(0).c_str() || *end) call.badArgument("SECONDS must be a number, got " + call.arg(0));
     // Frame times are FROM + (TO - FROM) k / (N - 1) in double: a script writes them to a few
     // decimals (2/3 s as 0.6667), so half a millisecond tells frames apart and admits the rounding.
     if (std::abs(*shown - want) > 5e-4)
       call.fail("frame " + std::to_string(viewer.frames.frame) + " poses the scene at " + std::to_string(*shown) +
                 " s, expected " + call.arg(0));
   }},
  {"expect-reran", 2, 2, "expect-reran STAGE yes|no (the shown frame re-ran STAGE: highlighted in the stage list)",
   [](Viewer& viewer, const ScriptCall& call) {
     const int i = viewer.cursor->technique().stageIndex(call.arg(0));
     if (call.arg(1) != "yes" && call.arg(1) != "no") call.badArgument("expected yes or no, got " + call.arg(1));
     const bool want = call.arg(1) == "yes";
     if (viewer.frameReran(i) != want)
       call.fail("frame " + std::to_string(viewer.frames.frame) + (want ? " did not re-run " : " re-ran ") + call.arg(0));
   }},
  {"expect-frame-times", 1, 1, "expect-frame-times N (the plot holds the stage times of N frames)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (int(viewer.frames.stageMs.size()) != call.intArg(0))
       call.fail("the plot holds " + std::to_string(viewer.frames.stageMs.size()) + " frames, expected " + call.arg(0));
   }});

}  // namespace voxlab
