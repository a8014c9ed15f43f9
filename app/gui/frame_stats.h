// Frame statistics of the editor (GL-free): frame times, how many frames re-rendered the 3D
// scene (the others reused the cached image), and how many frames a published worker snapshot
// waited before it was drawn. Printed by --bench-frames and --frames.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace qs::app {

//! Summary of a run of frames (times in milliseconds).
struct FrameSummary {
  int frames = 0;
  double mean_ms = 0.0;
  double p95_ms = 0.0;
  double max_ms = 0.0;
  double fps = 0.0;         //!< 1000 / mean_ms (0 without frames)
  int scene_renders = 0;    //!< frames that rendered the 3D scene (not the cached image)
  int snapshots_drawn = 0;  //!< frames that picked up a newer worker snapshot
  //! Frames between the end of the frame during which a snapshot was (first seen) published
  //! and the frame that drew it (or a newer one): 1 means "the next frame". 0 when every
  //! snapshot was picked up by the frame during which it was published or none was waited on.
  int max_snapshot_lag = 0;
  int snapshots_waited = 0;  //!< snapshots seen published at the end of a frame, drawn later
};

class FrameStats {
 public:
  //! Records one frame: its duration, whether it rendered the scene, the snapshot version it
  //! drew, and the worker's latest published version read after the frame was presented.
  //! Versions are Worker / Snapshot::version counters (strictly increasing; 0: none).
  void add_frame(double ms, bool scene_rendered, std::uint64_t drawn_version,
                 std::uint64_t published_version);
  FrameSummary summary() const;
  //! Forgets recorded frames (e.g. after a warm-up); the snapshot being waited on, if any,
  //! stays pending.
  void clear_times();

 private:
  std::vector<double> ms_;
  int scene_renders_ = 0;
  int snapshots_drawn_ = 0;
  int max_lag_ = 0;
  int waited_ = 0;
  std::uint64_t frame_ = 0;
  std::uint64_t last_drawn_ = 0;
  bool have_drawn_ = false;
  std::uint64_t waiting_version_ = 0;  // 0: not waiting
  std::uint64_t waiting_since_ = 0;    // frame index
};

//! One line "frames: N, mean frame time X ms (Y fps), p95 ..., scene rendered in R frames,
//! S new snapshots drawn, max lag L frame(s)".
std::string format_frame_summary(const FrameSummary& s);

}  // namespace qs::app
