// The editor's command-line options (docs/interfaces.md §3), parsed in main.cpp.
#pragma once

#include <string>
#include <vector>

namespace qs::app {

struct AppOptions {
  std::string mesh_path;    //!< "" -> bundled example
  std::string layout_path;  //!< "" -> bundled example layout (with the example mesh only)
  int width = 1280;
  int height = 800;
  bool show_field = false;  //!< start with the cross-field glyph layer on
  //! Multisampling of the window; -1: automatic (4, or 0 on a software renderer such as
  //! llvmpipe, where 4x multisampling costs about 4x the frame time).
  int msaa_samples = -1;
  //! Redraw on demand: reuse the last rendered scene image while nothing it shows changed.
  bool scene_cache = true;
  //! Resolution scale of the scene while the camera moves (software renderers without
  //! multisampling only); 1: always full resolution.
  float motion_resolution = 0.5f;
  //! Nice value (0..19) of the solver threads; 0 leaves their priority alone.
  int worker_nice = 10;

  // Automation (automation.h).
  bool run = false;  //!< start the optimization at once
  std::string screenshot_path;
  int frames = 0;  //!< 0: not given
  bool quit = false;
  //! Frame-time benchmark: render this many frames (after a short warm-up), print mean and
  //! 95th-percentile frame time and fps, then quit. 0: off.
  int bench_frames = 0;
  //! A free-hand stroke through the screen positions of these mesh vertices (the first must
  //! hold a node), applied like a mouse stroke with the stroke tool.
  std::vector<int> stroke_vertices;
  //! Live-drag benchmark (drag_bench.h): drag one node over this many mouse positions, one per
  //! frame, print the live solves shown per second and their latency, then quit. 0: off.
  int bench_drag = 0;
  //! Orbit the camera a little every frame (the scene re-renders every frame, the worst case
  //! for the frame rate).
  bool bench_orbit = false;
  //! Per-stage frame timings (glFinish between stages), printed at exit.
  bool frame_profile = false;
  //! A script of editor commands, one per line (automation.h), run one per frame.
  std::string script_path;
  //! The editor's state as JSON, written at exit (state_dump.h).
  std::string state_path;
};

}  // namespace qs::app
