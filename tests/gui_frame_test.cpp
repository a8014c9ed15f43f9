// The editor's frame bookkeeping (GL-free): frame statistics and the snapshot lag counter,
// the solver threads' priority, and (with the render library, QS_TEST_RENDER) the key that
// decides whether the cached scene image is reused.
#include <gtest/gtest.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "app/gui/frame_stats.h"
#include "app/gui/thread_priority.h"

#ifdef QS_TEST_RENDER
#include "render/scene_cache.h"
#endif

#if defined(__linux__)
#include <unistd.h>
#endif

namespace qs::app {
namespace {

TEST(GuiFrameStats, SummaryOfFrameTimes) {
  FrameStats stats;
  for (int i = 1; i <= 100; ++i) stats.add_frame(double(i), i % 4 == 0, 0, 0);
  const FrameSummary s = stats.summary();
  EXPECT_EQ(s.frames, 100);
  EXPECT_DOUBLE_EQ(s.mean_ms, 50.5);
  EXPECT_DOUBLE_EQ(s.p95_ms, 95.0);
  EXPECT_DOUBLE_EQ(s.max_ms, 100.0);
  EXPECT_NEAR(s.fps, 1000.0 / 50.5, 1e-9);
  EXPECT_EQ(s.scene_renders, 25);
  EXPECT_EQ(s.snapshots_drawn, 0);
  EXPECT_EQ(s.max_snapshot_lag, 0);
  EXPECT_NE(format_frame_summary(s).find("scene rendered in 25 of 100 frames"), std::string::npos);
}

TEST(GuiFrameStats, SnapshotPublishedDuringAFrameIsDrawnByTheNext) {
  FrameStats stats;
  // Frame 1 draws version 1; version 2 is published while it renders.
  stats.add_frame(10, true, 1, 2);
  // Frame 2 polls and draws version 2: one frame after publication.
  stats.add_frame(10, true, 2, 2);
  stats.add_frame(10, false, 2, 2);
  FrameSummary s = stats.summary();
  EXPECT_EQ(s.snapshots_drawn, 1);
  EXPECT_EQ(s.max_snapshot_lag, 1);
  EXPECT_EQ(s.snapshots_waited, 1);

  // A UI that misses versions: 3 is published after frame 4 but only drawn by frame 7 (which
  // already shows 4, published meanwhile).
  stats.add_frame(10, false, 2, 3);
  stats.add_frame(10, false, 2, 3);
  stats.add_frame(10, false, 2, 4);
  stats.add_frame(10, true, 4, 4);
  s = stats.summary();
  EXPECT_EQ(s.snapshots_drawn, 2);
  EXPECT_EQ(s.max_snapshot_lag, 3);
  EXPECT_EQ(s.snapshots_waited, 2);
}

TEST(GuiFrameStats, WarmUpIsForgottenButAPendingSnapshotIsNot) {
  FrameStats stats;
  stats.add_frame(500, true, 1, 1);  // shader compilation
  stats.add_frame(10, true, 1, 2);   // version 2 published during this frame
  stats.clear_times();
  stats.add_frame(10, true, 2, 2);
  const FrameSummary s = stats.summary();
  EXPECT_EQ(s.frames, 1);
  EXPECT_DOUBLE_EQ(s.max_ms, 10.0);
  EXPECT_EQ(s.max_snapshot_lag, 1);
  EXPECT_EQ(s.snapshots_drawn, 1);
}

#if defined(__linux__)
TEST(GuiThreadPriority, SolverThreadsDropBelowTheMainThread) {
  const int main_tid = int(::getpid());
  const int main_nice = thread_nice(main_tid);
  if (main_nice >= 5) GTEST_SKIP() << "the test process already runs at nice " << main_nice;

  // A bystander thread, like a math library's pool started before the solver: lowered too.
  std::mutex mutex;
  std::condition_variable cv;
  bool release = false;
  std::atomic<int> bystander_tid{0};
  std::thread bystander([&] {
    bystander_tid = current_thread_id();
    std::unique_lock lock(mutex);
    cv.wait(lock, [&] { return release; });
  });
  while (bystander_tid == 0) std::this_thread::yield();

  int solver_nice = -100, child_nice = -100, changed = 0;
  std::thread solver([&] {
    changed = lower_solver_thread_priority(5);
    solver_nice = thread_nice(current_thread_id());
    // Threads the solver starts later (OpenMP teams) inherit its priority.
    std::thread child([&] { child_nice = thread_nice(current_thread_id()); });
    child.join();
  });
  solver.join();
  const int bystander_nice = thread_nice(bystander_tid);
  {
    std::lock_guard lock(mutex);
    release = true;
  }
  cv.notify_all();
  bystander.join();

  EXPECT_GE(changed, 2);  // the solver and the bystander
  EXPECT_GE(solver_nice, 5);
  EXPECT_GE(child_nice, 5);
  EXPECT_GE(bystander_nice, 5);
  EXPECT_EQ(thread_nice(main_tid), main_nice) << "the UI (main) thread must keep its priority";
  EXPECT_EQ(lower_solver_thread_priority(0), 0) << "0 leaves priorities alone";
}
#endif

#ifdef QS_TEST_RENDER
TEST(GuiSceneKey, ChangesWithEverythingTheSceneShows) {
  render::SceneData scene;
  std::vector<std::array<float, 2>> uv(6, {0.0f, 0.0f});
  scene.corner_uv = &uv;
  scene.param_version = 3;
  scene.preview_path = {1, 2, 3};
  auto key_of = [](const render::SceneData& s) {
    render::FrameKey key;
    render::add_scene(key, s);
    return key.value();
  };
  const std::uint64_t base = key_of(scene);
  EXPECT_EQ(key_of(scene), base) << "the key must be deterministic";

  render::SceneData changed = scene;
  changed.param_version = 4;  // a new parameterization (a new snapshot)
  EXPECT_NE(key_of(changed), base);
  changed = scene;
  changed.hovered_node = 7;  // hover highlight
  EXPECT_NE(key_of(changed), base);
  changed = scene;
  changed.preview_path.push_back(4);  // the arc tool's route preview
  EXPECT_NE(key_of(changed), base);
  changed = scene;
  changed.stroke_points.emplace_back(0.1f, 0.2f, 0.3f);  // a stroke being drawn
  EXPECT_NE(key_of(changed), base);
  changed = scene;
  changed.pin_overrides.emplace_back(2, true);  // a pin sent to the worker
  EXPECT_NE(key_of(changed), base);
  changed = scene;
  changed.history_step = 5;  // the step slider
  EXPECT_NE(key_of(changed), base);

  render::FrameKey a, b;
  a.add(1.0f);
  b.add(1.0f + 1e-6f);  // a camera that moved a tiny bit
  EXPECT_NE(a.value(), b.value());
}
#endif

}  // namespace
}  // namespace qs::app
