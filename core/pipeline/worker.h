// The pipeline worker: one thread that owns all algorithm state, driven by a command queue,
// streaming immutable versioned snapshots (docs/design.md, "Editor and worker"). No GL here.
//
// The UI thread only calls the public member functions below; they lock, enqueue and notify.
// The worker thread drains the queue between steps (never during one), runs the pluggable
// StepFunction without holding any lock, and publishes a new Snapshot under the lock.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stop_token>
#include <string>
#include <thread>
#include <variant>

#include "core/base/progress.h"
#include "core/field/cross_field.h"
#include "core/layout/layout.h"
#include "core/layout/symmetry.h"
#include "core/mesh/mesh.h"
#include "core/param/sizing.h"
#include "core/pipeline/snapshot.h"

namespace qs {

//! Options of a job; changed with SetOptions, read by the step function at its next step.
struct WorkerOptions {
  //! The job finishes after this many steps at most (the editor's job: the initial solve, then
  //! one step per descent step or hop sweep of node optimization; its last step also removes
  //! fold-overs).
  int max_steps = 200;
  double publish_interval_ms = 16;  //!< minimum time between intermediate snapshots
  bool node_optimization = true;
  double quad_size = 0.0;  //!< 0: automatic
  // Pipeline settings of a job (as `quadsketch-cli optimize`); a job keeps those it started with.
  bool align = true;              //!< false: ignore curvature directions (--no-align)
  double sharp_angle_deg = 35.0;  //!< sharp feature dihedral angle (--sharp-angle)
  //! Split curvature clusters of at most this many faces (--max-cluster-faces; 0: off)
  int max_cluster_faces = CrossFieldOptions{}.max_cluster_faces;
  //! Iso-lines wrap around holes that only dangling arcs run into (--wrap-free-holes)
  bool wrap_free_holes = false;
  double anisotropy = 10.0;  //!< anisotropic norm factor of the parameterization energy
  //! Curl-reducing sizing field (--sizing / --no-sizing). Unset: off, and the run retries with it
  //! when the fold-over removal fails (as `quadsketch-cli optimize` does).
  std::optional<bool> sizing;
  double alpha = 0.75;            //!< initial damping α of node-optimization steps
  int descent_steps = 25;         //!< descent steps before the first hop sweep (--steps)
  bool keep_sharp_edges = false;  //!< sharp edges as feature curves (--keep-sharp-edges)
  //! No moving node is carried next to another node (--keep-nodes-apart /
  //! --no-keep-nodes-apart). Unset: off, and the run retries with it when the fold-over removal
  //! fails or falls back (as `quadsketch-cli optimize` does).
  std::optional<bool> keep_nodes_apart;
  //! Nodes sketched next to another node are moved apart before the node optimization
  //! (NodeOptOptions::Moves::separate_crowded_nodes, --separate-nodes).
  bool separate_nodes = false;
  //! Without node optimization: when the parameterization folds, solve it again with strict
  //! orientation constraints (`optimize --no-node-opt --orientation`); the node optimization
  //! removes fold-overs at its end in any case.
  bool remove_foldovers = false;
  //! Where the orientation constraints leave fold-overs, untangle the parameterization
  //! (OrientationOptions::untangle; --no-untangle turns it off).
  bool untangle = true;
  //! Keep the layout mirror symmetric about the plane of this axis (`optimize --symmetry`,
  //! OptimizeSettings::Nodes::symmetry). Unset: off unless symmetry_plane is set. The editor
  //! sets both from its mirrored sketching when a run starts.
  std::optional<SymmetryAxis> symmetry;
  //! The mirror plane, when already computed (the editor's): used instead of the axis's.
  std::optional<MirrorPlane> symmetry_plane;
};

//! What a step function sees of the job: a qs::Observer, so it can be handed straight to
//! the pipeline stages. Lives on the worker thread only.
class WorkerObserver : public Observer {
 public:
  WorkerObserver(const std::atomic<std::uint64_t>& generation, std::uint64_t job_generation,
                 std::stop_token stop)
      : generation_(generation), job_generation_(job_generation), stop_(std::move(stop)) {}
  //! True when the job was superseded (LoadMesh, Stop) or the worker shuts down. Core code
  //! checks it between solves and throws Cancelled.
  bool should_cancel() const override {
    return stop_.stop_requested() || generation_.load(std::memory_order_acquire) != job_generation_;
  }
  //! Throws Cancelled when should_cancel().
  void check_cancel() const;

 private:
  const std::atomic<std::uint64_t>& generation_;
  std::uint64_t job_generation_;
  std::stop_token stop_;
};

//! Mutable algorithm state, owned by the worker thread.
struct WorkerState {
  std::shared_ptr<const TriMesh> mesh;
  Layout layout;            //!< the job's current layout
  std::map<int, int> pins;  //!< node id -> target vertex (SetPin)
  //! Node ids released by ClearPin: unpinned also when the job's layout pins them.
  std::set<int> released;
  //! Arc id -> pinned (SetArcPin), overriding the job's layout. A pinned arc keeps its route
  //! and its end nodes.
  std::map<int, bool> arc_pins;
  bool pins_changed = false;  //!< set when pins changed since the last step
  WorkerOptions options;
  int iteration = 0;  //!< steps done in this job (incremented by the worker)
  //! Stage state of the plugged pipeline (field, factorization, ...); reset on LoadMesh/Stop.
  std::shared_ptr<void> user;
};

//! Output of one step. Fields left empty keep the previous snapshot's value.
struct StepResult {
  bool finished = false;  //!< the job is complete; the worker goes to Finished
  std::string message;
  double energy = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::array<float, 2>> corner_uv;
  std::vector<char> face_foldover;
  StepMetrics metrics;                        //!< copied when metrics.valid
  std::shared_ptr<const NodeFrame> nodes;     //!< appended to Snapshot::node_history
  std::shared_ptr<const QuadOverlay> quads;   //!< replaces Snapshot::quads when set
  std::shared_ptr<const JobExports> exports;  //!< replaces Snapshot::exports when set
  std::shared_ptr<const FieldView> field;     //!< replaces Snapshot::field when set
  bool validate = true;  //!< run validate_layout on the state's layout for the snapshot
};

//! One step of a job. Throws QsError on failure (-> status Failed), Cancelled when cancelled.
using StepFunction = std::function<StepResult(WorkerState&, const WorkerObserver&)>;

//! Commands (each carries the seq number given by Worker::send).
namespace cmd {
struct LoadMesh {
  std::shared_ptr<const TriMesh> mesh;
  Layout layout;
};
struct Run {};
struct Pause {};
struct Step {
  int count = 1;
};
struct Stop {};
struct SetPin {
  int node_id = -1;
  int vertex = -1;
};
//! Releases the node: also one the job's layout pins.
struct ClearPin {
  int node_id = -1;
};
//! Pins (or releases) an arc: its route and end nodes stay where they are.
struct SetArcPin {
  int arc_id = -1;
  bool pinned = true;
};
struct SetOptions {
  WorkerOptions options;
};
//! Replaces the layout (after an edit); cancels a running job and drops the pins of SetPin,
//! ClearPin and SetArcPin (the new layout carries its own).
struct SetLayout {
  Layout layout;
};
struct Shutdown {};
}  // namespace cmd

using Command =
    std::variant<cmd::LoadMesh, cmd::Run, cmd::Pause, cmd::Step, cmd::Stop, cmd::SetPin,
                 cmd::ClearPin, cmd::SetArcPin, cmd::SetOptions, cmd::SetLayout, cmd::Shutdown>;

class Worker {
 public:
  //! Starts the worker thread. \p step is run once per step of a job.
  explicit Worker(StepFunction step);
  //! Sends Shutdown, cancels the running step and joins.
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  //! Enqueues a command and returns its seq number (1, 2, ...). Thread-safe.
  //! Structural commands (LoadMesh, SetLayout, Stop, Shutdown) cancel the running step at once.
  //! A SetPin replaces a still-queued SetPin for the same node, a SetArcPin one for the same
  //! arc (the latest one wins).
  std::uint64_t send(Command command);

  //! The latest published snapshot (never null). Cheap: copies a shared_ptr under the lock.
  SnapshotPtr latest() const;
  //! Version of the latest snapshot (0 before the first publication).
  std::uint64_t version() const;

  //! Blocks until a published snapshot satisfies \p pred or \p timeout passes; returns the
  //! latest snapshot either way (for tests and headless use).
  SnapshotPtr wait_for(const std::function<bool(const Snapshot&)>& pred,
                       std::chrono::milliseconds timeout) const;

  //! Number of commands waiting in the queue (for tests).
  std::size_t queued() const;

 private:
  struct Queued {
    std::uint64_t seq;
    Command command;
  };
  void run(std::stop_token stop);
  void publish(const Snapshot& base);

  StepFunction step_;
  mutable std::mutex mutex_;
  mutable std::condition_variable_any queue_cv_;  // wakes the worker
  mutable std::condition_variable publish_cv_;    // wakes wait_for
  std::deque<Queued> queue_;                      // guarded by mutex_
  std::uint64_t next_seq_ = 1;                    // guarded by mutex_
  SnapshotPtr latest_;                            // guarded by mutex_
  std::uint64_t version_ = 0;                     // guarded by mutex_
  std::atomic<std::uint64_t> generation_{0};      // bumped by structural commands
  std::jthread thread_;                           // last: starts after the members above
};

}  // namespace qs
