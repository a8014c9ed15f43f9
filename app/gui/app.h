// The QuadSketch editor's window and main loop: it owns the parts and passes each frame
// through them. The state is the Editor (editor.h, GL-free), the mouse tools are Tools
// (tools.h), drawing is the render::Renderer (every GL call), the panels are panel_*.cpp, and
// the flags for tests and benchmarks are Automation (automation.h).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "app/gui/app_options.h"
#include "app/gui/automation.h"
#include "app/gui/context.h"
#include "app/gui/editor.h"
#include "app/gui/tools.h"
#include "render/camera.h"
#include "render/picking.h"
#include "render/renderer.h"

struct GLFWwindow;

namespace qs::app {

class App {
 public:
  explicit App(AppOptions options);
  ~App();
  App(const App&) = delete;
  App& operator=(const App&) = delete;
  //! Runs until the window closes (or automation ends it). Returns the process exit code.
  int run();

  // GLFW callbacks (static trampolines find the App through the window user pointer).
  void on_key(int key, int mods, int action);
  void on_drop(int count, const char** paths);

 private:
  bool init_window();
  void init_imgui();
  void shutdown();
  //! One frame: input, worker snapshot, panels; returns whether the scene was rendered.
  bool frame(const glm::ivec2& framebuffer, float dt);
  AppContext context();

  AppOptions options_;
  GLFWwindow* window_ = nullptr;
  bool imgui_ready_ = false;
  Editor editor_;
  Tools tools_;
  render::Camera camera_;
  render::SurfacePicker picker_;
  std::uint64_t picker_mesh_version_ = ~0ull;
  std::uint64_t camera_mesh_version_ = ~0ull;
  render::Renderer renderer_;
  UiState ui_;
  Automation automation_;
  std::vector<std::pair<int, int>> key_presses_;  //!< (key, mods)
  std::vector<std::string> dropped_files_;
};

}  // namespace qs::app
