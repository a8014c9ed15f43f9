#include "app/gui/automation.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>  // key modifier bits only

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>

#include "app/gui/actions.h"
#include "app/gui/state_dump.h"

namespace qs::app {

namespace {

const std::set<std::string>& command_names() {
  static const std::set<std::string> names = {"frames",
                                              "wait_guides",
                                              "symmetry",
                                              "field_hints",
                                              "hint_scale",
                                              "wireframe",
                                              "wait_step",
                                              "wait_finished",
                                              "wait_camera",
                                              "wait_status",
                                              "run",
                                              "step",
                                              "pause",
                                              "stop",
                                              "keep",
                                              "discard",
                                              "set",
                                              "tool",
                                              "click_vertex",
                                              "drag",
                                              "stroke",
                                              "select_node",
                                              "select_arc",
                                              "pin_node",
                                              "pin_arc",
                                              "key",
                                              "camera",
                                              "open",
                                              "save",
                                              "browser_folder",
                                              "browser_name",
                                              "browser_filter",
                                              "browser_accept",
                                              "restore_autosave",
                                              "discard_autosave",
                                              "screenshot",
                                              "state",
                                              "abort",
                                              "quit"};
  return names;
}

// Commands whose argument is a path: the rest of the line.
const std::set<std::string>& path_commands() {
  static const std::set<std::string> names = {"open",  "save",         "screenshot",
                                              "state", "browser_name", "browser_folder"};
  return names;
}

bool parse_int(const std::string& s, int& out) {
  try {
    std::size_t used = 0;
    out = std::stoi(s, &used);
    return used == s.size();
  } catch (const std::exception&) {
    return false;
  }
}

bool parse_double(const std::string& s, double& out) {
  try {
    std::size_t used = 0;
    out = std::stod(s, &used);
    return used == s.size();
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

Automation::Automation(const AppOptions& options) : options_(options) {
  if (options_.bench_drag > 0) drag_bench_.emplace(options_.bench_drag);
}

bool Automation::load(std::string* error) {
  if (options_.script_path.empty()) return true;
  std::ifstream in(options_.script_path);
  if (!in) {
    if (error) *error = "cannot read the script " + options_.script_path;
    return false;
  }
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    if (const auto hash = text.find('#'); hash != std::string::npos) text.resize(hash);
    std::istringstream words(text);
    Command c;
    c.line = line;
    if (!(words >> c.name)) continue;
    if (path_commands().count(c.name)) {  // the rest of the line is one path (spaces allowed)
      std::string rest;
      std::getline(words, rest);
      const auto first = rest.find_first_not_of(" \t");
      const auto last = rest.find_last_not_of(" \t\r");
      if (first != std::string::npos) c.args.push_back(rest.substr(first, last - first + 1));
    } else {
      for (std::string w; words >> w;) c.args.push_back(w);
    }
    if (!command_names().count(c.name)) {
      if (error)
        *error = options_.script_path + ":" + std::to_string(line) + ": unknown command '" +
                 c.name + "'";
      return false;
    }
    script_.push_back(std::move(c));
  }
  return true;
}

void Automation::fail(const Command& c, const std::string& message) {
  std::fprintf(stderr, "quadsketch: %s:%d: %s: %s\n", options_.script_path.c_str(), c.line,
               c.name.c_str(), message.c_str());
  exit_code_ = 1;
  quit_ = true;
}

bool Automation::wait(const Command& c, bool done, double default_timeout_s) {
  if (done) {
    waiting_ = false;
    return true;
  }
  const auto now = std::chrono::steady_clock::now();
  if (!waiting_) {
    waiting_ = true;
    wait_start_ = now;
  }
  double timeout = default_timeout_s;
  // The timeout follows the step (wait_step) or the status (wait_status).
  const std::size_t at = c.name == "wait_step" || c.name == "wait_status" ? 1 : 0;
  if (c.args.size() > at) parse_double(c.args[at], timeout);
  if (std::chrono::duration<double>(now - wait_start_).count() > timeout) {
    waiting_ = false;
    char seconds[32];
    std::snprintf(seconds, sizeof(seconds), "%g", timeout);
    fail(c, std::string("timed out after ") + seconds + " s");
    return true;
  }
  return false;
}

void Automation::before_frame(AppContext& ctx) {
  if (!options_.bench_orbit) return;
  // A small trackball drag every frame: the worst case, the scene re-renders each frame. The
  // trackball (not the default turntable) keeps the views of earlier measurements.
  if (ctx.camera.orbit_mode() != render::OrbitMode::Trackball)
    ctx.camera.set_orbit_mode(render::OrbitMode::Trackball);
  const glm::vec2 centre = 0.5f * ctx.camera.viewport();
  ctx.camera.begin_orbit(centre);
  ctx.camera.orbit_to(centre + glm::vec2(3.0f, 1.0f));
}

bool Automation::run_command(const Command& c, AppContext& ctx, const glm::ivec2& framebuffer) {
  Editor& editor = ctx.editor;
  const auto& a = c.args;
  const auto arg_int = [&](std::size_t k, int& out) {
    if (k < a.size() && parse_int(a[k], out)) return true;
    fail(c, "expected an integer argument " + std::to_string(k + 1));
    return false;
  };
  const std::string& n = c.name;
  int x = 0;
  if (n == "frames") {
    if (wait_frames_ < 0) {
      if (!arg_int(0, x)) return true;
      wait_frames_ = x;
    }
    if (wait_frames_-- > 0) return false;
    wait_frames_ = -1;
    return true;
  }
  if (n == "wait_step") {
    if (!arg_int(0, x)) return true;
    const Snapshot* s = editor.result();
    const SnapshotPtr& latest = editor.job.latest();
    const bool ended = latest && (latest->status == WorkerStatus::Finished ||
                                  latest->status == WorkerStatus::Failed);
    return wait(c, (s && s->iteration >= x) || ended);
  }
  if (n == "wait_finished") {
    const SnapshotPtr& latest = editor.job.latest();
    return wait(c, latest && (latest->status == WorkerStatus::Finished ||
                              latest->status == WorkerStatus::Failed));
  }
  if (n == "wait_camera") return wait(c, !ctx.camera.animating(), 30.0);
  if (n == "wait_guides") {
    // Guides that cannot come fail the script at once (no mesh, a failed computation).
    const bool wanted = editor.symmetry.enabled() || editor.field_hints.enabled;
    std::string why;
    if (wanted && !editor.doc.mesh)
      why = "no mesh is open";
    else if (editor.symmetry.enabled() && !editor.symmetry.error().empty())
      why = "mirror plane: " + editor.symmetry.error();
    else if (editor.field_hints.enabled && !editor.field_hints.error().empty())
      why = "field hints: " + editor.field_hints.error();
    if (!why.empty()) {
      waiting_ = false;
      fail(c, why);
      return true;
    }
    const bool plane = !editor.symmetry.enabled() || editor.mirror();
    const bool hints = !editor.field_hints.enabled || editor.field_hints.field();
    return wait(c, plane && hints);
  }
  if (n == "wait_status") {
    const SnapshotPtr& latest = editor.job.latest();
    return wait(c, latest && !a.empty() && a[0] == to_string(latest->status));
  }
  if (n == "run") {
    editor.run();
  } else if (n == "step") {
    editor.step();
  } else if (n == "pause") {
    editor.pause();
  } else if (n == "stop") {
    editor.stop();
  } else if (n == "keep") {
    editor.keep_result();
  } else if (n == "discard") {
    editor.discard_result();
  } else if (n == "set") {
    if (a.size() != 2 || !parse_int(a[1], x)) {
      fail(c, "expected: set NAME INTEGER");
      return true;
    }
    WorkerOptions& o = editor.job.options;
    if (a[0] == "max_steps")
      o.max_steps = std::max(1, x);
    else if (a[0] == "descent_steps")
      o.descent_steps = std::max(0, x);
    else if (a[0] == "node_optimization")
      o.node_optimization = x != 0;
    else if (a[0] == "publish_interval_ms")
      o.publish_interval_ms = std::max(0, x);
    else
      fail(c, "unknown option " + a[0]);
  } else if (n == "tool") {
    Tool tool;
    if (a.empty() || !tool_from_name(a[0], tool))
      fail(c, "unknown tool");
    else
      ctx.tools.set_tool(tool);
  } else if (n == "symmetry") {
    if (a.empty()) {
      fail(c, "expected: symmetry off|x|y|z|auto");
    } else if (a[0] == "off") {
      editor.symmetry.disable();
    } else {
      try {
        editor.symmetry.enable(parse_symmetry_axis(a[0]));
      } catch (const std::exception& e) {
        fail(c, e.what());
      }
    }
  } else if (n == "field_hints") {
    if (a.empty() || (a[0] != "on" && a[0] != "off"))
      fail(c, "expected: field_hints on|off");
    else
      editor.field_hints.enabled = a[0] == "on";
  } else if (n == "hint_scale") {
    double fraction = -1.0;
    if (a.size() != 1 || !parse_double(a[0], fraction) || !(fraction >= 0.0) ||
        fraction > FieldHints::kMaxScale)
      fail(c, "expected: hint_scale F (a fraction of the diagonal in [0, 0.5])");
    else
      editor.field_hints.set_scale(fraction);
  } else if (n == "wireframe") {
    if (a.empty() || (a[0] != "on" && a[0] != "off"))
      fail(c, "expected: wireframe on|off");
    else if (ctx.renderer)
      ctx.renderer->mesh_layer().wireframe = a[0] == "on";
  } else if (n == "click_vertex") {
    if (!arg_int(0, x)) return true;
    if (!editor.doc.mesh || x < 0 || x >= int(editor.doc.mesh->n_vertices())) {
      fail(c, "no vertex " + std::to_string(x));
      return true;
    }
    const auto& p = editor.doc.mesh->point(OpenMesh::VertexHandle(x));
    const glm::vec3 s = ctx.camera.project({float(p[0]), float(p[1]), float(p[2])});
    ctx.tools.click(glm::vec2(s), editor, ctx.camera, ctx.picker);
  } else if (n == "drag") {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    if (!arg_int(0, x0) || !arg_int(1, y0) || !arg_int(2, x1) || !arg_int(3, y1)) return true;
    // Press, move in a few steps, release: the mouse's own path through the tools.
    MouseInput in;
    in.position = {float(x0), float(y0)};
    in.left_clicked = in.left_down = true;
    ctx.tools.mouse(in, editor, ctx.camera, ctx.picker);
    in.left_clicked = false;
    for (int k = 1; k <= 8; ++k) {
      in.position = glm::mix(glm::vec2(x0, y0), glm::vec2(x1, y1), float(k) / 8.0f);
      ctx.tools.mouse(in, editor, ctx.camera, ctx.picker);
    }
    in.left_down = false;
    ctx.tools.mouse(in, editor, ctx.camera, ctx.picker);
  } else if (n == "stroke") {
    std::vector<int> vertices;
    std::stringstream list(a.empty() ? std::string() : a[0]);
    for (std::string v; std::getline(list, v, ',');)
      if (parse_int(v, x)) vertices.push_back(x);
    std::string error;
    if (!ctx.tools.stroke_through_vertices(vertices, editor, ctx.camera, ctx.picker, &error))
      fail(c, error);
  } else if (n == "select_node" || n == "select_arc") {
    if (!arg_int(0, x)) return true;
    if (n == "select_node")
      editor.select(x, -1);
    else
      editor.select(-1, x);
  } else if (n == "pin_node" || n == "pin_arc") {
    if (!arg_int(0, x)) return true;
    if (n == "pin_node")
      editor.toggle_node_pin(x);
    else
      editor.toggle_arc_pin(x);
  } else if (n == "key") {
    const int key = a.empty() ? -1 : key_from_name(a[0]);
    if (key < 0) {
      fail(c, "unknown key");
      return true;
    }
    int mods = 0;
    for (std::size_t k = 1; k < a.size(); ++k) {
      if (a[k] == "ctrl") mods |= GLFW_MOD_CONTROL;
      if (a[k] == "shift") mods |= GLFW_MOD_SHIFT;
    }
    perform(key_binding(key, mods), ctx);
  } else if (n == "camera") {
    if (!a.empty() && a[0] == "trackball")
      ctx.camera.set_orbit_mode(render::OrbitMode::Trackball);
    else
      ctx.camera.set_orbit_mode(render::OrbitMode::Turntable);
  } else if (n == "open") {
    if (a.empty() || !editor.open_file(a[0])) fail(c, "cannot open");
  } else if (n == "save") {
    if (a.empty())
      save_or_ask(ctx);
    else if (!editor.save(a[0]))
      fail(c, "cannot save");
  } else if (n == "browser_folder") {
    if (a.empty() || !ctx.ui.browser.navigate(a[0])) fail(c, "not a folder");
  } else if (n == "browser_name") {
    ctx.ui.browser.set_file_name(a.empty() ? std::string() : a[0]);
  } else if (n == "browser_filter") {
    if (arg_int(0, x)) ctx.ui.browser.set_filter(x);
  } else if (n == "browser_accept") {
    accept_browser(ctx);
  } else if (n == "restore_autosave") {
    editor.restore_autosave();
  } else if (n == "discard_autosave") {
    editor.discard_autosave();
  } else if (n == "screenshot") {
    std::string error;
    if (a.empty() || !ctx.renderer || !ctx.renderer->save_png(a[0], framebuffer, &error))
      fail(c, "screenshot failed: " + error);
  } else if (n == "state") {
    std::string error;
    if (a.empty() || !write_state_json(ctx, frame_count_, a[0], &error))
      fail(c, "cannot write the state: " + error);
  } else if (n == "abort") {
    std::fflush(nullptr);
    std::_Exit(137);  // as if killed: no destructors, no clean-up
  } else if (n == "quit") {
    quit_ = true;
  }
  return true;
}

bool Automation::after_frame(AppContext& ctx, const glm::ivec2& framebuffer) {
  ++frame_count_;
  Editor& editor = ctx.editor;
  // With a scripted stroke the run starts after the stroke (frame 2), so it runs on the edit.
  const bool scripted_stroke = !options_.stroke_vertices.empty();
  if (frame_count_ == 1 && options_.run && !scripted_stroke) {
    editor.run();
    run_requested_ = true;
  }
  if (scripted_stroke && frame_count_ == 2) {
    std::string error;
    if (ctx.tools.stroke_through_vertices(options_.stroke_vertices, editor, ctx.camera, ctx.picker,
                                          &error))
      std::fprintf(stderr, "quadsketch: scripted stroke: %s\n", editor.status().c_str());
    else
      editor.report_error("--stroke-vertices: " + error);
    if (options_.run) {
      editor.run();
      run_requested_ = true;
    }
  }
  if (drag_bench_ && drag_bench_->after_frame(ctx)) quit_ = true;
  // The script: one command per frame (waits hold it).
  if (next_ < script_.size() && !quit_ && frame_count_ >= 2) {
    if (run_command(script_[next_], ctx, framebuffer)) ++next_;
  }

  // Decide whether this frame is the one to save / the last one.
  const SnapshotPtr& s = editor.job.latest();
  if (run_requested_ && frames_since_run_done_ < 0 && s &&
      (s->status == WorkerStatus::Finished || s->status == WorkerStatus::Failed ||
       s->status == WorkerStatus::Cancelled))
    frames_since_run_done_ = 0;
  else if (frames_since_run_done_ >= 0)
    ++frames_since_run_done_;
  bool due = false;
  const int bench_total = options_.bench_frames > 0 ? kBenchWarmup + options_.bench_frames : 0;
  if (bench_total > 0) {
    due = frame_count_ >= bench_total;
  } else if (options_.frames > 0) {
    due = frame_count_ >= options_.frames;
  } else if (options_.run) {
    // Two more frames so that the final snapshot is uploaded and drawn.
    const double waited =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    due = frames_since_run_done_ >= 2 || waited > 600.0;
  } else if (!options_.script_path.empty()) {
    due = quit_;
  } else {
    due = frame_count_ >= 3;
  }
  if (due && !options_.screenshot_path.empty()) {
    std::string error;
    if (!ctx.renderer || !ctx.renderer->save_png(options_.screenshot_path, framebuffer, &error)) {
      std::fprintf(stderr, "quadsketch: screenshot failed: %s\n", error.c_str());
      exit_code_ = 1;
    }
    options_.screenshot_path.clear();  // once
  }
  return quit_ || (due && (options_.quit || bench_total > 0));
}

void Automation::frame_shown(AppContext& ctx, double ms, bool scene_rendered) {
  const SnapshotPtr& latest = ctx.editor.job.latest();
  frame_stats_.add_frame(ms, scene_rendered, latest ? latest->version : 0,
                         ctx.editor.job.published_version());
  if (drag_bench_) drag_bench_->frame_shown(ctx);
  if (options_.bench_frames > 0 && frame_count_ == kBenchWarmup) {
    frame_stats_.clear_times();  // the timed frames start now
    bench_start_version_ = ctx.editor.job.published_version();
    bench_start_ = std::chrono::steady_clock::now();
    bench_start_iteration_ = latest ? latest->iteration : 0;
    if (ctx.renderer) ctx.renderer->clear_profile();
  }
}

void Automation::finish(AppContext& ctx, const glm::ivec2& framebuffer) {
  const FrameSummary stats = frame_stats_.summary();
  const Editor& editor = ctx.editor;
  if (options_.bench_frames > 0 && stats.frames > 0 && ctx.renderer) {
    render::Renderer& renderer = *ctx.renderer;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - bench_start_).count();
    const SnapshotPtr& s = editor.job.latest();
    const std::string name = render::current_renderer_name();
    std::printf(
        "bench: %d frames at %dx%d, mesh %zu faces, %zu nodes, %zu arcs; frame time mean %.2f "
        "ms, p95 %.2f ms, max %.2f ms; %.1f fps (mean); %.1f frames/s presented (paced at "
        "60); scene rendered in %d frames; %llu new snapshots published, %d drawn, max lag %d "
        "frame(s); job: %s, steps %d -> %d; camera %s; field glyphs %s; %d MSAA samples; "
        "scene cache %s; motion resolution %.2f; worker nice %d; renderer: %s\n",
        stats.frames, framebuffer.x, framebuffer.y,
        editor.doc.mesh ? std::size_t(editor.doc.mesh->n_faces()) : std::size_t(0),
        editor.doc.editor.layout().nodes.size(), editor.doc.editor.layout().arcs.size(),
        stats.mean_ms, stats.p95_ms, stats.max_ms, stats.fps,
        seconds > 0.0 ? double(stats.frames) / seconds : 0.0, stats.scene_renders,
        static_cast<unsigned long long>(editor.job.published_version() - bench_start_version_),
        stats.snapshots_drawn, stats.max_snapshot_lag, s ? to_string(s->status) : "none",
        bench_start_iteration_, s ? s->iteration : 0, options_.bench_orbit ? "orbiting" : "still",
        renderer.field_layer().visible ? "on" : "off", renderer.cache().samples(),
        renderer.cache().enabled() ? "on" : "off", options_.motion_resolution, options_.worker_nice,
        name.empty() ? "?" : name.c_str());
  }
  if (drag_bench_) {
    std::printf("%s\n", drag_bench_->report(ctx).c_str());
    if (drag_bench_->failed()) exit_code_ = 1;
  }
  if (options_.frames > 0 && stats.frames > 0)
    std::printf("%s\n", format_frame_summary(stats).c_str());
  if (ctx.renderer)
    if (const std::string profile = ctx.renderer->profile_summary(); !profile.empty())
      std::printf("%s\n", profile.c_str());
  if (!options_.state_path.empty()) {
    std::string error;
    if (!write_state_json(ctx, frame_count_, options_.state_path, &error)) {
      std::fprintf(stderr, "quadsketch: cannot write %s: %s\n", options_.state_path.c_str(),
                   error.c_str());
      exit_code_ = 1;
    }
  }
}

}  // namespace qs::app
