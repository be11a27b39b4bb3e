// GL log tab: every distinct GL debug message of the session (gpu/gl_debug.h: the KHR_debug
// callback every context installs), newest last, with its severity, how often it arrived and the
// stage or object it happened in. Failures (high and medium, what fails a test) are counted in
// the tab's label and drawn in the error colour.
#include <cstdio>

#include "gpu/gl_debug.h"
#include "inspect/viewer_state.h"

namespace voxlab {

namespace {

bool failuresOnly = false;

void drawGLLog(Viewer&) {
  const std::vector<GLDebugLogEntry> log = glDebugLog();
  size_t failures = 0;
  for (const auto& e : log) failures += isGLFailure(e.message);
  ImGui::Text("%zu distinct GL debug messages, %zu of them failures (high or medium)", log.size(), failures);
  ImGui::Checkbox("failures only", &failuresOnly);
  ImGui::Separator();
  if (log.empty()) {
    ImGui::TextDisabled("no GL debug messages (the context's KHR_debug output is on)");
    return;
  }
  ImGui::BeginChild("gl-log", ImVec2(0, 0), false, ImGuiWindowFlags_HorizontalScrollbar);
  for (const auto& e : log) {
    const bool failure = isGLFailure(e.message);
    if (failuresOnly && !failure) continue;
    const ImVec4 colour = failure ? kErrorColour : e.message.severity == GL_DEBUG_SEVERITY_LOW
                                                       ? kWarningColour
                                                       : ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled);
    ImGui::PushStyleColor(ImGuiCol_Text, colour);
    ImGui::TextWrapped("[%s] x%d %s", glDebugSeverityName(e.message.severity), e.count, e.message.describe().c_str());
    ImGui::PopStyleColor();
  }
  ImGui::SetScrollHereY(1.0f);  // keep the newest in sight
  ImGui::EndChild();
}

}  // namespace

VOXLAB_REGISTER_DETAILS_TAB(gl_log, "gl-log", "GL log", 60, nullptr, [](Viewer& v) { drawGLLog(v); });

}  // namespace voxlab
