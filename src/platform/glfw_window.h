// GlfwWindow: a visible window with a GL 4.5 core context, for the viewer.
//
// The renderer never draws into the window's framebuffer: stages draw into their own FBOs and the
// viewer only presents (ImGui plus textures). Creating the window makes its context current and
// loads the GL entry points with glad (loadGL).
#pragma once
#include <string>

#include "platform/gl_context.h"

struct GLFWwindow;

namespace voxlab {

class GlfwWindow final : public GLContext {
 public:
  // Throws Error when GLFW cannot start (no display) or the context is not GL 4.5 core.
  GlfwWindow(int width, int height, const std::string& title);
  ~GlfwWindow() override;
  GlfwWindow(const GlfwWindow&) = delete;
  GlfwWindow& operator=(const GlfwWindow&) = delete;

  void makeCurrent() override;
  const char* kind() const override { return "glfw"; }

  GLFWwindow* handle() const { return window_; }
  bool shouldClose() const;
  void requestClose();
  void swapBuffers();
  void pollEvents();
  void framebufferSize(int& width, int& height) const;

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace voxlab
