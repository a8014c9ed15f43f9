#include "app/gui/job_control.h"

#include <algorithm>

#include "app/gui/history.h"
#include "app/gui/pipeline_job.h"
#include "app/gui/thread_priority.h"
#include "core/base/solver_threads.h"

namespace qs::app {

const char* to_string(ResultKind kind) {
  switch (kind) {
    case ResultKind::None:
      return "none";
    case ResultKind::Live:
      return "live";
    case ResultKind::Stopped:
      return "stopped";
    case ResultKind::Kept:
      return "kept";
  }
  return "?";
}

StepFunction editor_step_function(int worker_nice) {
  return [worker_nice](WorkerState& state, const WorkerObserver& observer) {
    // The solver threads run below the UI's priority (lowered at the first step of every job,
    // so that the math libraries' thread pools, created on first use, are caught too).
    if (state.iteration == 0) lower_solver_thread_priority(worker_nice);
    limit_solver_threads_here();  // CHOLMOD's OpenMP regions: at most the idle cores
    return pipeline_step(state, observer);
  };
}

JobControl::JobControl(StepFunction step)
    : worker_(std::make_unique<Worker>(std::move(step))), latest_(worker_->latest()) {}

JobControl::~JobControl() {
  worker_.reset();  // joins the worker thread first
}

bool JobControl::showable(const Snapshot& s, const Document& doc) const {
  // Nothing the worker published before it took the latest layout sent.
  return s.mesh && s.mesh == doc.mesh && s.iteration > 0 && s.layout &&
         s.applied_seq >= layout_seq_ && s.status != WorkerStatus::Failed &&
         s.status != WorkerStatus::Idle;
}

bool JobControl::held_valid(const Document& doc) const {
  return held_.snapshot && held_.mesh == doc.mesh.get() &&
         held_.layout_version == doc.editor.version();
}

const Snapshot* JobControl::shown(const Document& doc) const {
  // While dragging: the newest live solve (none at an invalid position).
  if (live_.active) {
    return live_.invalid || !live_.shown || live_.shown->mesh != doc.mesh ? nullptr
                                                                          : live_.shown.get();
  }
  const bool held = held_valid(doc);
  // A stopped run, a restored result, and a kept result until the worker has moved on, before
  // the worker's state.
  if (held && (held_.kind == ResultKind::Stopped || held_.restored || held_.snapshot == latest_))
    return held_.snapshot.get();
  if (latest_ && showable(*latest_, doc)) return latest_.get();
  if (held) return held_.snapshot.get();
  return nullptr;
}

ResultKind JobControl::shown_kind(const Document& doc) const {
  const Snapshot* s = shown(doc);
  if (!s) return ResultKind::None;
  if (!live_.active && s == held_.snapshot.get() && held_valid(doc)) return held_.kind;
  return ResultKind::Live;
}

SnapshotPtr JobControl::shown_snapshot(const Document& doc) const {
  const Snapshot* s = shown(doc);
  if (!s) return nullptr;
  if (s == live_.shown.get()) return live_.shown;
  if (s == held_.snapshot.get()) return held_.snapshot;
  return latest_;
}

void JobControl::restore(SnapshotPtr snapshot, ResultKind kind, const Document& doc) {
  if (!snapshot || kind == ResultKind::None) return;
  live_ = {};
  held_ = {};
  held_.snapshot = std::move(snapshot);
  held_.kind = kind;
  held_.layout_version = doc.editor.version();
  held_.mesh = doc.mesh.get();
  held_.restored = true;
}

bool JobControl::running() const {
  return latest_ && latest_->status == WorkerStatus::Running && stop_seq_ == 0;
}

bool JobControl::paused() const {
  return latest_ && latest_->status == WorkerStatus::Paused && latest_->iteration > 0 &&
         stop_seq_ == 0;
}

void JobControl::load(const Document& doc) {
  live_ = {};
  held_ = {};
  stop_seq_ = 0;
  pending_nodes_.clear();
  pending_arcs_.clear();
  if (doc.mesh) layout_seq_ = worker_->send(cmd::LoadMesh{doc.mesh, doc.editor.layout()});
}

bool JobControl::layout_edited(const Layout& layout) {
  bool dropped = false;
  if (keeping_) {  // keep(): the result becomes the layout, nothing is dropped
    layout_seq_ = worker_->send(cmd::SetLayout{layout});
    return false;
  }
  if (held_.kind == ResultKind::Stopped && held_.snapshot) dropped = true;
  // A live solve is no run result: dropping it is no news.
  if (latest_ && latest_->iteration > 0 && latest_->layout && latest_->mesh &&
      latest_->status != WorkerStatus::Idle && latest_->status != WorkerStatus::Failed &&
      !latest_is_live())
    dropped = true;
  live_ = {};
  held_ = {};
  stop_seq_ = 0;
  layout_seq_ = worker_->send(cmd::SetLayout{layout});
  return dropped;
}

void JobControl::send_options() {
  worker_->send(cmd::SetOptions{options});
}

void JobControl::start_fresh(const Document& doc) {
  // A new run starts from the edited layout (not from an earlier run's state), without the
  // pins toggled during that run, and replaces the result shown (stopped or kept).
  live_ = {};
  held_ = {};
  stop_seq_ = 0;
  layout_seq_ = worker_->send(cmd::SetLayout{doc.editor.layout()});
  send_options();
}

void JobControl::run(const Document& doc) {
  if (!doc.mesh || running()) return;
  if (paused()) {
    send_options();
  } else {
    start_fresh(doc);
  }
  worker_->send(cmd::Run{});
}

void JobControl::step(const Document& doc) {
  if (!doc.mesh || running()) return;
  if (paused())
    send_options();
  else
    start_fresh(doc);
  worker_->send(cmd::Step{});
}

void JobControl::pause() {
  worker_->send(cmd::Pause{});
}

void JobControl::stop(const Document& doc) {
  // The state reached is what the user sees now (a step finishing meanwhile is taken too).
  Held held;
  held.kind = ResultKind::Stopped;
  if (latest_ && latest_->iteration > 0 && latest_->layout && latest_->mesh &&
      latest_->status != WorkerStatus::Failed && latest_->status != WorkerStatus::Idle) {
    held.snapshot = latest_;
  }
  held.mesh = doc.mesh.get();
  held.layout_version = doc.editor.version();
  live_ = {};
  stop_generation_ = latest_ ? latest_->generation : 0;
  held_ = std::move(held);
  stop_seq_ = worker_->send(cmd::Stop{});
  pending_nodes_.clear();
  pending_arcs_.clear();
}

void JobControl::discard(const Document& doc) {
  const bool live = live_.active || (latest_ && showable(*latest_, doc));
  live_ = {};
  held_ = {};
  stop_seq_ = 0;
  if (live) layout_seq_ = worker_->send(cmd::SetLayout{doc.editor.layout()});
}

bool JobControl::keep(Document& doc) {
  const Snapshot* s = shown(doc);
  if (!s || !s->layout || shown_kind(doc) == ResultKind::Kept) return false;
  if (running()) return false;
  const SnapshotPtr kept = shown_snapshot(doc);
  const Layout layout = *s->layout;
  // replace_layout reports the edit (on_change -> layout_edited), which sends the layout to
  // the worker; the kept result is held after that.
  live_ = {};
  keeping_ = true;
  const EditResult r = doc.editor.replace_layout(layout, "keep optimized layout");
  keeping_ = false;
  if (!r) return false;
  stop_seq_ = 0;
  held_.snapshot = kept;
  held_.kind = ResultKind::Kept;
  held_.layout_version = doc.editor.version();
  held_.mesh = doc.mesh.get();
  return true;
}

bool JobControl::poll(const Document& doc) {
  // Copy the pointer under the worker's lock; use the immutable snapshot lock-free after.
  SnapshotPtr s = worker_->latest();
  if (latest_ && s->version == latest_->version) return false;
  latest_ = std::move(s);
  // Pins the worker has now applied (or that a new layout superseded) are no longer pending.
  const auto applied = [&](const PendingPin& p) { return p.seq <= latest_->applied_seq; };
  std::erase_if(pending_nodes_, applied);
  std::erase_if(pending_arcs_, applied);
  if (stop_seq_ != 0) {
    // A step of the stopped run that was finished before the Stop reached the worker.
    if (held_.kind == ResultKind::Stopped && latest_->generation == stop_generation_ &&
        latest_->mesh && latest_->mesh == doc.mesh && latest_->iteration > 0 && latest_->layout &&
        (!held_.snapshot || latest_->iteration > held_.snapshot->iteration))
      held_.snapshot = latest_;
    if (latest_->applied_seq >= stop_seq_) stop_seq_ = 0;
  }
  poll_live(doc);
  const Snapshot* shown_now = shown(doc);
  history_step =
      scrub_index(history_step, shown_now ? int(shown_now->node_history.size()) : 0, history_live);
  return true;
}

std::uint64_t JobControl::param_version(const Document& doc) {
  const Snapshot* s = shown(doc);
  if (!s || s->corner_uv.empty()) {
    param_snapshot_ = nullptr;
    return 0;
  }
  if (s != param_snapshot_) {
    if (!param_snapshot_ || s->corner_uv.size() != param_size_ ||
        s->iteration != param_iteration_ || s->generation != param_generation_)
      ++param_version_;
    param_snapshot_ = s;
    param_size_ = s->corner_uv.size();
    param_iteration_ = s->iteration;
    param_generation_ = s->generation;
  }
  return param_version_;
}

bool JobControl::live_pins() const {
  return (running() || paused()) && latest_->layout && latest_->mesh &&
         held_.kind != ResultKind::Stopped;
}

bool JobControl::node_pinned(int node) const {
  for (auto it = pending_nodes_.rbegin(); it != pending_nodes_.rend(); ++it)
    if (it->id == node) return it->pinned;
  if (!latest_ || !latest_->layout) return false;
  if (const int k = latest_->layout->node_index(node); k >= 0)
    return latest_->layout->nodes[k].pinned;
  return false;
}

bool JobControl::arc_pinned(int arc) const {
  for (auto it = pending_arcs_.rbegin(); it != pending_arcs_.rend(); ++it)
    if (it->id == arc) return it->pinned;
  if (!latest_ || !latest_->layout) return false;
  if (const int k = latest_->layout->arc_index(arc); k >= 0) return latest_->layout->arcs[k].pinned;
  return false;
}

bool JobControl::toggle_node_pin(int node) {
  const Layout& layout = *latest_->layout;
  const int k = layout.node_index(node);
  if (k < 0) return false;
  const bool pin = !node_pinned(node);
  const std::uint64_t seq = pin ? worker_->send(cmd::SetPin{node, layout.nodes[k].vertex})
                                : worker_->send(cmd::ClearPin{node});
  pending_nodes_.push_back({node, pin, seq});
  return pin;
}

bool JobControl::toggle_arc_pin(int arc) {
  if (latest_->layout->arc_index(arc) < 0) return false;
  const bool pin = !arc_pinned(arc);
  const std::uint64_t seq = worker_->send(cmd::SetArcPin{arc, pin});
  pending_arcs_.push_back({arc, pin, seq});
  return pin;
}

std::vector<std::pair<int, bool>> JobControl::pending_node_pins() const {
  std::vector<std::pair<int, bool>> out;
  for (const auto& p : pending_nodes_) out.emplace_back(p.id, p.pinned);
  return out;
}

std::vector<std::pair<int, bool>> JobControl::pending_arc_pins() const {
  std::vector<std::pair<int, bool>> out;
  for (const auto& p : pending_arcs_) out.emplace_back(p.id, p.pinned);
  return out;
}

void JobControl::send_live(const Layout& layout, Clock::time_point event) {
  // Run without node optimization: its first step is the initial solve, and the last.
  WorkerOptions fixed = options;
  fixed.node_optimization = false;
  layout_seq_ = worker_->send(cmd::SetLayout{layout});  // cancels the solve in flight, if any
  worker_->send(cmd::SetOptions{fixed});
  live_.inflight_seq = worker_->send(cmd::Step{});
  live_.inflight_event = event;
  ++live_stats_.sent;
}

void JobControl::begin_live() {
  if (live_.active) return;
  held_ = {};
  stop_seq_ = 0;
  live_ = {};
  live_.active = true;
}

void JobControl::live_request(const Layout& layout, Clock::time_point event) {
  ++live_stats_.requests;
  begin_live();
  live_.invalid = false;
  if (live_.inflight_seq == 0) {
    send_live(layout, event);
  } else {
    live_.pending = layout;
    live_.pending_event = event;
  }
}

void JobControl::live_invalid() {
  begin_live();
  live_.invalid = true;
  live_.pending.reset();
}

void JobControl::live_release(const Layout& layout, Clock::time_point event) {
  live_request(layout, event);
  if (live_.pending) {  // a drag solve is in flight: the release's supersedes it
    live_.pending.reset();
    send_live(layout, event);
  }
  live_.released = true;
}

bool JobControl::latest_is_live() const {
  return latest_ && (live_.active || latest_ == live_result_);
}

bool JobControl::take_live_released() {
  const bool released = live_released_;
  live_released_ = false;
  return released;
}

void JobControl::poll_live(const Document& doc) {
  if (!live_.active || live_.inflight_seq == 0 || latest_->applied_seq < live_.inflight_seq) return;
  const WorkerStatus status = latest_->status;
  if (status != WorkerStatus::Finished && status != WorkerStatus::Failed &&
      status != WorkerStatus::Cancelled)
    return;  // the Step was taken; its solve is running
  live_.inflight_seq = 0;
  if (!live_.invalid) {
    live_.shown = showable(*latest_, doc) ? latest_ : nullptr;
    ++live_stats_.shown;
    live_stats_.latency_ms.push_back(
        std::chrono::duration<double, std::milli>(Clock::now() - live_.inflight_event).count());
    live_stats_.last_event = live_.inflight_event;
  }
  if (live_.released) {
    // The solve of the released layout: from now on the worker's result, as after a Run.
    live_ = {};
    live_result_ = latest_;
    live_released_ = true;
  } else if (live_.pending) {
    const Layout next = std::move(*live_.pending);
    live_.pending.reset();
    send_live(next, live_.pending_event);
  }
}

}  // namespace qs::app
