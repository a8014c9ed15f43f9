// The editor's side of the pipeline worker (GL-free): the commands it sends, the snapshots it
// reads, and which job result the editor shows. A result is never dropped without the user's
// say: a stopped run stays shown (Keep or Discard), a kept result keeps its quad mesh, energy
// and exports while the layout is unchanged, and pins toggled during a run go to that run.
// While a node is dragged, the layout at the drag position is solved live (docs/design.md,
// "Editor and worker"): one solve at a time, the newest position next.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/gui/document.h"
#include "core/pipeline/worker.h"

namespace qs::app {

//! What the shown job result is.
enum class ResultKind {
  None,     //!< no result: the edited layout is shown
  Live,     //!< the worker's current job (running, paused, finished; not failed)
  Stopped,  //!< a run ended with Stop: its state when stopped (Keep or Discard it)
  Kept,     //!< adopted with Keep result; shown while the edited layout is unchanged and
            //!< until the next run
};

const char* to_string(ResultKind kind);

//! The editor's job (pipeline_step) with its solver threads at nice \p worker_nice (0:
//! unchanged) and limited to the idle cores.
StepFunction editor_step_function(int worker_nice);

class JobControl {
 public:
  //! Starts a worker thread running \p step once per step of a job.
  explicit JobControl(StepFunction step);
  ~JobControl();

  //! The options the next Run / Step sends (the Pipeline panel edits them).
  WorkerOptions options;

  // Worker commands. \p doc is the editor's document (mesh and edited layout).
  //! A new mesh (and its layout): the worker starts over; held results are dropped.
  void load(const Document& doc);
  //! The edited layout changed (an edit, undo, redo): the worker takes it, cancelling a run.
  //! Returns true when this dropped a shown result that was not kept.
  bool layout_edited(const Layout& layout);
  //! Resumes a paused run, or starts a new one from the edited layout (which replaces the
  //! stopped or kept result shown).
  void run(const Document& doc);
  //! One step: of the paused run, or the first of a new run from the edited layout.
  void step(const Document& doc);
  void pause();
  //! Ends the run at once; the state reached stays shown (ResultKind::Stopped).
  void stop(const Document& doc);
  //! Forgets the shown result (stopped, finished or paused run): the edited layout is shown.
  void discard(const Document& doc);
  //! Adopts the shown result's layout as the edited layout (one undoable edit) and keeps its
  //! quad mesh, energy and exports shown. Returns false (nothing changes) without a result.
  bool keep(Document& doc);
  //! Sends the options now (e.g. the quad size after its slider was released).
  void send_options();

  //! Reads the worker's latest snapshot; true when it is new. Once per frame.
  bool poll(const Document& doc);
  const SnapshotPtr& latest() const { return latest_; }
  //! Version of the worker's newest snapshot (maybe not read by poll() yet).
  std::uint64_t published_version() const { return worker_->version(); }
  //! The result shown instead of the edited layout, or null.
  const Snapshot* shown(const Document& doc) const;
  ResultKind shown_kind(const Document& doc) const;
  //! True while a run is in progress (running, or paused with steps done).
  bool running() const;
  bool paused() const;
  //! Identifies the shown result's parameterization (changes when it does; 0: none).
  std::uint64_t param_version(const Document& doc);
  //! The shown result as a shared pointer (null: none), e.g. to restore it later.
  SnapshotPtr shown_snapshot(const Document& doc) const;
  //! Shows \p snapshot as a result of kind \p kind for the edited layout as it is now (undo of a
  //! drag: the result shown before it), until the layout changes or another result replaces it.
  //! Nothing happens for a null \p snapshot or ResultKind::None.
  void restore(SnapshotPtr snapshot, ResultKind kind, const Document& doc);

  // Live solves while a node is dragged. Each is the solve of Run without node optimization
  // (the engine's initial solve, with the quad mesh) of one drag position's layout, on the
  // worker. At most one is in flight; a newer position replaces the pending one, so no stale
  // position is ever queued. The solve in flight runs to its end and is shown (it is the newest
  // that can be shown soonest); only the release cancels it. Any other command (load, edit,
  // run, step, stop, discard, keep) ends live solving.
  using Clock = std::chrono::steady_clock;
  //! Asks for the solve of \p layout, the drag position of the mouse event at \p event: sent
  //! at once when no live solve is in flight, else kept as the pending request (replacing an
  //! older one) and sent when the solve in flight ends. The first request drops the result
  //! shown (as an edit does).
  void live_request(const Layout& layout, Clock::time_point event);
  //! The current drag position is invalid: the pending request is dropped and no solve is
  //! shown (the edited layout with its validation issues is) until the next request.
  void live_invalid();
  //! The drag was released on \p layout: its solve is sent at once (cancelling the one in
  //! flight); the last drag solve stays shown until it arrives, and no older solve is shown
  //! after it. Then the result is that of Run without node optimization on \p layout.
  void live_release(const Layout& layout, Clock::time_point event);
  //! True from the first live request (or live_invalid) until the release's solve arrived or
  //! another command ended live solving.
  bool live() const { return live_.active; }
  //! True when the newest snapshot read by poll() belongs to live solving.
  bool latest_is_live() const;
  //! True once after poll() read the solve of the released layout.
  bool take_live_released();
  //! Counts and latencies of the live solves shown.
  struct LiveStats {
    int requests = 0;  //!< live_request and live_release calls
    int sent = 0;      //!< solves sent to the worker
    int shown = 0;     //!< solves shown (drag positions and releases)
    //! Per solve shown: milliseconds from its request's mouse event to poll() reading it.
    std::vector<double> latency_ms;
    Clock::time_point last_event;  //!< the mouse event of the latest solve shown
  };
  const LiveStats& live_stats() const { return live_stats_; }
  void clear_live_stats() { live_stats_ = {}; }

  // Pins during a run: they go to the run (applied at its next step) instead of the layout.
  //! True when pins go to the worker's job (running or paused with steps done).
  bool live_pins() const;
  //! Pinned state in the job as the user sees it (pins sent but not yet applied included).
  bool node_pinned(int node) const;
  bool arc_pinned(int arc) const;
  //! Toggles the pin in the job; returns the new state.
  bool toggle_node_pin(int node);
  bool toggle_arc_pin(int arc);
  //! Pins sent and not yet applied, (id, pinned), for drawing them at once.
  std::vector<std::pair<int, bool>> pending_node_pins() const;
  std::vector<std::pair<int, bool>> pending_arc_pins() const;

  //! Scrubbed step of the shown result (index into node_history); follows the newest when live.
  int history_step = -1;
  bool history_live = true;

 private:
  bool showable(const Snapshot& s, const Document& doc) const;
  bool held_valid(const Document& doc) const;
  void start_fresh(const Document& doc);
  //! Sends the live solve of \p layout (SetLayout, the options without node optimization, Step).
  void send_live(const Layout& layout, Clock::time_point event);
  //! Starts a live drag session (drops a held run result and a pending stop) unless one is on.
  void begin_live();
  //! Reads the end of the live solve in flight from latest_.
  void poll_live(const Document& doc);

  struct PendingPin {
    int id = -1;
    bool pinned = false;
    std::uint64_t seq = 0;
  };
  struct Held {
    SnapshotPtr snapshot;
    ResultKind kind = ResultKind::None;
    std::uint64_t layout_version = 0;  //!< the edited layout's version it belongs to
    const TriMesh* mesh = nullptr;
    bool restored = false;  //!< by restore(): shown before the worker's state
  };
  struct Live {
    bool active = false;
    bool released = false;  //!< the release's solve is the one in flight
    bool invalid = false;   //!< the current drag position is invalid
    std::optional<Layout> pending;
    Clock::time_point pending_event;
    std::uint64_t inflight_seq = 0;  //!< seq of the Step of the solve in flight (0: none)
    Clock::time_point inflight_event;
    SnapshotPtr shown;  //!< the newest live solve read
  };

  std::unique_ptr<Worker> worker_;
  SnapshotPtr latest_;
  std::vector<PendingPin> pending_nodes_;
  std::vector<PendingPin> pending_arcs_;
  Held held_;
  Live live_;
  LiveStats live_stats_;
  SnapshotPtr live_result_;       //!< the release's solve, once read
  bool live_released_ = false;    //!< take_live_released()
  bool keeping_ = false;          //!< inside keep()
  std::uint64_t stop_seq_ = 0;    //!< Stop sent and not yet applied (0: none)
  std::uint64_t layout_seq_ = 0;  //!< the latest LoadMesh or SetLayout sent
  std::uint64_t stop_generation_ = 0;
  // param_version bookkeeping
  const Snapshot* param_snapshot_ = nullptr;
  std::uint64_t param_version_ = 0;
  std::size_t param_size_ = 0;
  int param_iteration_ = -1;
  std::uint64_t param_generation_ = 0;
};

}  // namespace qs::app
