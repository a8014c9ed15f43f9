// Node optimization on a working mesh (paper §6–7; docs/design.md, "Node optimization"):
// gradient descent on the residual E of energy (1), each node moved to exactly the surface point
// its straightest-geodesic step reaches (node_move.h), then fold-over removal and the choice of
// the returned state among the candidates by one rule.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/node_move.h"
#include "core/param/orientation.h"
#include "core/pipeline/pipeline.h"

namespace qs {

enum class GradientKind { kEstimator, kExact };

struct WmOptions {
  // ---- descent ----
  int max_steps = 25;    //!< descent steps (accepted + rejected)
  double alpha = 0.75;   //!< initial damping factor α of the step length
  int max_halvings = 5;  //!< the descent ends after this many halvings of α in a row
  GradientKind gradient = GradientKind::kEstimator;
  ExactGradientOptions exact;
  // ---- fold-over removal ----
  //! Strict orientation constraints (paper §7.2) at a candidate state that folds.
  bool orientation = true;
  OrientationOptions orientation_options;  //!< `enabled` is set by the optimizer
  //! Ends the node movement early when it returns true (polled before each step).
  std::function<bool()> stop;
};

//! \throw InvalidInputError naming the option when a value is out of range.
void validate_wm_options(const WmOptions& options);

//! One state the fold-over removal considered for the result.
struct WmCandidate {
  std::string name;  //!< "final", "oriented final", "last fold-free", "initial", ...
  double E = 0;
  int foldovers = 0;
  bool structurally_equivalent = false;
};

struct WmResult {
  std::optional<MeshLayout> state;  //!< the returned working mesh and layout on it (set by finish)
  //! Solved at `state` (with the orientation constraints when orientation_constraints).
  std::shared_ptr<Pipeline> pipeline;
  bool orientation_constraints = false;    //!< the returned solve uses them
  OrientationOptions orientation_options;  //!< the options of that solve
  OrientationReport orientation;           //!< of the last orientation-constrained solve run
  double E_init = 0, E_descent = 0, E_final = 0;
  int foldovers_init = 0, foldovers_descent = 0, foldovers_final = 0;
  int steps = 0, accepted = 0, halvings = 0;
  bool stopped = false;
  std::vector<StepReport> reports;
  //! Every candidate examined, and the name of the one returned (the rule: lowest E among the
  //! fold-free, structurally equivalent candidates; else fewest fold-overs, then equivalence,
  //! then E).
  std::vector<WmCandidate> candidates;
  std::string chosen;
  double time_s = 0;
};

//! The descent one step at a time (the editor shows each state); finish() ends it.
class WmOptimizer {
 public:
  //! Solves the initial state (reported as step 0). \throw InvalidInputError, TopologyError,
  //! SolverError, Cancelled.
  WmOptimizer(MeshLayout start, const PipelineOptions& options, const WmOptions& node_options = {},
              Observer* observer = nullptr);
  ~WmOptimizer();
  WmOptimizer(const WmOptimizer&) = delete;
  WmOptimizer& operator=(const WmOptimizer&) = delete;

  //! One descent step; false when the descent is over (then call finish()).
  bool step(Observer* observer = nullptr);
  //! Pins per node (index): pinned nodes do not move from the next step on.
  void set_pinned(const std::vector<char>& pinned);
  const MeshLayout& state() const;
  const std::vector<StepReport>& reports() const;
  //! The Pipeline solved at the current state.
  std::shared_ptr<Pipeline> pipeline() const;
  //! Fold-over removal and the choice of the result; ends the optimization.
  WmResult finish(Observer* observer = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

//! Runs the whole optimization (step until over, then finish).
WmResult optimize_working_layout(MeshLayout start, const PipelineOptions& options,
                                 const WmOptions& node_options = {}, Observer* observer = nullptr);

}  // namespace qs
