// Presenter mode (`voxlab view --present`, keys P / F11): for a lecture on a projector. The view
// fills the window's height on the left, the lesson step's narrative is set large beside it (fitted
// to its column), the UI scale follows the window, and the usual panels stay hidden until the
// pointer reaches the window's left edge (Technique) or right edge (Details). The arrow, page and
// number keys drive the lesson; a probed pixel or cell is marked by a ring and crosshair large
// enough for the back row (drawLaserPointer).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "core/paths.h"
#include "inspect/script_verbs.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace {

// Projector palette: light text on near black (high contrast in a dark room), headings in amber.
const ImVec4 kPresenterBackground{0.04f, 0.04f, 0.05f, 1.0f};
const ImVec4 kNarrativeText{0.96f, 0.96f, 0.94f, 1.0f};
const ImVec4 kHeadingText{1.0f, 0.80f, 0.25f, 1.0f};
const ImVec4 kQuietText{0.62f, 0.66f, 0.72f, 1.0f};
const ImU32 kProgressDone = IM_COL32(255, 204, 64, 255);
const ImU32 kProgressTodo = IM_COL32(70, 74, 84, 255);

const char* kNarrativeFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
const char* kHeadingFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf";

// Basic Latin and Latin-1, Greek, general punctuation (dashes, quotes), super/subscripts, arrows,
// mathematical operators: what the lessons' prose uses.
const ImWchar kNarrativeGlyphs[] = {0x0020, 0x00FF, 0x0370, 0x03FF, 0x2000, 0x206F, 0x2070, 0x209F,
                                    0x2190, 0x21FF, 0x2200, 0x22FF, 0};

}  // namespace

float Viewer::presenterUiScale() const {
  int w = opt.windowWidth, h = opt.windowHeight;
  if (window) window->framebufferSize(w, h);
  return std::clamp(std::min(w / 1280.0f, h / 720.0f), 0.75f, 3.0f);
}

void Viewer::addPresenterFonts(float scale) {
  ImGuiIO& io = ImGui::GetIO();
  presenter.narrativeFont = presenter.headingFont = nullptr;
  // The narrative is set at up to 30 px per unit of UI scale (45 px at 1920x1080) and fitted
  // down from there; DejaVu Sans when it is installed (fonts-dejavu-core), else the UI font.
  const float px = std::round(30.0f * scale);
  ImFontConfig cfg;
  cfg.OversampleH = 2;
  if (fileExists(kNarrativeFontFile))
    presenter.narrativeFont = io.Fonts->AddFontFromFileTTF(kNarrativeFontFile, px, &cfg, kNarrativeGlyphs);
  if (fileExists(kHeadingFontFile))
    presenter.headingFont = io.Fonts->AddFontFromFileTTF(kHeadingFontFile, px, &cfg, kNarrativeGlyphs);
  if (!presenter.headingFont) presenter.headingFont = presenter.narrativeFont;
}

void Viewer::setPresenting(bool on) {
  if (on == presenter.on) return;
  presenter.on = on;
  presenter.leftShown = presenter.rightShown = false;
  if (on) {
    presenter.restoreScale = uiScale;
    wantUiScale = presenterUiScale();
  } else {
    wantUiScale = presenter.restoreScale;
  }
  status = on ? "presenter mode (P or F11 leaves)" : "";
}

bool Viewer::presenterKey(int key) {
  if (key == GLFW_KEY_P || key == GLFW_KEY_F11) {
    setPresenting(!presenter.on);
    return true;
  }
  if (!presenter.on) return false;
  if (key == GLFW_KEY_ESCAPE) {
    setPresenting(false);
    return true;
  }
  if (lesson.steps.empty()) return false;
  const int last = int(lesson.steps.size()) - 1;
  const bool next = key == GLFW_KEY_PAGE_DOWN || key == GLFW_KEY_RIGHT || key == GLFW_KEY_SPACE;
  const bool back = key == GLFW_KEY_PAGE_UP || key == GLFW_KEY_LEFT || key == GLFW_KEY_BACKSPACE;
  // A long step's pages turn first (PresenterState::page).
  if (next && presenter.page + 1 < presenter.pages) {
    ++presenter.page;
    return true;
  }
  if (back && presenter.page > 0) {
    --presenter.page;
    return true;
  }
  int to = -1;
  if (next) to = std::min(lessonStep + 1, last);
  else if (back) to = std::max(lessonStep - 1, 0);
  else if (key == GLFW_KEY_HOME) to = 0;
  else if (key == GLFW_KEY_END) to = last;
  else if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) to = key - GLFW_KEY_1;
  else if (key == GLFW_KEY_0) to = 9;
  else if (key >= GLFW_KEY_KP_1 && key <= GLFW_KEY_KP_9) to = key - GLFW_KEY_KP_1;
  if (to < 0) return false;
  if (to > last) {
    status = "the lesson has " + std::to_string(last + 1) + " steps";
    return true;
  }
  if (to != lessonStep) {
    applyLessonStep(to);
    // Back to the previous step opens its last page (clamped to its page count when drawn).
    presenter.page = back ? 1 << 20 : 0;
    presenter.pages = 1;
  }
  return true;
}

bool Viewer::handlePresenterKeys() {
  static const int kKeys[] = {GLFW_KEY_P,    GLFW_KEY_F11,  GLFW_KEY_ESCAPE,    GLFW_KEY_PAGE_DOWN, GLFW_KEY_PAGE_UP,
                              GLFW_KEY_RIGHT, GLFW_KEY_LEFT, GLFW_KEY_SPACE,     GLFW_KEY_BACKSPACE, GLFW_KEY_HOME,
                              GLFW_KEY_END,   GLFW_KEY_0,    GLFW_KEY_1,         GLFW_KEY_2,         GLFW_KEY_3,
                              GLFW_KEY_4,     GLFW_KEY_5,    GLFW_KEY_6,         GLFW_KEY_7,         GLFW_KEY_8,
                              GLFW_KEY_9};
  ImGuiIO& io = ImGui::GetIO();
  // The presses queued since the last frame (keyPresses), not ImGui's key state: a remote's tap
  // can begin and end between two frames, and while a stage runs a frame takes long.
  std::vector<int> presses;
  presses.swap(keyPresses);
  if (io.KeyCtrl || io.KeyAlt || io.WantTextInput) return presenter.on && !lesson.steps.empty();
  for (int k : presses) {
    const bool presenterKeyCode = std::find(std::begin(kKeys), std::end(kKeys), k) != std::end(kKeys) ||
                                  (k >= GLFW_KEY_KP_1 && k <= GLFW_KEY_KP_9);
    if (presenterKeyCode) presenterKey(k);
  }
  return presenter.on && !lesson.steps.empty();
}

void Viewer::drawLaserPointer(ImDrawList* dl, ImVec2 at, ImVec2 imageSize) const {
  // A ring a little under a twentieth of the image across with four ticks pointing at its centre,
  // yellow on a black outline so it reads on white walls and on black background alike; the
  // probed pixel itself stays uncovered.
  const float r = std::max(14.0f, 0.045f * std::min(imageSize.x, imageSize.y));
  const float w = std::max(3.0f, r * 0.12f);
  const ImU32 outline = IM_COL32(0, 0, 0, 230), ring = IM_COL32(255, 235, 0, 255);
  for (int pass = 0; pass < 2; ++pass) {
    const ImU32 c = pass == 0 ? outline : ring;
    const float t = pass == 0 ? w + 4.0f : w;
    dl->AddCircle(at, r, c, 48, t);
    const float in = r * 0.45f, out = r * 1.9f;
    dl->AddLine(ImVec2(at.x - out, at.y), ImVec2(at.x - in, at.y), c, t);
    dl->AddLine(ImVec2(at.x + in, at.y), ImVec2(at.x + out, at.y), c, t);
    dl->AddLine(ImVec2(at.x, at.y - out), ImVec2(at.x, at.y - in), c, t);
    dl->AddLine(ImVec2(at.x, at.y + in), ImVec2(at.x, at.y + out), c, t);
  }
}

void Viewer::drawNarrative(ImVec2 size) {
  ImFont* body = presenter.narrativeFont ? presenter.narrativeFont : ImGui::GetFont();
  ImFont* heading = presenter.headingFont ? presenter.headingFont : body;
  const float maxPx = body->FontSize;
  const float pad = ImGui::GetStyle().WindowPadding.x;  // drawPresenter pads the column
  const float wrap = size.x - 2 * pad;
  ImGui::PushTextWrapPos(size.x - pad);

  // Header: the lesson's title and the step's place in it as a row of segments.
  ImGui::PushFont(heading);
  ImGui::SetWindowFontScale(0.5f);
  if (lesson.steps.empty()) {
    ImGui::TextColored(kQuietText, "presenter mode");
  } else {
    ImGui::TextColored(kQuietText, "%s  \xC2\xB7  step %d of %zu", lesson.title.c_str(), lessonStep + 1, lesson.steps.size());
  }
  ImGui::SetWindowFontScale(1.0f);
  ImGui::PopFont();
  auto* dl = ImGui::GetWindowDrawList();
  const ImVec2 wp = ImGui::GetWindowPos();
  if (!lesson.steps.empty()) {
    const int n = int(lesson.steps.size());
    const float y = ImGui::GetCursorScreenPos().y + 0.15f * maxPx, h = std::max(4.0f, 0.14f * maxPx), gap = 0.25f * h;
    const float seg = (wrap - gap * (n - 1)) / n;
    for (int i = 0; i < n; ++i) {
      const float x = wp.x + pad + i * (seg + gap);
      dl->AddRectFilled(ImVec2(x, y), ImVec2(x + seg, y + h), i <= lessonStep ? kProgressDone : kProgressTodo, h * 0.5f);
    }
    ImGui::Dummy(ImVec2(wrap, 0.6f * maxPx));
  }

  // The step's narrative (and, on the last step, the epilogue), fitted: the largest size from
  // maxPx down to the smallest a hall reads (32 px per 1080 lines of window) at which every block
  // fits above the footer; at that smallest size a longer narrative is cut into pages.
  std::vector<NarrativeBlock> blocks;
  if (lessonStep >= 0 && lessonStep < int(lesson.steps.size())) {
    blocks = narrativeBlocks(lesson.steps[lessonStep].narrative);
    // The lesson's title is in the header already.
    if (!blocks.empty() && blocks[0].kind == NarrativeBlock::Kind::Heading && blocks[0].text == lesson.title)
      blocks.erase(blocks.begin());
    if (lessonStep + 1 == int(lesson.steps.size()))
      for (auto& b : narrativeBlocks(lesson.epilogue)) blocks.push_back(b);
  } else {
    blocks.push_back({NarrativeBlock::Kind::Heading, cursor->technique().id()});
    blocks.push_back({NarrativeBlock::Kind::Paragraph,
                      std::string(cursor->technique().stage(selected).title()) + " \xE2\x80\x94 open a lesson (--lesson FILE) "
                      "to show its narrative here."});
  }
  const float footer = 1.6f * 0.5f * maxPx;
  const float avail = size.y - ImGui::GetCursorPosY() - pad - footer;
  const float spacing = ImGui::GetStyle().ItemSpacing.y;  // after each text and each gap
  auto heightAt = [&](float px) {
    float hsum = 0;
    for (const auto& b : blocks) {
      const bool isHeading = b.kind == NarrativeBlock::Kind::Heading;
      const float s = isHeading ? px * 1.12f : px;
      hsum += (isHeading ? heading : body)->CalcTextSizeA(s, FLT_MAX, wrap, b.text.c_str()).y;
      hsum += spacing + std::max((b.kind == NarrativeBlock::Kind::Item ? 0.25f : 0.55f) * px, spacing);
    }
    return hsum;
  };
  const float minPx = std::min(maxPx, std::round(32.0f * ImGui::GetIO().DisplaySize.y / 1080.0f));
  float px = maxPx;
  while (px > minPx && heightAt(px) > avail) px -= 1.0f;
  presenter.narrativePx = px;
  // Pages: consecutive blocks that fit the column at px (a block taller than the column alone).
  std::vector<std::vector<NarrativeBlock>> pages(1);
  {
    std::vector<NarrativeBlock> one(1);
    float used = 0.0f;
    for (const auto& b : blocks) {
      one[0] = b;
      std::swap(blocks, one);
      const float h = heightAt(px);
      std::swap(blocks, one);
      if (!pages.back().empty() && used + h > avail) {
        pages.emplace_back();
        used = 0.0f;
      }
      pages.back().push_back(b);
      used += h;
    }
  }
  presenter.pages = int(pages.size());
  presenter.page = std::clamp(presenter.page, 0, presenter.pages - 1);
  ImGui::BeginChild("narrative-text", ImVec2(wrap, avail), false, ImGuiWindowFlags_NoBackground);
  ImGui::PushTextWrapPos(wrap);
  for (const auto& b : pages[size_t(presenter.page)]) {
    const bool isHeading = b.kind == NarrativeBlock::Kind::Heading;
    ImFont* f = isHeading ? heading : body;
    ImGui::PushFont(f);
    ImGui::SetWindowFontScale((isHeading ? px * 1.12f : px) / f->FontSize);
    ImGui::PushStyleColor(ImGuiCol_Text, isHeading ? kHeadingText : kNarrativeText);
    ImGui::TextWrapped("%s", b.text.c_str());
    ImGui::PopStyleColor();
    ImGui::SetWindowFontScale(1.0f);
    ImGui::PopFont();
    ImGui::Dummy(ImVec2(0, std::max((b.kind == NarrativeBlock::Kind::Item ? 0.25f : 0.55f) * px - spacing, 0.0f)));
  }
  ImGui::PopTextWrapPos();
  ImGui::EndChild();

  // Footer: what the keys do, or that the step's stages are still running.
  ImGui::SetCursorPosY(size.y - pad - footer * 0.8f);
  ImGui::PushFont(body);
  ImGui::SetWindowFontScale(0.5f);
  if (runs.target >= 0 || runs.iterateStage >= 0)
    ImGui::TextColored(kHeadingText, "running %s ...", cursor->technique().stage(std::max(runs.target, runs.iterateStage)).id());
  else if (!lesson.steps.empty())
    ImGui::TextColored(kQuietText, "%sPgDn / \xE2\x86\x92 next   PgUp / \xE2\x86\x90 back   1\xE2\x80\x93" "9 step   P leave",
                       presenter.pages > 1 ? ("page " + std::to_string(presenter.page + 1) + " of " +
                                              std::to_string(presenter.pages) + "   ").c_str()
                                           : "");
  else
    ImGui::TextColored(kQuietText, "P leave   mouse at the left or right edge: panels");
  ImGui::SetWindowFontScale(1.0f);
  ImGui::PopFont();
  ImGui::PopTextWrapPos();
}

void Viewer::drawPresenter() {
  ImGuiIO& io = ImGui::GetIO();
  const ImVec2 win = io.DisplaySize;
  wantUiScale = presenterUiScale();  // follows the window as it is resized
  // The narrative column: what a square view of the window's height leaves, between 30 % and 50 %
  // of the width (840 px at 1920x1080); under the view in a portrait window.
  const bool portrait = win.y > win.x;
  const float column = portrait ? std::round(0.4f * win.y) : std::round(std::clamp(win.x - win.y, 0.3f * win.x, 0.5f * win.x));
  const ImVec2 viewSize = portrait ? ImVec2(win.x, win.y - column) : ImVec2(win.x - column, win.y);
  const ImVec2 textPos = portrait ? ImVec2(0, viewSize.y) : ImVec2(viewSize.x, 0);
  const ImVec2 textSize = portrait ? ImVec2(win.x, column) : ImVec2(column, win.y);

  const ImGuiWindowFlags bare = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize |
                                ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBringToFrontOnFocus;
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0, 0));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
  ImGui::PushStyleColor(ImGuiCol_WindowBg, kPresenterBackground);
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(viewSize);
  ImGui::Begin("Presenter view", nullptr, bare);
  drawView();
  ImGui::End();
  ImGui::SetNextWindowPos(textPos);
  ImGui::SetNextWindowSize(textSize);
  const float pad = std::round(0.045f * std::min(textSize.x, textSize.y * 16.0f / 9.0f));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(pad, pad));
  ImGui::Begin("Presenter narrative", nullptr, bare | ImGuiWindowFlags_NoScrollbar);
  drawNarrative(textSize);
  ImGui::End();
  ImGui::PopStyleVar();
  ImGui::PopStyleColor();
  ImGui::PopStyleVar(2);

  // The side panels appear while the pointer is at the window's left or right edge (within 1 % of
  // the width) and stay while it is over them.
  const float leftWidth = std::min(330.0f * uiScale, 0.3f * win.x), rightWidth = std::min(380.0f * uiScale, 0.35f * win.x);
  const float edge = std::max(6.0f, 0.01f * win.x);
  const ImVec2 m = presenter.scriptMouse ? *presenter.scriptMouse : io.MousePos;
  const bool valid = presenter.scriptMouse || ImGui::IsMousePosValid(&io.MousePos);
  const bool inside = valid && m.x >= 0 && m.y >= 0 && m.x < win.x && m.y < win.y;
  const bool wasLeft = presenter.leftShown, wasRight = presenter.rightShown;
  presenter.leftShown = inside && (m.x < edge || (presenter.leftShown && m.x < leftWidth));
  presenter.rightShown = inside && (m.x >= win.x - edge || (presenter.rightShown && m.x >= win.x - rightWidth));
  const ImGuiWindowFlags fixed = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse;
  // The edge panels are opaque: over the narrative, a translucent panel mixes two texts.
  ImVec4 panelBg = ImGui::GetStyleColorVec4(ImGuiCol_WindowBg);
  panelBg.w = 1.0f;
  ImGui::PushStyleColor(ImGuiCol_WindowBg, panelBg);
  if (presenter.leftShown) {
    ImGui::SetNextWindowPos(ImVec2(0, 0));
    ImGui::SetNextWindowSize(ImVec2(leftWidth, win.y));
    if (!wasLeft) ImGui::SetNextWindowFocus();  // in front of the presenter's windows
    ImGui::Begin("Technique", nullptr, fixed);
    drawLeftPanel();
    ImGui::End();
  }
  if (presenter.rightShown) {
    ImGui::SetNextWindowPos(ImVec2(win.x - rightWidth, 0));
    ImGui::SetNextWindowSize(ImVec2(rightWidth, win.y));
    if (!wasRight) ImGui::SetNextWindowFocus();
    ImGui::Begin("Details", nullptr, fixed);
    drawRightPanel();
    ImGui::End();
  }
  ImGui::PopStyleColor();
}

// --- Script verbs: presenter mode ---------------------------------------------------------------------

namespace {

int scriptKeyCode(const ScriptCall& call) {
  static const std::pair<const char*, int> kKeys[] = {
      {"right", GLFW_KEY_RIGHT}, {"left", GLFW_KEY_LEFT},           {"pagedown", GLFW_KEY_PAGE_DOWN},
      {"pageup", GLFW_KEY_PAGE_UP}, {"space", GLFW_KEY_SPACE},      {"backspace", GLFW_KEY_BACKSPACE},
      {"home", GLFW_KEY_HOME},   {"end", GLFW_KEY_END},             {"p", GLFW_KEY_P},
      {"f11", GLFW_KEY_F11},     {"escape", GLFW_KEY_ESCAPE}};
  const std::string& name = call.arg(0);
  int key = -1;
  for (const auto& [keyName, code] : kKeys)
    if (name == keyName) key = code;
  if (name.size() == 1 && name[0] >= '0' && name[0] <= '9') key = GLFW_KEY_0 + (name[0] - '0');
  if (key < 0)
    call.badArgument("unknown key '" + name +
                     "'; valid: right, left, pagedown, pageup, space, backspace, home, end, 0..9, p, f11, escape");
  return key;
}

// A press and its release delivered to the window's key callback before the next frame.
void tapKey(Viewer& viewer, const ScriptCall& call) {
  const int key = scriptKeyCode(call);
  Viewer::onKeyEvent(viewer.window->handle(), key, 0, GLFW_PRESS, 0);
  Viewer::onKeyEvent(viewer.window->handle(), key, 0, GLFW_RELEASE, 0);
  viewer.script.waitFrames = 2;
}

void pressKey(Viewer& viewer, const ScriptCall& call) {
  const int key = scriptKeyCode(call);
  const std::string& name = call.arg(0);
  const int before = viewer.lessonStep;
  if (!viewer.presenterKey(key))
    call.fail("key " + name + " does nothing here (presenter mode is " + (viewer.presenter.on ? "on" : "off") +
              (viewer.lesson.steps.empty() ? ", no lesson is open)" : ")"));
  if (viewer.lessonStep != before) {
    const LessonStep& step = viewer.lesson.steps[size_t(viewer.lessonStep)];
    std::printf("key %s: lesson step %d/%zu: %s/%s\n", name.c_str(), viewer.lessonStep + 1, viewer.lesson.steps.size(),
                step.stage.c_str(), step.output.c_str());
  } else {
    std::printf("key %s: presenter mode %s, lesson step %d\n", name.c_str(), viewer.presenter.on ? "on" : "off",
                viewer.lessonStep + 1);
  }
  viewer.script.waitFrames = 2;
}

void expectPresenterView(Viewer& viewer, const ScriptCall& call) {
  const PresenterState& presenter = viewer.presenter;
  if (!presenter.on) call.fail("presenter mode is off (present on)");
  int w, h;
  viewer.window->framebufferSize(w, h);
  const ImVec2 size(presenter.imageMax.x - presenter.imageMin.x, presenter.imageMax.y - presenter.imageMin.y);
  const float fraction = size.x * size.y / float(std::max(w * h, 1));
  std::printf("presenter view: image %.0fx%.0f at (%.0f, %.0f) in a %dx%d window: %.3f of it; narrative at %.1f px, "
              "page %d of %d\n",
              size.x, size.y, presenter.imageMin.x, presenter.imageMin.y, w, h, fraction, presenter.narrativePx,
              presenter.page + 1, presenter.pages);
  if (!(fraction > call.floatArg(0)))
    call.fail("the view's image covers " + std::to_string(fraction) + " of the window, expected more than " + call.arg(0));
}

}  // namespace

VOXLAB_REGISTER_SCRIPT_VERBS(presenter, 90,
  {"present", 1, 1, "present on|off (presenter mode, as --present and the P / F11 keys)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.setPresenting(call.onOff(0));
     viewer.script.waitFrames = 2;  // the UI scale follows the window from the next frame
   }},
  {"key", 1, 1,
   "key NAME (a presenter-mode key, as pressed: right, left, pagedown, pageup, space, backspace, home, end, 0..9, p, "
   "f11, escape)",
   pressKey},
  {"tap", 1, 1,
   "tap NAME (a key pressed and released between two frames, through the window's key callback: what a "
   "presenter remote sends; names as for key)",
   tapKey},
  {"mouse", 2, 2, "mouse X Y (the pointer at window pixel X, Y from the top left, for presenter mode's edge panels)",
   [](Viewer& viewer, const ScriptCall& call) {
     viewer.presenter.scriptMouse = ImVec2(call.floatArg(0), call.floatArg(1));
     viewer.script.waitFrames = 2;  // a revealed panel is drawn from the next frame
   }},
  {"expect-narrative-px", 1, 1,
   "expect-narrative-px MIN (presenter mode set the step's narrative at MIN px or more)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (!viewer.presenter.on) call.fail("presenter mode is off (present on)");
     std::printf("narrative at %.1f px, page %d of %d\n", viewer.presenter.narrativePx, viewer.presenter.page + 1,
                 viewer.presenter.pages);
     if (viewer.presenter.narrativePx < call.floatArg(0))
       call.fail("the narrative is set at " + std::to_string(viewer.presenter.narrativePx) + " px, expected " +
                 call.arg(0) + " or more");
   }},
  {"expect-presenter-view", 1, 1,
   "expect-presenter-view MIN_FRACTION (presenter mode is on and the view's image covers more than MIN_FRACTION of "
   "the window)",
   expectPresenterView});

}  // namespace voxlab
