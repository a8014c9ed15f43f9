// Progress reporting and cancellation for long-running optimizations (node optimization).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/base/errors.h"

namespace qs {

//! One iteration of an iterative optimization (interfaces.md report.json "steps").
struct StepReport {
  int step = 0;           //!< 1-based iteration number (0: the initial solve)
  double E = 0;           //!< residual of energy (1) after the step (length² units)
  bool accepted = false;  //!< false: E rose, the step was undone
  double step_size = 0;   //!< damping factor α in force for this step (dimensionless)
  int foldovers = 0;      //!< faces with signed parametric area ≤ 0 after the step
  double time_s = 0;      //!< wall time of this step (seconds)
  int moved_nodes = 0;    //!< nodes whose position changed in this step
  std::string phase;      //!< "descent", "discrete", "stiffening", …
  //! Node positions (3D, mesh units) after the step, in layout node order.
  std::vector<std::array<double, 3>> node_positions;
};

//! Receives progress and is polled for cancellation between solves.
class Observer {
 public:
  virtual ~Observer();
  virtual void on_step(const StepReport& /*report*/) {}
  //! When true, the optimizer throws qs::Cancelled at its next check (between solves).
  virtual bool should_cancel() const { return false; }
};

inline Observer::~Observer() = default;

//! Throws qs::Cancelled when \p observer (may be null) asks to cancel.
inline void check_cancel(const Observer* observer) {
  if (observer && observer->should_cancel()) throw Cancelled();
}

}  // namespace qs
