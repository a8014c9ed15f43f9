#include "app/gui/app.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "app/gui/actions.h"
#include "app/gui/input.h"
#include "app/gui/panels.h"
#include "app/gui/scene.h"

#ifndef QS_ASSETS_DIR
#define QS_ASSETS_DIR "assets"
#endif

namespace qs::app {

namespace {

void glfw_error(int code, const char* message) {
  std::fprintf(stderr, "GLFW error %d: %s\n", code, message);
}

App* app_of(GLFWwindow* window) {
  return static_cast<App*>(glfwGetWindowUserPointer(window));
}

void key_callback(GLFWwindow* window, int key, int, int action, int mods) {
  if (App* app = app_of(window)) app->on_key(key, mods, action);
}

void drop_callback(GLFWwindow* window, int count, const char** paths) {
  if (App* app = app_of(window)) app->on_drop(count, paths);
}

EditorConfig editor_config(const AppOptions& options) {
  EditorConfig config;
  config.assets_dir = QS_ASSETS_DIR;
  config.worker_nice = options.worker_nice;
  return config;
}

}  // namespace

App::App(AppOptions options)
    : options_(std::move(options)), editor_(editor_config(options_)), automation_(options_) {}

App::~App() {
  shutdown();
}

AppContext App::context() {
  return AppContext{editor_, tools_, camera_, picker_, ui_, imgui_ready_ ? &renderer_ : nullptr};
}

void App::on_key(int key, int mods, int action) {
  if (action == GLFW_PRESS || action == GLFW_REPEAT) key_presses_.push_back({key, mods});
}

void App::on_drop(int count, const char** paths) {
  for (int i = 0; i < count; ++i) dropped_files_.emplace_back(paths[i]);
}

bool App::init_window() {
  glfwSetErrorCallback(glfw_error);
  if (!glfwInit()) return false;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SCALE_TO_MONITOR, GLFW_TRUE);  // high-DPI: logical size in points
  glfwWindowHint(GLFW_SAMPLES, options_.msaa_samples < 0 ? 4 : options_.msaa_samples);
  window_ = glfwCreateWindow(options_.width, options_.height, "QuadSketch", nullptr, nullptr);
  if (!window_) {
    glfwWindowHint(GLFW_SAMPLES, 0);  // some software stacks refuse multisampling
    window_ = glfwCreateWindow(options_.width, options_.height, "QuadSketch", nullptr, nullptr);
  }
  if (!window_) return false;
  glfwMakeContextCurrent(window_);
  if (options_.msaa_samples < 0 && render::is_software_renderer(render::current_renderer_name())) {
    // Software rasterizers pay for every sample: start again without multisampling there.
    glfwDestroyWindow(window_);
    glfwWindowHint(GLFW_SAMPLES, 0);
    window_ = glfwCreateWindow(options_.width, options_.height, "QuadSketch", nullptr, nullptr);
    if (!window_) return false;
    glfwMakeContextCurrent(window_);
  }
  // Automation measures frame times: do not wait for vertical sync there.
  glfwSwapInterval(automation_.timed() ? 0 : 1);
  glfwSetWindowUserPointer(window_, this);
  // Installed before ImGui's backend, which chains to them (imgui 1.86).
  glfwSetKeyCallback(window_, key_callback);
  glfwSetDropCallback(window_, drop_callback);
  return true;
}

void App::init_imgui() {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini littering the working directory
  float xscale = 1.0f, yscale = 1.0f;
  glfwGetWindowContentScale(window_, &xscale, &yscale);
  ui_.unicode = setup_style_and_fonts(std::max(1.0f, xscale));
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  imgui_ready_ = true;
}

void App::shutdown() {
  if (imgui_ready_) {
    renderer_.shutdown();  // GL objects die while the context is current
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    imgui_ready_ = false;
  }
  if (window_) {
    glfwDestroyWindow(window_);
    window_ = nullptr;
    glfwTerminate();
  }
}

bool App::frame(const glm::ivec2& framebuffer, float dt) {
  AppContext ctx = context();
  open_dropped(dropped_files_, ctx);
  editor_.poll();
  tools_.sync(editor_);
  if (editor_.doc.mesh && picker_mesh_version_ != editor_.doc.mesh_version) {
    picker_.build(*editor_.doc.mesh);
    picker_mesh_version_ = editor_.doc.mesh_version;
  }
  if (editor_.doc.mesh && camera_mesh_version_ != editor_.doc.mesh_version) {
    // A new mesh (however it was opened): its bounds, the home view (at once for the first
    // one), and its paths in the Files panel.
    fit_camera_to_mesh(ctx, true, camera_mesh_version_ == ~0ull);
    camera_mesh_version_ = editor_.doc.mesh_version;
    ui_.mesh_field = editor_.doc.mesh_path;
    ui_.layout_field = editor_.doc.layout_path;
  }
  int win_w = 0, win_h = 0;
  glfwGetWindowSize(window_, &win_w, &win_h);
  camera_.set_viewport(win_w, win_h);
  camera_.update(std::min(dt, 0.1f));
  automation_.before_frame(ctx);

  renderer_.begin_ui_frame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  if (!automation_.drives_mouse()) tools_.mouse(read_mouse(), editor_, camera_, picker_);
  handle_keys(key_presses_, ctx);
  draw_ui(ctx);
  ImGui::Render();
  renderer_.profile_mark(render::kStageUi);
  const bool rendered =
      renderer_.draw_scene(build_scene(editor_, tools_), camera_, framebuffer, glfwGetTime());
  renderer_.draw_ui();
  renderer_.profile_mark(render::kStageImgui);
  return rendered;
}

int App::run() {
  std::string script_error;
  if (!automation_.load(&script_error)) {
    std::fprintf(stderr, "quadsketch: %s\n", script_error.c_str());
    return 2;
  }
  const bool loaded = editor_.start(options_.mesh_path, options_.layout_path);
  if (!loaded && automation_.quit_on_load_error()) return 2;  // the reasons are printed
  if (!init_window()) {
    std::fprintf(stderr, "quadsketch: cannot create an OpenGL 3.3 window (is DISPLAY set?)\n");
    return 1;
  }
  init_imgui();
  try {
    render::RendererOptions ro;
    ro.show_field = options_.show_field;
    ro.scene_cache = options_.scene_cache;
    ro.motion_resolution = options_.motion_resolution;
    ro.profile = options_.frame_profile;
    renderer_.init(ro);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "quadsketch: %s\n", e.what());
    return 1;
  }
  AppContext ctx = context();
  int fb_w = 0, fb_h = 0;
  auto last = std::chrono::steady_clock::now();
  while (!glfwWindowShouldClose(window_)) {
    glfwPollEvents();
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    if (fb_w == 0 || fb_h == 0) {  // minimized
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    const auto frame_start = std::chrono::steady_clock::now();
    const float dt = std::chrono::duration<float>(frame_start - last).count();
    last = frame_start;
    renderer_.begin_profile_frame(frame_start);
    const glm::ivec2 framebuffer(fb_w, fb_h);
    const bool rendered = frame(framebuffer, dt);
    const bool quit = automation_.after_frame(ctx, framebuffer);
    glfwSwapBuffers(window_);
    if (automation_.timed()) renderer_.finish();  // count the frame's GPU work too
    renderer_.profile_mark(render::kStageSwap);
    renderer_.count_profile_frame();
    automation_.frame_shown(
        ctx,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frame_start)
            .count(),
        rendered);
    if (quit) break;
    // At most ~60 frames/s, also when vertical sync does not throttle (software GL, no vblank)
    // and in benchmarks (the frame time above is the work of one frame): wait for input for
    // the rest of the frame budget, leaving the CPU to the solver.
    constexpr double kFrameBudget = 1.0 / 60.0;
    const double spent =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - frame_start).count();
    if (spent < kFrameBudget) glfwWaitEventsTimeout(kFrameBudget - spent);
  }
  automation_.finish(ctx, glm::ivec2(fb_w, fb_h));
  if (editor_.doc.dirty && options_.script_path.empty() && !options_.quit)
    std::fprintf(stderr, "quadsketch: unsaved edits are in %s\n", autosave_path().c_str());
  shutdown();
  return automation_.exit_code();
}

}  // namespace qs::app
