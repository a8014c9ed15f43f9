#include "app/gui/frame_stats.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace qs::app {

void FrameStats::add_frame(double ms, bool scene_rendered, std::uint64_t drawn_version,
                           std::uint64_t published_version) {
  ++frame_;
  ms_.push_back(ms);
  if (scene_rendered) ++scene_renders_;
  if (have_drawn_ && drawn_version != last_drawn_) ++snapshots_drawn_;
  last_drawn_ = drawn_version;
  have_drawn_ = true;
  if (waiting_version_ != 0 && drawn_version >= waiting_version_) {
    max_lag_ = std::max(max_lag_, int(frame_ - waiting_since_));
    ++waited_;
    waiting_version_ = 0;
  }
  // A newer snapshot than the one on screen exists now: the next frames must draw it.
  if (waiting_version_ == 0 && published_version > drawn_version) {
    waiting_version_ = published_version;
    waiting_since_ = frame_;
  }
}

void FrameStats::clear_times() {
  ms_.clear();
  scene_renders_ = 0;
  snapshots_drawn_ = 0;
  max_lag_ = 0;
  waited_ = 0;
}

FrameSummary FrameStats::summary() const {
  FrameSummary s;
  s.frames = int(ms_.size());
  s.scene_renders = scene_renders_;
  s.snapshots_drawn = snapshots_drawn_;
  s.max_snapshot_lag = max_lag_;
  s.snapshots_waited = waited_;
  if (ms_.empty()) return s;
  std::vector<double> sorted = ms_;
  std::sort(sorted.begin(), sorted.end());
  double sum = 0.0;
  for (double t : sorted) sum += t;
  s.mean_ms = sum / double(sorted.size());
  const std::size_t k95 =
      std::min(sorted.size() - 1, std::size_t(std::ceil(0.95 * double(sorted.size()))) - 1);
  s.p95_ms = sorted[k95];
  s.max_ms = sorted.back();
  s.fps = s.mean_ms > 0.0 ? 1000.0 / s.mean_ms : 0.0;
  return s;
}

std::string format_frame_summary(const FrameSummary& s) {
  char line[512];
  std::snprintf(line, sizeof(line),
                "frames: %d, mean frame time %.2f ms (%.1f fps), p95 %.2f ms, max %.2f ms; scene "
                "rendered in %d of %d frames (the others reused the cached image); %d new "
                "snapshots drawn, max lag %d frame(s) after publication (%d waited)",
                s.frames, s.mean_ms, s.fps, s.p95_ms, s.max_ms, s.scene_renders, s.frames,
                s.snapshots_drawn, s.max_snapshot_lag, s.snapshots_waited);
  return line;
}

}  // namespace qs::app
