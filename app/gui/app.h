// The QuadSketch editor: window, main loop, input routing, tools and panels.
// app.cpp: window and loop; input.cpp: camera and sketch tools; panels.cpp: ImGui panels.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/gui/autosave.h"
#include "app/gui/document.h"
#include "app/gui/frame_stats.h"
#include "app/gui/recent_files.h"
#include "core/pipeline/worker.h"
#include "render/background.h"
#include "render/camera.h"
#include "render/field_layer.h"
#include "render/layout_layer.h"
#include "render/mesh_layer.h"
#include "render/picking.h"
#include "render/scene_cache.h"

struct GLFWwindow;

namespace qs::app {

//! Command-line options (interfaces.md §3).
struct AppOptions {
  std::string mesh_path;    //!< "" -> bundled example
  std::string layout_path;  //!< "" -> bundled example layout (with the example mesh only)
  bool run = false;
  std::string screenshot_path;
  int frames = 0;  //!< 0: not given
  bool quit = false;
  //! Frame-time benchmark: render this many frames (after a short warm-up), print mean and
  //! 95th-percentile frame time and fps, then quit. 0: off.
  int bench_frames = 0;
  bool show_field = false;  //!< start with the cross-field glyph layer on
  //! Multisampling of the window; -1: automatic (4, or 0 on a software renderer such as
  //! llvmpipe, where 4x multisampling costs about 4x the frame time).
  int msaa_samples = -1;
  //! Automation: a free-hand stroke through the screen positions of these mesh vertices
  //! (the first must hold a node), applied like a mouse stroke with the stroke tool.
  std::vector<int> stroke_vertices;
  int width = 1280;
  int height = 800;
  //! Automation: orbit the camera a little every frame (the scene re-renders every frame, the
  //! worst case for the frame rate).
  bool bench_orbit = false;
  //! Redraw on demand: reuse the last rendered scene image while nothing it shows changed.
  bool scene_cache = true;
  //! Resolution scale of the scene while the camera moves (software renderers without
  //! multisampling only); 1: always full resolution.
  float motion_resolution = 0.5f;
  //! Nice value (0..19) of the solver threads; 0 leaves their priority alone.
  int worker_nice = 10;
  //! Per-stage frame timings (glFinish between stages), printed at exit.
  bool frame_profile = false;
};

enum class Tool { Select, PlaceNode, DrawArc, Split, Delete, Pin, Stroke, Dangling };
constexpr int kToolCount = 8;

class App {
 public:
  explicit App(AppOptions options);
  ~App();
  //! Runs until the window closes (or --quit). Returns the process exit code.
  int run();

  // GLFW callbacks (static trampolines find the App through the window user pointer).
  void on_key(int key, int mods, int action);
  void on_drop(int count, const char** paths);

 private:
  bool init_window();
  void init_imgui();
  void shutdown();
  bool load_initial_files();
  void frame();
  //! Draws the scene (or the cached image of it) into the window framebuffer. Returns true
  //! when the scene was rendered, false when the cached image was reused.
  bool render_scene(int fb_width, int fb_height);
  //! --frame-profile: waits for the GPU and adds the time since the previous mark to \p stage.
  void profile_mark(int stage);
  void poll_worker();
  //! True when the latest job snapshot (not the editor's layout) should be drawn.
  bool job_layout_shown() const;
  bool automation() const {
    return !options_.screenshot_path.empty() || options_.quit || options_.bench_frames > 0;
  }

  // Files (app.cpp).
  void open_mesh(const std::string& path);
  void open_layout(const std::string& path);
  void after_layout_replaced();
  void save_layout(const std::string& path);
  void report_error(const std::string& message);
  void on_layout_edited(const Layout& layout);

  // Input and tools (input.cpp).
  void handle_mouse();
  void handle_keys();
  void update_hover(const glm::vec2& mouse);
  void click(const glm::vec2& mouse);
  int pick_node(const glm::vec2& mouse, float radius_px) const;
  int pick_arc(const glm::vec2& mouse, float radius_px) const;
  std::optional<render::SurfaceHit> pick_surface(const glm::vec2& mouse) const;
  glm::vec3 vertex_position(int v) const;
  void apply(const EditResult& result, const std::string& done_message);
  void focus_selection();
  void focus_vertices(const std::vector<int>& vertices);
  void reset_view();
  void undo();
  void redo();
  void delete_selection();
  void toggle_pin_selection();
  //! True when pins go to the running/paused job (cmd::SetPin) instead of the editor.
  bool live_pins() const;
  //! Pinned state of \p node in the job as the user sees it (pending commands included).
  bool job_node_pinned(int node) const;
  //! Sends SetPin / ClearPin for \p node to the worker and remembers it until applied.
  void toggle_live_pin(int node);
  void set_tool(Tool tool);
  //! Stroke tool: starts a stroke at \p node, adds a mouse sample, ends it (the arc goes to
  //! the node under \p mouse, or to a new node at the stroke's end).
  void begin_stroke(int node, const glm::vec2& mouse);
  void add_stroke_sample(const glm::vec2& mouse);
  void end_stroke(const glm::vec2& mouse);
  void cancel_stroke();
  //! --stroke-vertices: the same stroke code driven by projected vertex positions.
  void apply_scripted_stroke();
  //! Dangling tool: the boundary vertex a click at the surface point \p hit would end on.
  int dangling_target(const render::SurfaceHit& hit) const;
  //! Sends the panel's pipeline options to the worker (before Run / Step start a job).
  void send_options();

  // Panels (panels.cpp).
  void draw_ui();
  void draw_main_panel();
  void draw_files_section();
  void draw_tools_section();
  void draw_view_section();
  void draw_layout_section();
  void draw_validation_section();
  void draw_pipeline_section();
  void draw_pipeline_options();
  void draw_history_controls();
  void draw_quads_section();
  void draw_metrics_panel();
  void draw_error_panel();
  void draw_autosave_prompt();
  void draw_status_bar();
  void draw_legend();

  AppOptions options_;
  GLFWwindow* window_ = nullptr;
  bool imgui_ready_ = false;

  Document doc_;
  RecentFiles recent_;
  std::unique_ptr<Worker> worker_;
  SnapshotPtr snapshot_;
  std::uint64_t snapshot_version_ = ~0ull;
  std::uint64_t param_version_ = 0;

  render::Camera camera_;
  render::SurfacePicker picker_;
  std::unique_ptr<render::Background> background_;
  std::unique_ptr<render::MeshLayer> mesh_layer_;
  std::unique_ptr<render::LayoutLayer> layout_layer_;
  std::unique_ptr<render::FieldLayer> field_layer_;
  render::SceneCache scene_cache_;
  std::uint64_t last_camera_key_ = 0;
  std::uint64_t picker_mesh_version_ = ~0ull;

  // Interaction state.
  Tool tool_ = Tool::Select;
  int selected_node_ = -1;
  int selected_arc_ = -1;
  int hovered_node_ = -1;
  int hovered_arc_ = -1;
  int hovered_vertex_ = -1;
  int arc_start_node_ = -1;
  std::vector<int> preview_path_;
  int preview_target_vertex_ = -1;
  std::uint64_t interaction_version_ = 0;
  enum class Drag { None, Pending, Orbit, Pan, MoveNode, Stroke } drag_ = Drag::None;
  // Free-hand stroke in progress: start node, samples on the surface, their 3D points.
  int stroke_node_ = -1;
  std::vector<SurfacePoint> stroke_samples_;
  std::vector<glm::vec3> stroke_points_;
  glm::vec2 stroke_last_mouse_{-1.0f};
  glm::vec2 press_pos_{0.0f};
  glm::vec2 last_mouse_{-1.0f};
  int press_node_ = -1;
  std::vector<std::pair<int, int>> key_events_;  // (key, mods) presses
  std::vector<std::string> dropped_files_;

  // UI state.
  std::string mesh_field_;
  std::string layout_field_;
  std::string save_field_;
  std::vector<std::string> errors_;
  std::string status_;
  std::optional<AutosaveOffer> autosave_offer_;
  std::string autosave_error_;
  int highlighted_issue_ = -1;
  bool show_demo_ = false;
  std::string shader_log_;
  WorkerOptions worker_options_;
  //! Scrubbed step (index into Snapshot::node_history); follows the latest step when live.
  int history_step_ = -1;
  bool history_live_ = true;
  //! Pins sent to the worker and not yet reflected in a snapshot (drawn optimistically).
  struct PendingPin {
    int node = -1;
    bool pinned = false;
    std::uint64_t seq = 0;
  };
  std::vector<PendingPin> pending_pins_;
  std::string export_dir_;
  std::string export_message_;
  bool export_failed_ = false;
  //! Bounding-box diagonal of the mesh (quad size slider range), cached per mesh version.
  float mesh_diagonal_ = 1.0f;
  std::uint64_t mesh_diagonal_version_ = ~0ull;

  // Automation and timing.
  int frame_count_ = 0;
  std::chrono::steady_clock::time_point start_time_;
  std::chrono::steady_clock::time_point first_frame_;
  bool run_requested_ = false;
  int frames_since_run_done_ = -1;
  int exit_code_ = 0;
  bool quit_now_ = false;
  FrameStats frame_stats_;
  // --frame-profile: milliseconds per stage summed over the profiled frames.
  static constexpr int kProfileStages = 9;
  double profile_ms_[kProfileStages] = {};
  int profile_frames_ = 0;
  std::chrono::steady_clock::time_point profile_last_;
};

}  // namespace qs::app
