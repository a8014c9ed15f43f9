// The whole `optimize` policy in one place (docs/design.md, "The optimize engine"): user
// settings → initial solve → node optimization (descent, hop polish, fold-over removal) → the
// keep-apart and sizing retries → integer sizes → the final solve. `quadsketch-cli optimize`
// calls optimize(); the editor drives an OptimizeRun one unit at a time and streams each state.
// Both therefore produce the same result from the same settings.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/base/progress.h"
#include "core/layout/layout.h"
#include "core/layout/symmetry.h"
#include "core/mesh/mesh.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/symmetric_step.h"
#include "core/pipeline/integer_sizes.h"
#include "core/pipeline/pipeline.h"

namespace qs {

//! How nodes move: the gradient estimator or the exact gradient (paper §7.2), or the discrete
//! baseline (one vertex hop at a time, core/nodeopt/discrete.h; not steppable: one unit).
enum class NodeMethod { kEstimator, kExact, kDiscrete };

//! The user-facing settings of one optimize run, in groups. Every other setting of the node
//! optimizer keeps its NodeOptOptions default. Angles in degrees, times in seconds.
struct OptimizeSettings {
  struct Field {
    bool align = true;              //!< follow principal curvature directions (--no-align)
    double sharp_angle_deg = 35.0;  //!< dihedral angle above which an edge is a feature
    int max_cluster_faces = CrossFieldOptions{}.max_cluster_faces;  //!< 0: whole regions
    bool wrap_free_holes = false;                                   //!< FreeLoopTurning::kWrap
  } field;
  struct Param {
    double anisotropy = ParamOptions{}.anisotropy;  //!< ≥ 1 (1: isotropic)
    //! Curl-reducing sizing field. Unset: off, and the sizing retry may turn it on.
    std::optional<bool> sizing;
  } param;
  struct Nodes {
    bool enabled = true;  //!< false: the nodes stay where the layout puts them
    int steps = 25;       //!< descent steps before the first hop sweep (≥ 0)
    NodeMethod method = NodeMethod::kEstimator;
    double alpha = NodeOptOptions{}.descent.alpha;  //!< initial damping of the steps, in (0, 1]
    bool slide_on_curves = true;                    //!< nodes on features and the boundary slide
    bool keep_sharp_edges = false;                  //!< sharp edges are curves nodes slide along
    //! No node moves next to another node. Unset: off, and the keep-apart retry may turn it on.
    std::optional<bool> keep_apart;
    bool separate_crowded = false;  //!< nodes next to another node move apart first
    double time_limit_s = 0;        //!< wall-clock budget for moving nodes (0: none)
    //! Keep the layout mirror symmetric (docs/design.md, "Symmetric optimization"; continuous
    //! node optimization only, not with separate_crowded): the plane of this axis through the
    //! mesh's bounding-box centre, or fitted (mirror_plane). Unset: off unless symmetry_plane is
    //! set.
    std::optional<SymmetryAxis> symmetry;
    //! The mirror plane itself (e.g. the editor's, already fitted): used instead of computing
    //! the plane of `symmetry`, and turns symmetry on. Unit normal, finite offset.
    std::optional<MirrorPlane> symmetry_plane;
    //! Threads the node optimizer may use (NodeOptOptions::Run::threads, ≥ 1): 2 or more solve
    //! hop candidates and a fold-over removal fallback beside the main thread, 3 or more also a
    //! descent trial beside its retry. The same results for every value.
    int threads = NodeOptOptions{}.run.threads;
  } nodes;
  struct Folds {
    //! Remove fold-overs with orientation constraints: with moving nodes at the end of each
    //! node optimization, with fixed nodes in the one solve. Unset: on with moving nodes, off
    //! with fixed ones. `sectors` and `untangle` go into PipelineOptions::param.orientation in
    //! either case (enabled only for fixed nodes), whose options the node optimizer's
    //! constrained solves take.
    std::optional<bool> remove;
    SectorFrame sectors = SectorFrame::kFieldThenSolution;
    bool untangle = true;  //!< untangle where the orientation constraints leave fold-overs
  } folds;
  struct Sizes {
    //! Patch sides integer multiples of a quad size (paper §8): the quad size, or a quad count
    //! from which it is derived (one of the two > 0).
    bool integer = false;
    double quad_size = 0;
    int quad_count = 0;
  } sizes;
};

//! Checks \p settings; \throw InvalidInputError naming the setting and its value.
void validate_settings(const OptimizeSettings& settings);
//! Symmetric optimization is on (nodes.symmetry or nodes.symmetry_plane set).
bool symmetric(const OptimizeSettings& settings);

//! The solver options that \p settings mean (the field and parameterization options of the
//! first attempt, before any retry; the orientation options of the fold-over removal).
PipelineOptions pipeline_options(const OptimizeSettings& settings);
//! The node optimizer options that \p settings mean (keep_nodes_apart as given or off).
NodeOptOptions node_options(const OptimizeSettings& settings);

//! One rerun of the node optimization from the input (a retry) and its outcome.
struct RetryRecord {
  std::string with;   //!< "nodes kept apart" or "the sizing field"
  bool used = false;  //!< its result replaced the earlier one
  int foldovers_without = 0, foldovers_with = 0;
  double E_without = 0, E_with = 0;
  bool untangled_without = false, untangled_with = false;
  bool fell_back_without = false;  //!< the earlier run fell back to an earlier state
  bool initial_without = false, initial_with = false;  //!< ... to the initial state
  double time_s = 0;
};

//! The outcome of an optimize run.
struct OptimizeResult {
  //! At the final mesh and layout with `options`: solved (field + parameterization) after a
  //! node optimization or OptimizeRun::pipeline(); a fixed-node run's solve may be left to the
  //! caller (its orientation-constrained solve polls what Pipeline::set_orientation_observer
  //! sets). extract(), metrics() and output_layout() are the caller's.
  std::shared_ptr<Pipeline> pipeline;
  PipelineOptions options;  //!< of that solve (weights, orientation, sizing, arc lengths)
  //! The node optimization whose result was kept (absent with fixed nodes).
  std::optional<NodeOptResult> nodes;
  //! With integer sizes and moving nodes: the relaxed run they were rounded from.
  std::optional<NodeOptResult> relaxed;
  bool keep_nodes_apart = false;  //!< of the kept run
  std::optional<RetryRecord> keep_apart_retry, sizing_retry;
  std::optional<IntegerSizes> integer;
  double E_relaxed = 0;  //!< unweighted E of the relaxed solve (integer sizes)
  //! With symmetric optimization: the plane and the node pairs every run kept (found once on
  //! the input layout; measure_node_symmetry measures them on the result). Null when off.
  std::shared_ptr<const NodeSymmetry> symmetry;
  double node_time_s = 0;     //!< wall-clock time of every node optimization run
  bool time_limited = false;  //!< the time limit ended a node movement
};

//! An optimize run one unit at a time: construction is the initial solve (with symmetric
//! optimization first the plane and the mirror pairs of the input layout), each step() one
//! descent step or hop sweep of the current node optimization; when one ends, step() removes
//! its fold-overs and starts the next run the policy asks for (a retry from the input, or the
//! integer run) with its initial solve. finish() ends the run and returns the result; with all
//! steps taken it equals optimize(). Not thread-safe: one thread drives it.
class OptimizeRun {
 public:
  //! \throw InvalidInputError (settings, invalid layout, a layout that is not symmetric about
  //! the plane of symmetric optimization: find_mirror_pairs's message naming the first node
  //! without a mirror), TopologyError, SolverError, Cancelled.
  OptimizeRun(TriMesh mesh, Layout layout, const OptimizeSettings& settings,
              Observer* observer = nullptr);
  ~OptimizeRun();
  OptimizeRun(const OptimizeRun&) = delete;
  OptimizeRun& operator=(const OptimizeRun&) = delete;

  //! Runs the next unit; false when nothing is left (call finish()). \throw as the constructor.
  bool step(Observer* observer = nullptr);
  //! Pins for the next steps and for every later run (retries start from the input with the
  //! same pins): one flag per node / arc of layout() (same indexing as the input layout; empty
  //! arc flags: unchanged). \throw std::invalid_argument on a wrong count.
  void set_pinned(const std::vector<char>& nodes, const std::vector<char>& arcs = {});

  //! The current state (of the current node optimization, or the fixed-node solve).
  const TriMesh& mesh() const;
  const Layout& layout() const;
  //! Solved at the current state; valid until the next step().
  std::shared_ptr<Pipeline> pipeline(Observer* observer = nullptr);
  //! Reports of the current node optimization (the initial solve first; empty: fixed nodes).
  const std::vector<StepReport>& reports() const;
  //! Counts the node optimization runs started (1 for the first; a retry or the integer run
  //! adds one). A change between steps means the state went back to a run's start.
  int runs() const;
  //! Messages for the user since the last call (retries started and their outcome, nodes moved
  //! apart), oldest first.
  std::vector<std::string> take_notes();
  //! Ends the run: the fold-over removal of a node optimization still going, the choice among
  //! the runs made, the integer sizes of a fixed-node run and the final solve. No other call
  //! after it. \throw as the constructor.
  OptimizeResult finish(Observer* observer = nullptr);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

//! The whole run: OptimizeRun's steps to the end, then finish(). \p observer gets every step
//! and is polled for cancellation; notes go to it as well through \p notes when given.
OptimizeResult optimize(TriMesh mesh, Layout layout, const OptimizeSettings& settings,
                        Observer* observer = nullptr, std::vector<std::string>* notes = nullptr);

}  // namespace qs
