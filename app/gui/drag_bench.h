// The live-drag benchmark (--bench-drag N, automation.h): a scripted drag of one node of the
// open layout with the select tool, one mouse position per frame through the same code as the
// mouse (Tools::mouse), then the release. It reports the live solves shown (JobControl's live
// solving): their number per second and the latency from the mouse event to the frame that
// shows the solve, and whether the result after the release is the released layout's solve.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "app/gui/context.h"

namespace qs::app {

class DragBench {
 public:
  //! A drag over \p positions mouse positions (at least 2).
  explicit DragBench(int positions);

  //! After a frame was drawn: the next mouse event of the drag (from the third frame on), or
  //! the wait for the release's solve. True when the benchmark is over (report() is ready).
  bool after_frame(AppContext& ctx);
  //! After the frame was shown: the latency of a solve that this frame showed for the first time.
  void frame_shown(AppContext& ctx);
  //! One line with the numbers ("bench-drag: ..."), or why the benchmark failed.
  std::string report(const AppContext& ctx) const;
  bool failed() const { return !error_.empty(); }

 private:
  using Clock = std::chrono::steady_clock;
  enum class Phase { Start, Drag, Wait, Done };
  //! Chooses the node and the path; false with error_ set when there is none.
  bool plan(AppContext& ctx);

  int positions_;
  Phase phase_ = Phase::Start;
  int frame_ = 0;
  int node_ = -1;
  glm::vec2 from_{0.0f};
  glm::vec2 along_{1.0f, 0.0f};  //!< unit direction of the path's chord on screen
  float radius_ = 0.0f;          //!< of the circle the path follows (pixels)
  int next_ = 0;                 //!< next mouse position (0: the press)
  int moves_ = 0;                //!< positions that moved the node
  int refused_ = 0;              //!< positions the drag refused
  std::string refusal_;          //!< the first refusal's reason
  Clock::time_point first_event_;
  Clock::time_point release_;
  Clock::time_point end_;
  int shown_seen_ = 0;  //!< JobControl::LiveStats::shown at the last frame
  int shown_while_dragging_ = 0;
  std::vector<double> latency_ms_;    //!< mouse event -> frame shown, per solve shown
  std::vector<double> solve_ms_;      //!< worker time (StepMetrics::total_ms) per solve shown
  std::vector<double> ui_ms_;         //!< UI thread time per mouse event that moved the node
  double release_latency_ms_ = -1.0;  //!< release -> its solve shown
  std::string final_;                 //!< the result after the release
  std::string error_;
};

}  // namespace qs::app
