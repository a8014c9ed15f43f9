// Worker: commands in, ordered snapshots out; cancellation; pins; failures; shutdown.
// Uses fake step functions (no pipeline stages needed).
#include "core/pipeline/worker.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "app/gui/history.h"
#include "core/base/errors.h"

namespace qs {
namespace {

using namespace std::chrono_literals;

std::shared_ptr<const TriMesh> tetrahedron() {
  auto mesh = std::make_shared<TriMesh>();
  TriMesh::VertexHandle v[4] = {mesh->add_vertex({0, 0, 0}), mesh->add_vertex({1, 0, 0}),
                                mesh->add_vertex({0, 1, 0}), mesh->add_vertex({0, 0, 1})};
  mesh->add_face(v[0], v[2], v[1]);
  mesh->add_face(v[0], v[1], v[3]);
  mesh->add_face(v[0], v[3], v[2]);
  mesh->add_face(v[1], v[2], v[3]);
  return mesh;
}

bool is(const Snapshot& s, WorkerStatus status) {
  return s.status == status;
}

TEST(Worker, StartsWithAnEmptySnapshot) {
  Worker worker([](WorkerState&, const WorkerObserver&) { return StepResult{}; });
  const auto s = worker.latest();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->version, 0u);
  EXPECT_EQ(s->status, WorkerStatus::Idle);
}

TEST(Worker, RunPublishesOrderedSnapshotsUntilFinished) {
  Worker worker([](WorkerState& state, const WorkerObserver&) {
    StepResult r;
    r.energy = 100.0 - state.iteration;  // iteration is the number of steps done before
    r.validate = false;
    return r;
  });
  WorkerOptions options;
  options.max_steps = 6;
  options.publish_interval_ms = 0;  // publish every step
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  const auto run_seq = worker.send(cmd::Run{});

  // Watch the stream: versions strictly increase, iterations never go back.
  std::uint64_t last_version = 0;
  int last_iteration = -1;
  SnapshotPtr s;
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  do {
    s = worker.latest();
    EXPECT_GE(s->version, last_version);
    if (s->generation == worker.latest()->generation) {
      EXPECT_GE(s->iteration, last_iteration);
    }
    last_version = s->version;
    last_iteration = s->iteration;
    std::this_thread::yield();
  } while (!is(*s, WorkerStatus::Finished) && std::chrono::steady_clock::now() < deadline);

  ASSERT_EQ(s->status, WorkerStatus::Finished);
  EXPECT_EQ(s->iteration, 6);
  ASSERT_EQ(s->energy_history.size(), 6u);
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(s->energy_history[i], 100.0 - i);
  EXPECT_DOUBLE_EQ(s->energy, 95.0);
  EXPECT_GE(s->applied_seq, run_seq);
  EXPECT_TRUE(s->mesh);
  EXPECT_TRUE(s->layout);
}

TEST(Worker, StopCancelsARunningStepAndTheWorkerStaysUsable) {
  std::atomic<bool> slow{true};
  std::atomic<int> entered{0};
  Worker worker([&](WorkerState&, const WorkerObserver& observer) {
    ++entered;
    while (slow) {
      observer.check_cancel();  // throws Cancelled once Stop bumped the generation
      std::this_thread::sleep_for(1ms);
    }
    StepResult r;
    r.finished = true;
    r.message = "done";
    r.validate = false;
    return r;
  });
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::Run{});
  for (int i = 0; i < 5000 && entered == 0; ++i) std::this_thread::sleep_for(1ms);
  ASSERT_GT(entered.load(), 0);

  const auto stop_seq = worker.send(cmd::Stop{});
  auto s = worker.wait_for(
      [&](const Snapshot& x) {
        return x.applied_seq >= stop_seq && is(x, WorkerStatus::Cancelled);
      },
      5s);
  EXPECT_EQ(s->status, WorkerStatus::Cancelled);
  EXPECT_EQ(s->iteration, 0);

  slow = false;
  worker.send(cmd::Run{});
  s = worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Finished); }, 5s);
  EXPECT_EQ(s->status, WorkerStatus::Finished);
  EXPECT_EQ(s->message, "done");
}

TEST(Worker, PinsAreAppliedAtTheNextStep) {
  std::mutex seen_mutex;
  std::map<int, int> seen_pins;
  Worker worker([&](WorkerState& state, const WorkerObserver&) {
    std::lock_guard lock(seen_mutex);
    seen_pins = state.pins;
    StepResult r;
    r.validate = false;
    return r;
  });
  const auto load_seq = worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  const auto pin_seq = worker.send(cmd::SetPin{7, 3});
  // The pin is drained but not applied: no step ran, so applied_seq stays below it.
  auto s = worker.wait_for([&](const Snapshot& x) { return x.applied_seq >= load_seq; }, 2s);
  std::this_thread::sleep_for(20ms);
  s = worker.latest();
  EXPECT_LT(s->applied_seq, pin_seq);
  EXPECT_TRUE(s->pins.empty());

  worker.send(cmd::Step{});
  s = worker.wait_for([&](const Snapshot& x) { return x.iteration >= 1; }, 5s);
  ASSERT_EQ(s->iteration, 1);
  EXPECT_GE(s->applied_seq, pin_seq);
  ASSERT_EQ(s->pins.size(), 1u);
  EXPECT_EQ(s->pins[0][0], 7);
  EXPECT_EQ(s->pins[0][1], 3);
  {
    std::lock_guard lock(seen_mutex);
    EXPECT_EQ(seen_pins.at(7), 3);
  }

  const auto clear_seq = worker.send(cmd::ClearPin{7});
  worker.send(cmd::Step{});
  s = worker.wait_for([&](const Snapshot& x) { return x.iteration >= 2; }, 5s);
  EXPECT_GE(s->applied_seq, clear_seq);
  EXPECT_TRUE(s->pins.empty());
}

TEST(Worker, RepeatedSetPinForOneNodeCollapses) {
  std::atomic<bool> gate{false};
  std::atomic<int> entered{0};
  Worker worker([&](WorkerState& state, const WorkerObserver&) {
    ++entered;
    while (!gate) std::this_thread::sleep_for(1ms);  // hold the worker inside a step
    StepResult r;
    r.validate = false;
    r.message = "pins " + std::to_string(state.pins.size());
    return r;
  });
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::Step{});
  for (int i = 0; i < 5000 && entered == 0; ++i) std::this_thread::sleep_for(1ms);
  ASSERT_EQ(entered.load(), 1);

  // The worker is busy: these stay queued, and the three SetPin for node 1 collapse.
  worker.send(cmd::SetPin{1, 0});
  worker.send(cmd::SetPin{2, 0});
  worker.send(cmd::SetPin{1, 2});
  const auto last = worker.send(cmd::SetPin{1, 3});
  EXPECT_EQ(worker.queued(), 2u);

  worker.send(cmd::Step{});
  gate = true;
  auto s = worker.wait_for([&](const Snapshot& x) { return x.applied_seq >= last; }, 5s);
  ASSERT_GE(s->applied_seq, last);
  ASSERT_EQ(s->pins.size(), 2u);
  EXPECT_EQ(s->pins[0][0], 1);
  EXPECT_EQ(s->pins[0][1], 3);  // the latest wins
}

TEST(Worker, ArcPinsAndReleasesAreAppliedAtTheNextStepAndSetLayoutDropsThem) {
  std::mutex seen_mutex;
  std::map<int, bool> seen_arcs;
  std::set<int> seen_released;
  Worker worker([&](WorkerState& state, const WorkerObserver&) {
    std::lock_guard lock(seen_mutex);
    seen_arcs = state.arc_pins;
    seen_released = state.released;
    StepResult r;
    r.validate = false;
    return r;
  });
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::SetPin{4, 1});
  const auto release_seq = worker.send(cmd::ClearPin{4});  // released: also a layout pin
  worker.send(cmd::SetArcPin{3, false});
  const auto arc_seq = worker.send(cmd::SetArcPin{3, true});  // replaces the queued one
  worker.send(cmd::Step{});
  auto s = worker.wait_for([&](const Snapshot& x) { return x.iteration >= 1; }, 5s);
  ASSERT_EQ(s->iteration, 1);
  EXPECT_GE(s->applied_seq, std::max(release_seq, arc_seq));
  EXPECT_TRUE(s->pins.empty());
  {
    std::lock_guard lock(seen_mutex);
    EXPECT_EQ(seen_arcs, (std::map<int, bool>{{3, true}}));
    EXPECT_EQ(seen_released, (std::set<int>{4}));
  }
  // A new layout carries its own pins: the commands' pins are gone at the next step.
  worker.send(cmd::SetPin{5, 2});
  worker.send(cmd::SetLayout{Layout{}});
  const auto step_seq = worker.send(cmd::Step{});
  s = worker.wait_for(
      [&](const Snapshot& x) { return x.applied_seq >= step_seq && x.iteration >= 1; }, 5s);
  ASSERT_GE(s->applied_seq, step_seq);
  EXPECT_TRUE(s->pins.empty());
  std::lock_guard lock(seen_mutex);
  EXPECT_TRUE(seen_arcs.empty());
  EXPECT_TRUE(seen_released.empty());
}

TEST(Worker, FailuresArePublishedAndTheWorkerStaysAlive) {
  Worker worker([](WorkerState&, const WorkerObserver&) -> StepResult {
    throw SolverError("parameterization: matrix not positive definite (n = 12)");
  });
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::Run{});
  auto s = worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Failed); }, 5s);
  ASSERT_EQ(s->status, WorkerStatus::Failed);
  EXPECT_NE(s->message.find("positive definite"), std::string::npos);

  const auto seq = worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  s = worker.wait_for([&](const Snapshot& x) { return x.applied_seq >= seq; }, 5s);
  EXPECT_EQ(s->status, WorkerStatus::Idle);
}

TEST(Worker, RunWithoutMeshFails) {
  Worker worker([](WorkerState&, const WorkerObserver&) { return StepResult{}; });
  worker.send(cmd::Run{});
  auto s = worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Failed); }, 5s);
  EXPECT_EQ(s->status, WorkerStatus::Failed);
  EXPECT_EQ(s->message, "no mesh loaded");
}

TEST(Worker, PauseAndStep) {
  std::atomic<bool> gate{true};
  Worker worker([&](WorkerState&, const WorkerObserver& observer) {
    while (!gate) {
      observer.check_cancel();
      std::this_thread::sleep_for(1ms);
    }
    std::this_thread::sleep_for(2ms);
    StepResult r;
    r.validate = false;
    return r;
  });
  WorkerOptions options;
  options.max_steps = 1000000;
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::Run{});
  worker.wait_for([](const Snapshot& x) { return x.iteration >= 3; }, 5s);
  const auto pause_seq = worker.send(cmd::Pause{});
  auto s = worker.wait_for(
      [&](const Snapshot& x) { return x.applied_seq >= pause_seq && is(x, WorkerStatus::Paused); },
      5s);
  ASSERT_EQ(s->status, WorkerStatus::Paused);
  const int paused_at = s->iteration;
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(worker.latest()->iteration, paused_at);  // nothing runs while paused

  worker.send(cmd::Step{2});
  s = worker.wait_for([&](const Snapshot& x) { return x.iteration >= paused_at + 2; }, 5s);
  EXPECT_EQ(s->iteration, paused_at + 2);
  std::this_thread::sleep_for(30ms);
  EXPECT_EQ(worker.latest()->iteration, paused_at + 2);
  EXPECT_EQ(worker.latest()->status, WorkerStatus::Paused);
}

TEST(Worker, ShutsDownCleanlyDuringALongStep) {
  std::atomic<int> entered{0};
  const auto start = std::chrono::steady_clock::now();
  {
    Worker worker([&](WorkerState&, const WorkerObserver& observer) {
      ++entered;
      for (;;) {  // only cancellation ends this step
        observer.check_cancel();
        std::this_thread::sleep_for(1ms);
      }
      return StepResult{};
    });
    worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
    worker.send(cmd::Run{});
    for (int i = 0; i < 5000 && entered == 0; ++i) std::this_thread::sleep_for(1ms);
    ASSERT_GT(entered.load(), 0);
  }  // ~Worker must return promptly
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
}

// A fake step that moves two nodes along x and reports metrics, like the editor's job.
StepResult moving_nodes_step(WorkerState& state, const WorkerObserver&) {
  StepResult r;
  r.energy = 10.0 / (1 + state.iteration);
  r.validate = false;
  r.metrics.valid = true;
  r.metrics.E = r.energy;
  r.metrics.E_confor = 2.0 + state.iteration;
  r.metrics.foldovers = state.iteration;
  r.metrics.total_ms = 1.0;
  auto frame = std::make_shared<NodeFrame>();
  frame->ids = {7, 9};
  frame->positions = {{float(state.iteration), 0, 0}, {float(state.iteration), 1, 0}};
  r.nodes = frame;
  if (state.iteration + 1 == state.options.max_steps) {
    auto quads = std::make_shared<QuadOverlay>();
    quads->vertices = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    quads->quads = {{0, 1, 2, 3}};
    r.quads = quads;
  }
  return r;
}

TEST(WorkerHistory, GrowsByOneNodeFramePerStepWithMetrics) {
  Worker worker(moving_nodes_step);
  WorkerOptions options;
  options.max_steps = 5;
  options.publish_interval_ms = 0;
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  EXPECT_TRUE(worker.wait_for([](const Snapshot& x) { return x.mesh != nullptr; }, 5s)
                  ->node_history.empty());
  // Step by step: the history grows by exactly one frame per step.
  for (int step = 1; step <= 3; ++step) {
    worker.send(cmd::Step{});
    const auto s = worker.wait_for([&](const Snapshot& x) { return x.iteration >= step; }, 5s);
    ASSERT_EQ(s->iteration, step);
    ASSERT_EQ(s->node_history.size(), std::size_t(step));
    const NodeFrame& last = *s->node_history.back();
    ASSERT_EQ(last.ids, (std::vector<int>{7, 9}));
    EXPECT_FLOAT_EQ(last.positions[0][0], float(step - 1));
    EXPECT_DOUBLE_EQ(s->energy_init, 10.0);
    ASSERT_TRUE(s->metrics.valid);
    EXPECT_DOUBLE_EQ(s->metrics.E_confor, 2.0 + (step - 1));
    EXPECT_EQ(s->metrics.foldovers, step - 1);
    EXPECT_FALSE(s->quads);  // built at the final step only
  }
  worker.send(cmd::Run{});
  const auto s =
      worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Finished); }, 5s);
  ASSERT_EQ(s->status, WorkerStatus::Finished);
  ASSERT_EQ(s->node_history.size(), 5u);
  for (int k = 0; k < 5; ++k) EXPECT_FLOAT_EQ(s->node_history[k]->positions[1][0], float(k));
  ASSERT_TRUE(s->quads);
  EXPECT_EQ(s->quads->quads.size(), 1u);
  EXPECT_DOUBLE_EQ(s->energy_init, 10.0);
  EXPECT_DOUBLE_EQ(s->metrics.E, 2.0);

  // A new job starts a fresh history.
  worker.send(cmd::Stop{});
  const auto stopped =
      worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Cancelled); }, 5s);
  EXPECT_TRUE(stopped->node_history.empty());
  EXPECT_FALSE(stopped->quads);
  EXPECT_FALSE(stopped->metrics.valid);
  EXPECT_TRUE(std::isnan(stopped->energy_init));
}

TEST(WorkerHistory, StepResultWithoutFramesKeepsHistoryAndMetrics) {
  std::atomic<int> calls{0};
  Worker worker([&](WorkerState& state, const WorkerObserver& observer) {
    StepResult r = moving_nodes_step(state, observer);
    if (calls++ % 2 == 1) {  // every second step reports nothing new
      r.nodes.reset();
      r.metrics = StepMetrics{};
    }
    return r;
  });
  WorkerOptions options;
  options.max_steps = 4;
  options.publish_interval_ms = 0;
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::Run{});
  const auto s =
      worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Finished); }, 5s);
  ASSERT_EQ(s->status, WorkerStatus::Finished);
  EXPECT_EQ(s->node_history.size(), 2u);
  ASSERT_TRUE(s->metrics.valid);
  EXPECT_DOUBLE_EQ(s->metrics.E_confor, 2.0 + 2);  // from step 3, kept through step 4
}

TEST(WorkerHistory, ScrubIndexStaysInBounds) {
  using app::scrub_index;
  EXPECT_EQ(scrub_index(3, 0, false), -1);
  EXPECT_EQ(scrub_index(-1, 0, true), -1);
  EXPECT_EQ(scrub_index(-1, 5, true), 4);  // live: newest
  EXPECT_EQ(scrub_index(2, 5, true), 4);
  EXPECT_EQ(scrub_index(2, 5, false), 2);  // scrubbed: kept while steps stream in
  EXPECT_EQ(scrub_index(2, 9, false), 2);
  EXPECT_EQ(scrub_index(7, 5, false), 4);  // history shrank (new job): clamped
  EXPECT_EQ(scrub_index(-3, 5, false), 0);
}

TEST(WorkerHistory, LivePinIsAppliedAtTheNextStep) {
  std::atomic<bool> release{false};
  Worker worker([&](WorkerState& state, const WorkerObserver& observer) {
    while (!release) {
      observer.check_cancel();
      std::this_thread::sleep_for(1ms);
    }
    return moving_nodes_step(state, observer);
  });
  WorkerOptions options;
  options.max_steps = 3;
  options.publish_interval_ms = 0;
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{tetrahedron(), Layout{}});
  worker.send(cmd::Run{});
  std::this_thread::sleep_for(20ms);  // the first step is running
  const auto pin_seq = worker.send(cmd::SetPin{7, 2});
  // Not applied while the step that was running when it was sent is not done.
  EXPECT_LT(worker.latest()->applied_seq, pin_seq);
  release = true;
  const auto s = worker.wait_for(
      [&](const Snapshot& x) { return x.applied_seq >= pin_seq || is(x, WorkerStatus::Finished); },
      5s);
  ASSERT_GE(s->applied_seq, pin_seq);
  ASSERT_EQ(s->pins.size(), 1u);
  EXPECT_EQ(s->pins[0], (std::array<int, 2>{7, 2}));
  const auto clear_seq = worker.send(cmd::ClearPin{7});
  const auto f =
      worker.wait_for([](const Snapshot& x) { return is(x, WorkerStatus::Finished); }, 5s);
  if (f->applied_seq >= clear_seq) {
    EXPECT_TRUE(f->pins.empty());
  }
}

}  // namespace
}  // namespace qs
