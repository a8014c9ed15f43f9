// quadsketch: the layout editor (interfaces.md §3).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <new>

#include "app/cli/validators.h"
#include "app/gui/app.h"
#include "core/base/allocator.h"

namespace {

// What the editor is doing, for the message of an allocation failure.
const char* activity = "starting the editor";

int run_editor(int argc, char** argv) {
  qs::keep_freed_memory();  // the worker's solves reuse freed memory (core/base/allocator.h)
  qs::app::AppOptions options;
  CLI::App cli("QuadSketch: sketch a quad layout on a triangle mesh and optimize it.");
  cli.add_option("--mesh", options.mesh_path, "Triangle mesh (.obj .off .ply .stl)");
  cli.add_option("--layout", options.layout_path, "Layout (.layout.json)");
  cli.add_flag("--run", options.run, "Start the optimization at once");
  cli.add_option("--screenshot", options.screenshot_path,
                 "Save the window as PNG after the run finishes (or after --frames frames)");
  cli.add_option("--frames", options.frames, "Number of frames before the screenshot / quit")
      ->check(CLI::PositiveNumber);
  cli.add_flag("--quit", options.quit,
               "Exit after the screenshot (files that cannot be opened: exit code 2 at once)");
  cli.add_option("--bench-frames", options.bench_frames,
                 "Frame-time benchmark: render N frames (after 10 warm-up frames), print mean "
                 "and 95th-percentile frame time and fps, and quit")
      ->check(CLI::PositiveNumber);
  cli.add_option("--bench-drag", options.bench_drag,
                 "Live-drag benchmark: drag one node with the select tool over N mouse positions "
                 "(default 60), one per frame, then print the live solves shown per second and "
                 "the latency from mouse event to solve shown, and quit")
      ->expected(0, 1)
      ->default_str("60")
      ->check(CLI::PositiveNumber);
  cli.add_flag("--show-field", options.show_field, "Start with the cross-field glyph layer on");
  cli.add_option("--samples", options.msaa_samples,
                 "Multisampling (anti-aliasing) samples, 0: off (default: 4, or 0 on software "
                 "renderers such as llvmpipe)")
      ->check(CLI::Range(0, 16));
  cli.add_option("--stroke-vertices", options.stroke_vertices,
                 "Automation: draw a free-hand stroke (stroke tool) through the screen positions "
                 "of these mesh vertices, comma-separated; the first must hold a node")
      ->delimiter(',');
  cli.add_flag("--bench-orbit", options.bench_orbit,
               "Automation: orbit the camera a little every frame (the scene is re-rendered "
               "every frame: the worst case for --bench-frames / --frames)");
  cli.add_flag("!--no-scene-cache", options.scene_cache,
               "Render the 3D scene every frame instead of reusing the last image while the "
               "camera, the scene and the view settings are unchanged");
  cli.add_option("--motion-resolution", options.motion_resolution,
                 "Resolution scale of the 3D view while the camera moves, 0.25-1 (default 0.5; "
                 "used without multisampling only; 1: always full resolution)")
      ->check(qs::cli::finite_in(0.25, 1.0));
  cli.add_option("--worker-nice", options.worker_nice,
                 "Nice value of the solver threads, 0-19 (default 10: the UI wins the CPU; 0 "
                 "leaves their priority alone)")
      ->check(CLI::Range(0, 19));
  cli.add_flag("--frame-profile", options.frame_profile,
               "Print the mean time per frame stage (waiting for the GPU between stages) at exit");
  cli.add_option("--script", options.script_path,
                 "Automation: run the editor commands of this file, one per frame (see "
                 "docs/interfaces.md)")
      ->check(CLI::ExistingFile);
  cli.add_option("--state-json", options.state_path,
                 "Automation: write the editor's state as JSON to this file at exit");
  cli.add_option("--width", options.width, "Window width")->check(CLI::Range(200, 8192));
  cli.add_option("--height", options.height, "Window height")->check(CLI::Range(200, 8192));
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);  // prints the message (or --help)
    return code == 0 ? 0 : 1;      // a malformed or out-of-range option: exit code 1
  }
  qs::app::App app(std::move(options));
  activity = "running the editor";
  return app.run();
}

}  // namespace

int main(int argc, char** argv) {
  // An allocation failure that no part of the editor handles (it reports failed loads and runs
  // itself) ends it with a message and exit code 1 instead of std::terminate; without exit
  // handlers, which could wait for a library thread that never got its memory.
  try {
    return run_editor(argc, argv);
  } catch (const std::bad_alloc&) {
    std::fflush(stdout);
    std::cerr << "quadsketch: error: out of memory while " << activity << std::endl;
    std::_Exit(1);
  }
}
