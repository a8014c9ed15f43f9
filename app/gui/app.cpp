#include "app/gui/app.h"

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#endif
#include <GL/glcorearb.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include "app/gui/history.h"
#include "app/gui/pipeline_job.h"
#include "app/gui/screenshot.h"
#include "app/gui/thread_priority.h"
#include "core/base/solver_threads.h"

#ifndef QS_ASSETS_DIR
#define QS_ASSETS_DIR "assets"
#endif

namespace qs::app {

namespace fs = std::filesystem;

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

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

// A calm, neutral theme: dark translucent panels over the grey viewport, blue accents.
void apply_style(float scale) {
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 6.0f;
  style.FrameRounding = 4.0f;
  style.GrabRounding = 4.0f;
  style.ScrollbarRounding = 6.0f;
  style.WindowBorderSize = 0.0f;
  style.FramePadding = ImVec2(6.0f, 4.0f);
  style.ItemSpacing = ImVec2(8.0f, 6.0f);
  style.WindowPadding = ImVec2(10.0f, 10.0f);
  ImVec4* c = style.Colors;
  c[ImGuiCol_WindowBg] = ImVec4(0.11f, 0.12f, 0.14f, 0.94f);
  c[ImGuiCol_TitleBg] = ImVec4(0.13f, 0.15f, 0.18f, 1.0f);
  c[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.22f, 0.30f, 1.0f);
  c[ImGuiCol_Header] = ImVec4(0.20f, 0.27f, 0.36f, 0.80f);
  c[ImGuiCol_HeaderHovered] = ImVec4(0.26f, 0.36f, 0.50f, 0.90f);
  c[ImGuiCol_HeaderActive] = ImVec4(0.30f, 0.42f, 0.58f, 1.00f);
  c[ImGuiCol_FrameBg] = ImVec4(0.18f, 0.20f, 0.23f, 1.0f);
  c[ImGuiCol_Button] = ImVec4(0.22f, 0.30f, 0.40f, 1.0f);
  c[ImGuiCol_ButtonHovered] = ImVec4(0.28f, 0.40f, 0.55f, 1.0f);
  c[ImGuiCol_ButtonActive] = ImVec4(0.32f, 0.46f, 0.64f, 1.0f);
  style.ScaleAllSizes(scale);
}

}  // namespace

App::App(AppOptions options) : options_(std::move(options)) {
  // The solver threads run below the UI's priority (lowered at the first step of every job, so
  // that the math libraries' thread pools, created on first use, are caught too).
  worker_ = std::make_unique<Worker>(
      [nice = options_.worker_nice](WorkerState& state, const WorkerObserver& observer) {
        if (state.iteration == 0) lower_solver_thread_priority(nice);
        limit_solver_threads_here();  // CHOLMOD's OpenMP regions: at most the idle cores
        return pipeline_step(state, observer);
      });
  doc_.editor.on_change = [this](const Layout& layout) { on_layout_edited(layout); };
  recent_.load();
}

App::~App() {
  shutdown();
}

void App::on_key(int key, int mods, int action) {
  if (action == GLFW_PRESS || action == GLFW_REPEAT) key_events_.push_back({key, mods});
}

void App::on_drop(int count, const char** paths) {
  for (int i = 0; i < count; ++i) dropped_files_.emplace_back(paths[i]);
}

void App::report_error(const std::string& message) {
  errors_.push_back(message);
  std::fprintf(stderr, "quadsketch: %s\n", message.c_str());
}

bool App::load_initial_files() {
  std::string mesh = options_.mesh_path;
  std::string layout = options_.layout_path;
  if (mesh.empty()) {
    // The bundled example: the default scene when nothing is given.
    const fs::path example = fs::path(QS_ASSETS_DIR) / "example";
    mesh = (example / "ellipsoid.obj").string();
    if (layout.empty()) layout = (example / "ellipsoid.layout.json").string();
    std::error_code ec;
    if (!fs::exists(mesh, ec)) {
      report_error("The bundled example is missing (" + mesh +
                   "). Open a mesh with the Files panel or drop one onto the window.");
      return false;
    }
  }
  bool ok = true;
  if (std::string error = doc_.open_mesh(mesh); !error.empty()) {
    report_error(error);
    ok = false;
  } else {
    recent_.add_mesh(mesh);
    mesh_field_ = mesh;
    if (!layout.empty()) {
      if (std::string error = doc_.open_layout(layout); !error.empty()) {
        report_error(error);
        ok = false;
      } else {
        recent_.add_layout(layout);
      }
    }
  }
  layout_field_ = layout;
  save_field_ = doc_.layout_path;
  recent_.save();
  if (doc_.mesh) {
    worker_->send(cmd::LoadMesh{doc_.mesh, doc_.editor.layout()});
    if (!automation()) autosave_offer_ = find_autosave(doc_.mesh_path, doc_.layout_path);
  }
  return ok;
}

void App::open_mesh(const std::string& path) {
  if (std::string error = doc_.open_mesh(path); !error.empty()) {
    report_error(error);
    return;
  }
  recent_.add_mesh(path);
  recent_.save();
  mesh_field_ = path;
  save_field_.clear();
  after_layout_replaced();
  reset_view();
  status_ = "Opened " + path;
  autosave_offer_ = find_autosave(doc_.mesh_path, doc_.layout_path);
}

void App::open_layout(const std::string& path) {
  if (std::string error = doc_.open_layout(path); !error.empty()) {
    report_error(error);
    return;
  }
  recent_.add_layout(path);
  recent_.save();
  layout_field_ = path;
  save_field_ = path;
  after_layout_replaced();
  status_ = "Opened " + path;
  autosave_offer_ = find_autosave(doc_.mesh_path, doc_.layout_path);
}

void App::after_layout_replaced() {
  selected_node_ = selected_arc_ = hovered_node_ = hovered_arc_ = arc_start_node_ = -1;
  preview_path_.clear();
  highlighted_issue_ = -1;
  ++interaction_version_;
  if (doc_.mesh) worker_->send(cmd::LoadMesh{doc_.mesh, doc_.editor.layout()});
}

void App::save_layout(const std::string& path) {
  if (std::string error = doc_.save_layout_to(path); !error.empty()) {
    report_error(error);
    return;
  }
  recent_.add_layout(doc_.layout_path);
  recent_.save();
  save_field_ = doc_.layout_path;
  status_ = "Saved " + doc_.layout_path;
}

void App::on_layout_edited(const Layout& layout) {
  doc_.dirty = true;
  ++interaction_version_;
  // Autosave after every committed edit; failures are shown but never stop editing.
  try {
    write_autosave(layout, doc_.mesh.get(), doc_.mesh_path, doc_.layout_path);
    autosave_error_.clear();
  } catch (const std::exception& e) {
    autosave_error_ = e.what();
  }
  autosave_offer_.reset();  // the current session supersedes an older autosave
  worker_->send(cmd::SetLayout{layout});
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
  if (options_.msaa_samples < 0) {
    // Software rasterizers pay for every sample: start again without multisampling there.
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    const std::string name = renderer ? renderer : "";
    if (name.find("llvmpipe") != std::string::npos || name.find("softpipe") != std::string::npos ||
        name.find("swrast") != std::string::npos) {
      glfwDestroyWindow(window_);
      glfwWindowHint(GLFW_SAMPLES, 0);
      window_ = glfwCreateWindow(options_.width, options_.height, "QuadSketch", nullptr, nullptr);
      if (!window_) return false;
      glfwMakeContextCurrent(window_);
    }
  }
  // Automation measures frame times: do not wait for vertical sync there.
  glfwSwapInterval(options_.frames > 0 || options_.bench_frames > 0 ? 0 : 1);
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
  const float scale = std::max(1.0f, xscale);
  apply_style(scale);
  const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  std::error_code ec;
  if (fs::exists(font, ec)) {
    io.Fonts->AddFontFromFileTTF(font, 15.0f * scale);
  } else {
    ImFontConfig config;
    config.SizePixels = 13.0f * scale;
    io.Fonts->AddFontDefault(&config);
  }
  ImGui_ImplGlfw_InitForOpenGL(window_, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");
  imgui_ready_ = true;
}

void App::shutdown() {
  worker_.reset();  // joins the worker before anything it might reference goes away
  if (imgui_ready_) {
    // GL objects must die while the context is current.
    mesh_layer_.reset();
    layout_layer_.reset();
    field_layer_.reset();
    background_.reset();
    scene_cache_.release();
    ImGui_ImplOpenGL3_Shutdown();
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

bool App::job_layout_shown() const {
  return snapshot_ && snapshot_->mesh == doc_.mesh && snapshot_->iteration > 0 &&
         snapshot_->layout && snapshot_->status != WorkerStatus::Failed &&
         snapshot_->status != WorkerStatus::Idle;
}

void App::send_options() {
  worker_->send(cmd::SetOptions{worker_options_});
}

void App::poll_worker() {
  // Copy the pointer under the worker's lock; use the immutable snapshot lock-free after.
  SnapshotPtr latest = worker_->latest();
  if (latest->version == snapshot_version_) return;
  snapshot_version_ = latest->version;
  const bool param_changed = !snapshot_ ||
                             snapshot_->corner_uv.size() != latest->corner_uv.size() ||
                             snapshot_->face_foldover != latest->face_foldover ||
                             snapshot_->iteration != latest->iteration;
  snapshot_ = std::move(latest);
  if (param_changed) ++param_version_;
  // Pins the worker has now applied (or that a new job superseded) are no longer pending.
  std::erase_if(pending_pins_,
                [&](const PendingPin& p) { return p.seq <= snapshot_->applied_seq; });
  history_step_ = scrub_index(history_step_, int(snapshot_->node_history.size()), history_live_);
}

int App::run() {
  start_time_ = std::chrono::steady_clock::now();
  const bool loaded = load_initial_files();
  if (!loaded && options_.quit) return 2;  // report_error already printed the reasons
  if (!init_window()) {
    std::cerr << "quadsketch: cannot create an OpenGL 3.3 window (is DISPLAY set?)\n";
    return 1;
  }
  init_imgui();
  try {
    background_ = std::make_unique<render::Background>();
    background_->init();
    mesh_layer_ = std::make_unique<render::MeshLayer>();
    layout_layer_ = std::make_unique<render::LayoutLayer>();
    field_layer_ = std::make_unique<render::FieldLayer>();
    field_layer_->visible = options_.show_field;
  } catch (const std::exception& e) {
    std::cerr << "quadsketch: " << e.what() << "\n";
    return 1;
  }
  int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
  glfwGetWindowSize(window_, &win_w, &win_h);
  camera_.set_viewport(win_w, win_h);
  reset_view();
  camera_.reset(true);
  // With a scripted stroke the run starts after the stroke (frame 2), so it runs on the edit.
  const bool scripted_stroke = !options_.stroke_vertices.empty();
  if (options_.run && !scripted_stroke) {
    send_options();
    worker_->send(cmd::Run{});
    run_requested_ = true;
  }
  scene_cache_.set_enabled(options_.scene_cache);
  // Benchmark: a few warm-up frames (shader compilation, first uploads), then N timed frames.
  constexpr int kBenchWarmup = 10;
  const int bench_total = options_.bench_frames > 0 ? kBenchWarmup + options_.bench_frames : 0;
  // Automation measures whole frames: wait for the GPU (llvmpipe renders on the CPU).
  const bool timed = bench_total > 0 || options_.frames > 0;
  std::uint64_t bench_start_version = 0;
  int bench_start_iteration = 0;
  auto bench_start_time = std::chrono::steady_clock::now();

  auto last = std::chrono::steady_clock::now();
  while (!glfwWindowShouldClose(window_) && !quit_now_) {
    glfwPollEvents();
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    if (fb_w == 0 || fb_h == 0) {  // minimized
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      continue;
    }
    const auto frame_start = std::chrono::steady_clock::now();
    const float dt = std::chrono::duration<float>(frame_start - last).count();
    last = frame_start;
    camera_.update(std::min(dt, 0.1f));
    if (options_.bench_orbit) {
      // A small trackball drag every frame: the worst case, the scene re-renders each frame.
      const glm::vec2 centre = 0.5f * camera_.viewport();
      camera_.begin_orbit(centre);
      camera_.orbit_to(centre + glm::vec2(3.0f, 1.0f));
    }

    profile_last_ = frame_start;
    frame();
    profile_mark(0);
    const bool scene_rendered = render_scene(fb_w, fb_h);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    profile_mark(7);
    ++frame_count_;
    if (scripted_stroke && frame_count_ == 2) {
      apply_scripted_stroke();
      if (options_.run) {
        send_options();
        worker_->send(cmd::Run{});
        run_requested_ = true;
      }
    }

    // Automation: decide whether this frame is the one to save / the last one.
    if (run_requested_ && frames_since_run_done_ < 0 && snapshot_ &&
        (snapshot_->status == WorkerStatus::Finished || snapshot_->status == WorkerStatus::Failed ||
         snapshot_->status == WorkerStatus::Cancelled))
      frames_since_run_done_ = 0;
    else if (frames_since_run_done_ >= 0)
      ++frames_since_run_done_;
    bool due = false;
    if (bench_total > 0) {
      due = frame_count_ >= bench_total;
    } else if (options_.frames > 0) {
      due = frame_count_ >= options_.frames;
    } else if (options_.run) {
      // Two more frames so that the final snapshot is uploaded and drawn.
      const double waited = std::chrono::duration<double>(frame_start - start_time_).count();
      due = frames_since_run_done_ >= 2 || waited > 600.0;
    } else {
      due = frame_count_ >= 3;
    }
    if (due && !options_.screenshot_path.empty()) {
      std::string error;
      if (!save_framebuffer_png(options_.screenshot_path, fb_w, fb_h, &error)) {
        std::cerr << "quadsketch: screenshot failed: " << error << "\n";
        exit_code_ = 1;
      }
      options_.screenshot_path.clear();  // once
    }
    glfwSwapBuffers(window_);
    if (timed) glFinish();  // count the frame's GPU work too (llvmpipe renders on the CPU)
    profile_mark(8);
    if (options_.frame_profile) ++profile_frames_;
    frame_stats_.add_frame(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frame_start)
            .count(),
        scene_rendered, snapshot_version_, worker_->version());
    if (bench_total > 0 && frame_count_ == kBenchWarmup) {
      frame_stats_.clear_times();  // the timed frames start now
      bench_start_version = worker_->version();
      bench_start_time = std::chrono::steady_clock::now();
      bench_start_iteration = snapshot_ ? snapshot_->iteration : 0;
      if (options_.frame_profile) {
        std::fill(std::begin(profile_ms_), std::end(profile_ms_), 0.0);
        profile_frames_ = 0;
      }
    }
    if (due && (options_.quit || bench_total > 0)) break;
    {
      // At most ~60 frames/s, also when vertical sync does not throttle (software GL, no
      // vblank) and in benchmarks (the frame time above is the work of one frame): wait for
      // input for the rest of the frame budget, leaving the CPU to the solver.
      constexpr double kFrameBudget = 1.0 / 60.0;
      const double spent =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - frame_start).count();
      if (spent < kFrameBudget) glfwWaitEventsTimeout(kFrameBudget - spent);
    }
  }
  const FrameSummary stats = frame_stats_.summary();
  if (bench_total > 0 && stats.frames > 0) {
    const double bench_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - bench_start_time).count();
    const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    std::printf(
        "bench: %d frames at %dx%d, mesh %zu faces, %zu nodes, %zu arcs; frame time mean %.2f "
        "ms, p95 %.2f ms, max %.2f ms; %.1f fps (mean); %.1f frames/s presented (paced at "
        "60); scene rendered in %d frames; %llu new "
        "snapshots published, %d drawn, max lag %d frame(s); job: %s, steps %d -> %d; camera "
        "%s; field glyphs %s; %d MSAA samples; scene cache %s; motion resolution %.2f; worker nice "
        "%d; renderer: "
        "%s\n",
        stats.frames, fb_w, fb_h, doc_.mesh ? std::size_t(doc_.mesh->n_faces()) : std::size_t(0),
        doc_.editor.layout().nodes.size(), doc_.editor.layout().arcs.size(), stats.mean_ms,
        stats.p95_ms, stats.max_ms, stats.fps,
        bench_seconds > 0.0 ? double(stats.frames) / bench_seconds : 0.0, stats.scene_renders,
        static_cast<unsigned long long>(worker_->version() - bench_start_version),
        stats.snapshots_drawn, stats.max_snapshot_lag,
        snapshot_ ? to_string(snapshot_->status) : "none", bench_start_iteration,
        snapshot_ ? snapshot_->iteration : 0, options_.bench_orbit ? "orbiting" : "still",
        field_layer_ && field_layer_->visible ? "on" : "off", scene_cache_.samples(),
        scene_cache_.enabled() ? "on" : "off", options_.motion_resolution, options_.worker_nice,
        renderer ? renderer : "?");
  }
  if (options_.frames > 0 && stats.frames > 0)
    std::printf("%s\n", format_frame_summary(stats).c_str());
  if (options_.frame_profile && profile_frames_ > 0) {
    static const char* kStageNames[kProfileStages] = {"events+ui", "upload", "clear+background",
                                                      "surface",   "field",  "layout",
                                                      "blit",      "imgui",  "swap"};
    std::printf("frame profile (ms per frame, glFinish between stages, %d frames):",
                profile_frames_);
    for (int i = 0; i < kProfileStages; ++i)
      std::printf(" %s %.2f%s", kStageNames[i], profile_ms_[i] / profile_frames_,
                  i + 1 < kProfileStages ? ";" : "\n");
  }
  if (doc_.dirty && !automation())
    std::fprintf(stderr, "quadsketch: unsaved edits are in %s\n", autosave_path().c_str());
  shutdown();
  return exit_code_;
}

void App::frame() {
  // Dropped files: meshes first so that a mesh + layout dropped together both apply.
  if (!dropped_files_.empty()) {
    std::vector<std::string> files;
    files.swap(dropped_files_);
    std::stable_partition(files.begin(), files.end(),
                          [](const std::string& f) { return lower_extension(f) != ".json"; });
    for (const auto& f : files) {
      const std::string ext = lower_extension(f);
      if (ext == ".obj" || ext == ".off" || ext == ".ply" || ext == ".stl")
        open_mesh(f);
      else if (ext == ".json")
        open_layout(f);
      else
        report_error("Cannot open " + f +
                     ": expected a mesh (.obj .off .ply .stl) or a layout (.json)");
    }
  }
  poll_worker();
  if (!doc_.editor.dragging()) doc_.refresh_validation();
  if (doc_.mesh && picker_mesh_version_ != doc_.mesh_version) {
    picker_.build(*doc_.mesh);
    picker_mesh_version_ = doc_.mesh_version;
  }

  int win_w = 0, win_h = 0;
  glfwGetWindowSize(window_, &win_w, &win_h);
  camera_.set_viewport(win_w, win_h);

  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  handle_mouse();
  handle_keys();
  draw_ui();
  ImGui::Render();
}

void App::profile_mark(int stage) {
  if (!options_.frame_profile) return;
  glFinish();
  const auto now = std::chrono::steady_clock::now();
  profile_ms_[stage] += std::chrono::duration<double, std::milli>(now - profile_last_).count();
  profile_last_ = now;
}

bool App::render_scene(int fb_width, int fb_height) {
  render::SceneData scene;
  scene.mesh = doc_.mesh.get();
  scene.mesh_version = doc_.mesh_version;
  scene.layout = &doc_.editor.layout();
  scene.layout_version = doc_.editor.version();
  if (job_layout_shown()) {
    // While a job's result is current, show its layout: traced iso-lines, moved nodes.
    scene.layout = snapshot_->layout.get();
    scene.layout_version = (std::uint64_t(1) << 62) + snapshot_->version;
  }
  // The parameterization belongs to the mesh the worker used; ignore stale snapshots.
  if (snapshot_ && snapshot_->mesh == doc_.mesh) {
    scene.corner_uv = &snapshot_->corner_uv;
    scene.face_foldover = &snapshot_->face_foldover;
  }
  scene.param_version = param_version_ * 2 + (scene.corner_uv ? 1 : 0);
  for (const auto& issue : doc_.validation.issues) {
    if (issue.severity != IssueSeverity::Error) continue;
    scene.issue_vertices.insert(scene.issue_vertices.end(), issue.vertices.begin(),
                                issue.vertices.end());
    scene.issue_nodes.insert(scene.issue_nodes.end(), issue.node_ids.begin(), issue.node_ids.end());
    scene.issue_arcs.insert(scene.issue_arcs.end(), issue.arc_ids.begin(), issue.arc_ids.end());
  }
  scene.issues_version = doc_.validated_layout_version;
  scene.selected_node = selected_node_;
  scene.selected_arc = selected_arc_;
  scene.hovered_node = hovered_node_;
  scene.hovered_arc = hovered_arc_;
  scene.arc_start_node = arc_start_node_;
  scene.preview_path = preview_path_;
  for (const auto& p : pending_pins_) scene.pin_overrides.emplace_back(p.node, p.pinned);
  scene.interaction_version = interaction_version_;
  if (job_layout_shown()) {
    scene.node_history = &snapshot_->node_history;
    scene.history_step = history_step_;
    scene.history_version = snapshot_->version;
    scene.quads = snapshot_->quads.get();
    scene.quads_version = snapshot_->version;
  }

  render::FrameContext frame;
  frame.camera = &camera_;
  frame.framebuffer = {fb_width, fb_height};
  frame.pixel_ratio = float(fb_width) / std::max(1.0f, camera_.viewport().x);
  frame.time_s = glfwGetTime();
  scene.stroke_points = stroke_points_;
  if (snapshot_ && snapshot_->mesh == doc_.mesh && snapshot_->field) {
    scene.field = snapshot_->field.get();
    scene.field_version = snapshot_->version;
  }
  render::Layer* const layers[] = {mesh_layer_.get(), field_layer_.get(), layout_layer_.get()};
  // Uploads happen only when a version changed (a new snapshot, an edit).
  for (render::Layer* layer : layers) layer->upload(scene);
  profile_mark(1);

  // Everything the scene image depends on; an unchanged key reuses the cached image.
  render::FrameKey key;
  key.add(camera_.view());
  key.add(camera_.projection());
  key.add(frame.framebuffer);
  key.add(frame.pixel_ratio);
  key.add(background_->top);
  key.add(background_->bottom);
  render::add_scene(key, scene);
  for (render::Layer* layer : layers) {
    key.add(layer->settings_key());
    if (layer->visible && layer->animating()) key.add(frame.time_s);
  }
  // While the camera moves, a cheaper image at a fraction of the resolution; the first still
  // frame renders at full resolution again.
  render::FrameKey camera_key;
  camera_key.add(camera_.view());
  camera_key.add(camera_.projection());
  camera_key.add(frame.framebuffer);
  const bool moving = camera_key.value() != last_camera_key_;
  last_camera_key_ = camera_key.value();
  // A full-resolution moving frame is drawn straight into the window: the next frame needs a
  // new image anyway, so caching it would only add a copy.
  const bool direct = moving && options_.motion_resolution >= 1.0f;
  bool draw_scene = true;
  if (direct)
    scene_cache_.invalidate();
  else
    draw_scene = scene_cache_.begin(fb_width, fb_height, key.value(),
                                    moving ? options_.motion_resolution : 1.0f);
  if (draw_scene) {
    if (!direct) {
      frame.framebuffer = {scene_cache_.render_width(), scene_cache_.render_height()};
      frame.pixel_ratio *= float(frame.framebuffer.x) / float(std::max(1, fb_width));
    }
    glViewport(0, 0, frame.framebuffer.x, frame.framebuffer.y);
    // Clear only the part drawn (a reduced-resolution image uses a corner of the buffer).
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, frame.framebuffer.x, frame.framebuffer.y);
    glClearColor(0.3f, 0.31f, 0.33f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glEnable(GL_MULTISAMPLE);
    background_->draw();
    profile_mark(2);
    for (int i = 0; i < 3; ++i) {
      layers[i]->draw(frame);
      profile_mark(3 + i);
    }
    if (!direct) scene_cache_.end();
  }
  glViewport(0, 0, fb_width, fb_height);
  if (!direct) scene_cache_.present();
  profile_mark(6);
  return draw_scene;
}

}  // namespace qs::app
