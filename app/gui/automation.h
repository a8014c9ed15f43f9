// Automation of the editor for tests, benchmarks and screenshots (docs/interfaces.md §3): the
// --screenshot / --frames / --quit / --run / --stroke-vertices / --bench-* (--bench-drag:
// drag_bench.h) / --frame-profile flags, the --state-json dump at exit, and --script files of
// editor commands.
//
// A script has one command per line ('#' starts a comment; a path argument is the rest of its
// line); one command runs per frame, after the frame was drawn, through the same code as the
// mouse, keys and panels:
//   frames N                 wait N frames
//   wait_step N [S]          until the shown result reached step N or the run ended (S: timeout
//                            in seconds, default 300; a timeout fails the script)
//   wait_finished [S]        until the run finished or failed
//   wait_status NAME [S]     until the worker's status is NAME (idle, running, paused,
//                            finished, failed, cancelled)
//   wait_camera [S]          until the camera's animation ended
//   run | step | pause | stop | keep | discard      the Pipeline panel's buttons
//   set max_steps|descent_steps|node_optimization|publish_interval_ms V   a pipeline option
//   tool NAME                select | place_node | draw_arc | split | delete | pin | stroke |
//                            dangling | insert_loop | remove_loop
//   symmetry off|x|y|z|auto  mirrored sketching off, or on about that plane (Sketch panel)
//   field_hints on|off       the View panel's "Field hints"
//   hint_scale F             the View panel's "Hint scale", F a fraction of the diagonal
//   wireframe on|off         the View panel's wireframe of the surface
//   wait_guides [S]          until the mirror plane and the field hints that are on are ready
//                            (fails at once without a mesh or when their computation failed)
//   click_vertex V           the current tool's click at mesh vertex V's screen position
//   drag X0 Y0 X1 Y1         a left-button drag between window points (orbits off the nodes)
//   stroke V1,V2,...         a stroke-tool stroke through those vertices
//   select_node ID | select_arc ID | pin_node ID | pin_arc ID   (pins as the P key does)
//   key NAME [ctrl] [shift]  a key press (actions.h key_from_name)
//   camera turntable|trackball
//   open PATH                a mesh or a layout
//   save [PATH]              without PATH: as Ctrl+S
//   browser_folder PATH | browser_name NAME | browser_filter N | browser_accept
//   restore_autosave | discard_autosave
//   screenshot PATH | state PATH          the window as PNG | state_dump.h's JSON
//   abort                    ends the process at once (as if killed: no cleanup, exit 137)
//   quit
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/gui/app_options.h"
#include "app/gui/context.h"
#include "app/gui/drag_bench.h"
#include "app/gui/frame_stats.h"
#include "render/renderer.h"

namespace qs::app {

class Automation {
 public:
  explicit Automation(const AppOptions& options);

  //! Reads and checks the script (--script). False with \p error naming the file and line.
  bool load(std::string* error);
  //! With --quit (and no script), files that cannot be opened end the app before any window.
  bool quit_on_load_error() const { return options_.quit && options_.script_path.empty(); }
  //! Frame timings matter (benchmarks, --frames): no vertical sync, the GPU waited for.
  bool timed() const {
    return options_.bench_frames > 0 || options_.frames > 0 || options_.bench_drag > 0;
  }
  //! The mouse is scripted (--bench-drag): the window's own mouse input is ignored.
  bool drives_mouse() const { return drag_bench_.has_value(); }

  //! Before a frame: the benchmark's camera orbit.
  void before_frame(AppContext& ctx);
  //! After a frame was drawn, before it is shown: the scripted stroke and run, the script's
  //! next command, the screenshot when due. True when the app should quit after this frame.
  bool after_frame(AppContext& ctx, const glm::ivec2& framebuffer);
  //! After the frame was shown: its statistics (\p ms wall time).
  void frame_shown(AppContext& ctx, double ms, bool scene_rendered);
  //! At exit: the benchmark line, the frame summary, the profile, the state JSON.
  void finish(AppContext& ctx, const glm::ivec2& framebuffer);
  int exit_code() const { return exit_code_; }
  int frames() const { return frame_count_; }

 private:
  struct Command {
    int line = 0;
    std::string name;
    std::vector<std::string> args;
  };
  //! Runs the script's current command; true when it is done (the next one runs next frame).
  bool run_command(const Command& c, AppContext& ctx, const glm::ivec2& framebuffer);
  void fail(const Command& c, const std::string& message);
  bool wait(const Command& c, bool done, double default_timeout_s = 300.0);

  AppOptions options_;
  std::vector<Command> script_;
  std::size_t next_ = 0;
  int wait_frames_ = -1;  // "frames N": frames still to wait (-1: not waiting)
  bool waiting_ = false;
  std::chrono::steady_clock::time_point wait_start_;
  bool quit_ = false;

  int frame_count_ = 0;
  int exit_code_ = 0;
  bool run_requested_ = false;
  int frames_since_run_done_ = -1;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  FrameStats frame_stats_;
  std::optional<DragBench> drag_bench_;
  static constexpr int kBenchWarmup = 10;
  std::uint64_t bench_start_version_ = 0;
  int bench_start_iteration_ = 0;
  std::chrono::steady_clock::time_point bench_start_ = std::chrono::steady_clock::now();
};

}  // namespace qs::app
