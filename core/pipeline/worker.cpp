#include "core/pipeline/worker.h"

#include <utility>

#include "core/base/errors.h"
#include "core/layout/validate.h"

namespace qs {

const char* to_string(WorkerStatus status) {
  switch (status) {
    case WorkerStatus::Idle:
      return "idle";
    case WorkerStatus::Running:
      return "running";
    case WorkerStatus::Paused:
      return "paused";
    case WorkerStatus::Finished:
      return "finished";
    case WorkerStatus::Failed:
      return "failed";
    case WorkerStatus::Cancelled:
      return "cancelled";
  }
  return "?";
}

void WorkerObserver::check_cancel() const {
  if (should_cancel()) throw Cancelled();
}

namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

bool is_structural(const Command& c) {
  return std::holds_alternative<cmd::LoadMesh>(c) || std::holds_alternative<cmd::SetLayout>(c) ||
         std::holds_alternative<cmd::Stop>(c) || std::holds_alternative<cmd::Shutdown>(c);
}

// Validation must never take the worker down: a throwing validator becomes one issue.
std::vector<LayoutIssue> validate_safely(const TriMesh& mesh, const Layout& layout) {
  try {
    return validate_layout(mesh, layout).issues;
  } catch (const std::exception& e) {
    LayoutIssue issue;
    issue.code = "validation_failed";
    issue.message = std::string("validation failed: ") + e.what();
    return {issue};
  }
}

}  // namespace

Worker::Worker(StepFunction step) : step_(std::move(step)) {
  latest_ = std::make_shared<const Snapshot>();
  // Started last, once every member it reads exists.
  thread_ = std::jthread([this](std::stop_token stop) { run(std::move(stop)); });
}

Worker::~Worker() {
  send(cmd::Shutdown{});
  // thread_'s destructor requests stop (waking the condition variable) and joins.
}

std::uint64_t Worker::send(Command command) {
  std::uint64_t seq = 0;
  {
    std::lock_guard lock(mutex_);
    seq = next_seq_++;
    if (const auto* pin = std::get_if<cmd::SetPin>(&command)) {
      // Collapse: a newer SetPin for the same node makes a queued one obsolete. The new one
      // goes to the back so that it stays ordered after any ClearPin sent in between.
      std::erase_if(queue_, [&](const Queued& q) {
        const auto* old = std::get_if<cmd::SetPin>(&q.command);
        return old && old->node_id == pin->node_id;
      });
    }
    if (const auto* pin = std::get_if<cmd::SetArcPin>(&command)) {
      std::erase_if(queue_, [&](const Queued& q) {
        const auto* old = std::get_if<cmd::SetArcPin>(&q.command);
        return old && old->arc_id == pin->arc_id;
      });
    }
    // Bump the generation before the worker can see the command, so that a step that is
    // running right now sees should_cancel() and stops early.
    if (is_structural(command)) generation_.fetch_add(1, std::memory_order_acq_rel);
    queue_.push_back({seq, std::move(command)});
  }
  queue_cv_.notify_one();
  return seq;
}

SnapshotPtr Worker::latest() const {
  std::lock_guard lock(mutex_);
  return latest_;
}

std::uint64_t Worker::version() const {
  std::lock_guard lock(mutex_);
  return version_;
}

std::size_t Worker::queued() const {
  std::lock_guard lock(mutex_);
  return queue_.size();
}

SnapshotPtr Worker::wait_for(const std::function<bool(const Snapshot&)>& pred,
                             std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  publish_cv_.wait_for(lock, timeout, [&] { return pred(*latest_); });
  return latest_;
}

void Worker::publish(const Snapshot& base) {
  // The copy is made outside the lock; only this (worker) thread writes version_, so reading
  // it here without the lock does not race with the UI's locked reads.
  auto snapshot = std::make_shared<Snapshot>(base);
  snapshot->version = version_ + 1;
  {
    std::lock_guard lock(mutex_);
    latest_ = std::move(snapshot);
    version_ = latest_->version;
  }
  publish_cv_.notify_all();
}

void Worker::run(std::stop_token stop) {
  using Clock = std::chrono::steady_clock;
  // Everything below is owned by this thread; the UI never sees it except through publish().
  WorkerState state;
  Snapshot current;
  bool running = false;
  int step_budget = 0;
  std::uint64_t job_generation = generation_.load();
  std::uint64_t drained_seq = 0;
  std::uint64_t pending_pin_seq = 0;  // first pin command not yet used by a step (0: none)
  Clock::time_point last_publish = Clock::now() - std::chrono::hours(1);

  auto applied_seq = [&] { return pending_pin_seq ? pending_pin_seq - 1 : drained_seq; };
  auto set_layout = [&](Layout layout) {
    state.layout = std::move(layout);
    current.layout = std::make_shared<const Layout>(state.layout);
    current.issues =
        state.mesh ? validate_safely(*state.mesh, state.layout) : std::vector<LayoutIssue>{};
  };
  auto reset_job = [&] {
    state.iteration = 0;
    state.user.reset();
    current.iteration = 0;
    current.energy = std::numeric_limits<double>::quiet_NaN();
    current.energy_history.clear();
    current.energy_init = std::numeric_limits<double>::quiet_NaN();
    current.metrics = StepMetrics{};
    current.node_history.clear();
    current.quads.reset();
    current.exports.reset();
    current.field.reset();
    current.corner_uv.clear();
    current.face_foldover.clear();
  };
  // A job starts fresh unless it was paused (then it resumes).
  auto start_job = [&] {
    if (current.status != WorkerStatus::Paused && current.status != WorkerStatus::Running)
      reset_job();
    job_generation = generation_.load(std::memory_order_acquire);
  };

  for (;;) {
    std::deque<Queued> batch;
    {
      std::unique_lock lock(mutex_);
      const bool want_step = (running || step_budget > 0) && state.mesh;
      if (!want_step) queue_cv_.wait(lock, stop, [&] { return !queue_.empty(); });
      if (stop.stop_requested()) return;
      batch.swap(queue_);
    }

    bool changed = false;
    for (auto& queued : batch) {
      drained_seq = queued.seq;
      bool shutdown = false;
      std::visit(Overloaded{
                     [&](cmd::LoadMesh& c) {
                       WorkerOptions options = state.options;
                       state = WorkerState{};
                       state.mesh = std::move(c.mesh);
                       state.options = options;
                       running = false;
                       step_budget = 0;
                       pending_pin_seq = 0;
                       current = Snapshot{};
                       current.generation = generation_.load();
                       current.mesh = state.mesh;
                       set_layout(std::move(c.layout));
                       current.status = WorkerStatus::Idle;
                       current.message = state.mesh ? "mesh loaded" : "no mesh";
                     },
                     [&](cmd::SetLayout& c) {
                       running = false;
                       step_budget = 0;
                       reset_job();
                       set_layout(std::move(c.layout));
                       state.pins.clear();
                       state.released.clear();
                       state.arc_pins.clear();
                       state.pins_changed = true;
                       pending_pin_seq = 0;
                       current.generation = generation_.load();
                       current.status = WorkerStatus::Idle;
                       current.message = "layout changed";
                     },
                     [&](cmd::Run&) {
                       if (!state.mesh) {
                         current.status = WorkerStatus::Failed;
                         current.message = "no mesh loaded";
                         return;
                       }
                       start_job();
                       running = true;
                       current.status = WorkerStatus::Running;
                       current.message = "running";
                     },
                     [&](cmd::Pause&) {
                       running = false;
                       step_budget = 0;
                       if (current.status == WorkerStatus::Running) {
                         current.status = WorkerStatus::Paused;
                         current.message = "paused";
                       }
                     },
                     [&](cmd::Step& c) {
                       if (!state.mesh) return;
                       start_job();
                       running = false;
                       step_budget += std::max(1, c.count);
                       current.status = WorkerStatus::Paused;
                     },
                     [&](cmd::Stop&) {
                       running = false;
                       step_budget = 0;
                       reset_job();
                       current.generation = generation_.load();
                       current.status = WorkerStatus::Cancelled;
                       current.message = "stopped";
                     },
                     [&](cmd::SetPin& c) {
                       state.pins[c.node_id] = c.vertex;
                       state.released.erase(c.node_id);
                       state.pins_changed = true;
                       if (!pending_pin_seq) pending_pin_seq = queued.seq;
                     },
                     [&](cmd::ClearPin& c) {
                       state.pins.erase(c.node_id);
                       state.released.insert(c.node_id);
                       state.pins_changed = true;
                       if (!pending_pin_seq) pending_pin_seq = queued.seq;
                     },
                     [&](cmd::SetArcPin& c) {
                       state.arc_pins[c.arc_id] = c.pinned;
                       state.pins_changed = true;
                       if (!pending_pin_seq) pending_pin_seq = queued.seq;
                     },
                     [&](cmd::SetOptions& c) { state.options = c.options; },
                     [&](cmd::Shutdown&) { shutdown = true; },
                 },
                 queued.command);
      if (shutdown) return;
      changed = true;
    }
    if (changed) {
      current.applied_seq = applied_seq();
      publish(current);
      last_publish = Clock::now();
    }

    if (!((running || step_budget > 0) && state.mesh)) continue;

    // One step, without any lock held. Commands sent meanwhile wait in the queue.
    WorkerObserver observer(generation_, job_generation, stop);
    try {
      observer.check_cancel();
      StepResult result = step_(state, observer);
      ++state.iteration;
      state.pins_changed = false;
      pending_pin_seq = 0;
      if (step_budget > 0) --step_budget;

      current.generation = job_generation;
      current.iteration = state.iteration;
      current.energy = result.energy;
      if (current.energy_history.empty()) current.energy_init = result.energy;
      current.energy_history.push_back(result.energy);
      if (result.metrics.valid) current.metrics = result.metrics;
      if (result.nodes) current.node_history.push_back(std::move(result.nodes));
      if (result.quads) current.quads = std::move(result.quads);
      if (result.exports) current.exports = std::move(result.exports);
      if (result.field) current.field = std::move(result.field);
      if (!result.message.empty()) current.message = result.message;
      if (!result.corner_uv.empty()) current.corner_uv = std::move(result.corner_uv);
      if (!result.face_foldover.empty()) current.face_foldover = std::move(result.face_foldover);
      current.layout = std::make_shared<const Layout>(state.layout);
      if (result.validate) current.issues = validate_safely(*state.mesh, state.layout);
      current.pins.clear();
      for (const auto& [node, vertex] : state.pins) current.pins.push_back({node, vertex});
      if (result.finished || state.iteration >= state.options.max_steps) {
        running = false;
        step_budget = 0;
        current.status = WorkerStatus::Finished;
      } else {
        current.status = running ? WorkerStatus::Running : WorkerStatus::Paused;
      }
      current.applied_seq = applied_seq();

      // Throttle intermediate snapshots; the last one of a run is always published.
      const auto now = Clock::now();
      const bool last = !running && step_budget == 0;
      const auto interval = std::chrono::duration<double, std::milli>(now - last_publish);
      if (last || interval.count() >= state.options.publish_interval_ms) {
        publish(current);
        last_publish = now;
      }
    } catch (const Cancelled&) {
      // Superseded by a structural command (already queued) or shutting down: nothing to
      // publish; the next loop turn drains the command that cancelled us.
      if (!stop.stop_requested() && generation_.load() == job_generation) {
        running = false;  // the step cancelled itself: treat like Stop
        step_budget = 0;
        current.status = WorkerStatus::Cancelled;
        current.message = "cancelled";
        publish(current);
      }
    } catch (const std::exception& e) {
      running = false;
      step_budget = 0;
      current.status = WorkerStatus::Failed;
      current.message = dynamic_cast<const QsError*>(&e)
                            ? std::string(e.what())
                            : std::string("internal error: ") + e.what();
      current.applied_seq = applied_seq();
      publish(current);
      last_publish = Clock::now();
    }
  }
}

}  // namespace qs
