// GL log tab: every distinct GL debug message of the session (gpu/gl_debug.h: the KHR_debug
// callback every context installs), newest last, with its severity, how often it arrived and the
// stage or object it happened in. Failures (high and medium, what fails a test) are counted in
// the tab's label and drawn in the error colour.
#include <cstdio>

#include "gpu/gl_debug.h"
#include "inspect/script_verbs.h"
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

// --- Script verbs: the GL debug output ----------------------------------------------------------------

VOXLAB_REGISTER_SCRIPT_VERBS(gl_log, 110,
  {"gl-debug-message", 1, 32,
   "gl-debug-message TEXT... (insert an application message, severity low, into the GL debug output: the GL log tab "
   "shows it)",
   // Severity low: logged, not a failure, as a GL tool or a driver would send one.
   [](Viewer&, const ScriptCall& call) {
     glDebugMessageInsert(GL_DEBUG_SOURCE_APPLICATION, GL_DEBUG_TYPE_OTHER, 1, GL_DEBUG_SEVERITY_LOW, -1,
                          call.text().c_str());
   }},
  {"expect-gl-log", 1, 32, "expect-gl-log TEXT... (a message in the GL debug log contains TEXT)",
   [](Viewer&, const ScriptCall& call) {
     const std::string text = call.text();
     const auto log = glDebugLog();
     const GLDebugLogEntry* found = nullptr;
     for (const auto& e : log)
       if (e.message.describe().find(text) != std::string::npos) found = &e;
     if (!found) call.fail("no GL debug message contains '" + text + "' (" + std::to_string(log.size()) + " in the log)");
     std::printf("gl log: x%d %s\n", found->count, found->message.describe().c_str());
   }},
  {"expect-no-gl-failures", 0, 0,
   "expect-no-gl-failures (no GL message of severity high or medium since the script started)",
   [](Viewer& viewer, const ScriptCall& call) {
     if (glFailureCount() == viewer.script.glFailuresAtStart) return;
     std::string last;
     for (const auto& e : glDebugLog())
       if (isGLFailure(e.message)) last = e.message.describe();
     call.fail(std::to_string(glFailureCount() - viewer.script.glFailuresAtStart) +
               " GL failure(s) since the script started; last: " + last);
   }});

}  // namespace voxlab
