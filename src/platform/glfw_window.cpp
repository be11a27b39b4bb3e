#include "platform/glfw_window.h"

#include "core/error.h"
#include "gpu/gl.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

namespace voxlab {
namespace {

std::string lastGlfwError;

void onGlfwError(int code, const char* text) { lastGlfwError = text ? text : "unknown GLFW error"; }

void* glfwProc(const char* name) { return reinterpret_cast<void*>(glfwGetProcAddress(name)); }

}  // namespace

GlfwWindow::GlfwWindow(int width, int height, const std::string& title) {
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit())
    throw Error("cannot open a window: " + lastGlfwError + " (no display? run under xvfb-run -a)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_DOUBLEBUFFER, GLFW_TRUE);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    glfwTerminate();
    throw Error("cannot create a GL 4.5 core window: " + lastGlfwError);
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(0);  // the viewer paces itself; vsync would hide frame-time measurements
  try {
    loadGL(&glfwProc);
  } catch (...) {
    glfwDestroyWindow(window_);
    glfwTerminate();
    throw;
  }
}

GlfwWindow::~GlfwWindow() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

void GlfwWindow::makeCurrent() { glfwMakeContextCurrent(window_); }
bool GlfwWindow::shouldClose() const { return glfwWindowShouldClose(window_); }
void GlfwWindow::requestClose() { glfwSetWindowShouldClose(window_, GLFW_TRUE); }
void GlfwWindow::swapBuffers() { glfwSwapBuffers(window_); }
void GlfwWindow::pollEvents() { glfwPollEvents(); }
void GlfwWindow::framebufferSize(int& width, int& height) const { glfwGetFramebufferSize(window_, &width, &height); }

}  // namespace voxlab
