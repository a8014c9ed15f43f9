// Live solves while a node is dragged, through the editor's state without a window
// (app/gui/editor.h, job_control.h) on the bundled example: the result shown follows the drag,
// what is shown after the release is the solve of the released layout (as Run without node
// optimization computes it on a fresh worker), undo and redo bring back the results shown
// before and after the drag, drag positions issued faster than they are solved supersede each
// other, an invalid position shows its issues instead of a solve, and the option turns it off.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <set>
#include <thread>
#include <vector>

#include "app/gui/editor.h"
#include "app/gui/pipeline_job.h"
#include "tests/gui_editor_fixture.h"
#include "tests/scoped_env.h"

namespace qs::app {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kAssets = QS_ASSETS_DIR;

class GuiDrag : public ::testing::Test {
 protected:
  GuiDrag()
      : sandbox_("qs_gui_drag", ::testing::UnitTest::GetInstance()->current_test_info()->name()) {}
  static EditorConfig config() { return test::editor_test_config(); }
  static bool poll_until(Editor& editor, const std::function<bool()>& done,
                         std::chrono::seconds timeout = 120s) {
    return test::poll_editor_until(editor, done, timeout);
  }
  // The next drag position of node \p id from its vertex: a free neighbouring vertex farther
  // from \p origin, at which the layout stays valid. Moves the node there; false when there is
  // none.
  static bool step_away(Editor& editor, int id, int origin) {
    const TriMesh& mesh = *editor.doc.mesh;
    const Layout& layout = editor.doc.editor.layout();
    const int current = layout.nodes[layout.node_index(id)].vertex;
    const auto point = [&](int v) { return mesh.point(OpenMesh::VertexHandle(v)); };
    std::vector<std::pair<double, int>> candidates;
    for (const auto vh : mesh.vv_range(OpenMesh::VertexHandle(current)))
      candidates.push_back({-(point(vh.idx()) - point(origin)).norm(), vh.idx()});
    std::sort(candidates.begin(), candidates.end());
    for (const auto& [minus_d, v] : candidates) {
      if (-minus_d <= (point(current) - point(origin)).norm()) break;
      const std::uint64_t version = editor.doc.editor.version();
      if (!editor.drag_to(v) || editor.doc.editor.version() == version) continue;
      if (editor.doc.validation.errors() == 0) return true;
    }
    return false;
  }
  // A node of the example layout that is not pinned, and its vertex.
  static int free_node(const Editor& editor) {
    for (const auto& n : editor.doc.editor.layout().nodes)
      if (!n.pinned) return n.id;
    return -1;
  }
  // Run without node optimization on \p layout, on a fresh worker.
  static SnapshotPtr fresh_solve(const Editor& editor, const Layout& layout) {
    Worker worker(editor_step_function(0));
    WorkerOptions options = editor.job.options;
    options.node_optimization = false;
    worker.send(cmd::SetOptions{options});
    worker.send(cmd::LoadMesh{editor.doc.mesh, layout});
    worker.send(cmd::Run{});
    return worker.wait_for(
        [](const Snapshot& x) {
          return x.status == WorkerStatus::Finished || x.status == WorkerStatus::Failed;
        },
        120s);
  }
  static double max_uv_difference(const Snapshot& a, const Snapshot& b) {
    if (a.corner_uv.size() != b.corner_uv.size()) return INFINITY;
    double d = 0;
    for (std::size_t k = 0; k < a.corner_uv.size(); ++k)
      for (int c = 0; c < 2; ++c)
        d = std::max(d, double(std::abs(a.corner_uv[k][c] - b.corner_uv[k][c])));
    return d;
  }
  static int vertex_of(const Layout& layout, int id) {
    const int k = layout.node_index(id);
    return k < 0 ? -1 : layout.nodes[k].vertex;
  }

  test::EditorSandbox sandbox_;
};

// A scripted drag: the result shown changes with the drag, the release shows the solve of the
// released layout (the same as a fresh Run without node optimization), undo restores the layout
// and the result shown before the drag, redo the one after it.
TEST_F(GuiDrag, ShownSolveFollowsTheDragAndUndoRestoresTheStateBefore) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  ASSERT_TRUE(editor.live_solve);  // on by default
  // Before the drag: the solve of the example layout (Run without node optimization).
  editor.job.options.node_optimization = false;
  editor.run();
  ASSERT_TRUE(poll_until(editor, [&] {
    return editor.job.latest()->status == WorkerStatus::Finished && editor.result();
  }));
  const SnapshotPtr before = editor.job.shown_snapshot(editor.doc);
  ASSERT_TRUE(before);
  const Layout layout_before = editor.doc.editor.layout();

  const int id = free_node(editor);
  ASSERT_GE(id, 0);
  const int origin = vertex_of(layout_before, id);
  ASSERT_TRUE(editor.begin_drag(id));
  // Three drag positions, each shown before the next: the energy shown changes.
  std::set<double> energies;
  std::vector<int> shown_vertices;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(step_away(editor, id, origin)) << "position " << k;
    ASSERT_TRUE(step_away(editor, id, origin)) << "position " << k;
    const int at = vertex_of(editor.doc.editor.layout(), id);
    ASSERT_TRUE(poll_until(editor,
                           [&] {
                             const Snapshot* s = editor.result();
                             return s && s->layout && vertex_of(*s->layout, id) == at;
                           }))
        << "no solve shown for position " << k;
    const Snapshot* s = editor.result();
    EXPECT_EQ(editor.result_kind(), ResultKind::Live);
    EXPECT_FALSE(s->corner_uv.empty());
    EXPECT_TRUE(s->metrics.valid);
    energies.insert(s->energy);
    shown_vertices.push_back(at);
  }
  EXPECT_GE(energies.size(), 2u) << "the energy shown did not change during the drag";
  EXPECT_TRUE(editor.job.live());

  // Release: the solve of the released layout, equal to a fresh solve of it.
  editor.end_drag();
  const Layout released = editor.doc.editor.layout();
  EXPECT_NE(vertex_of(released, id), origin);
  ASSERT_TRUE(poll_until(editor, [&] { return !editor.job.live(); }));
  const SnapshotPtr after = editor.job.shown_snapshot(editor.doc);
  ASSERT_TRUE(after);
  EXPECT_EQ(after->status, WorkerStatus::Finished);
  EXPECT_EQ(vertex_of(*after->layout, id), vertex_of(released, id));
  const SnapshotPtr fresh = fresh_solve(editor, released);
  ASSERT_TRUE(fresh);
  ASSERT_EQ(fresh->status, WorkerStatus::Finished) << fresh->message;
  EXPECT_EQ(bool(after->quads), bool(fresh->quads)) << "the release's solve is Run's";
  EXPECT_NEAR(after->energy, fresh->energy, 1e-9 * std::max(1.0, std::abs(fresh->energy)));
  EXPECT_LE(max_uv_difference(*after, *fresh), 1e-6);
  EXPECT_EQ(after->metrics.foldovers, fresh->metrics.foldovers);
  EXPECT_EQ(after->message, fresh->message);
  // The other nodes stayed where they were.
  for (const auto& n : layout_before.nodes)
    if (n.id != id) {
      EXPECT_EQ(vertex_of(*after->layout, n.id), n.vertex) << "node " << n.id;
    }
  // Still shown a while later (nothing stale arrives).
  for (int k = 0; k < 20; ++k) {
    editor.poll();
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(editor.result(), after.get());

  // Undo: the layout and the result shown before the drag.
  editor.undo();
  EXPECT_EQ(vertex_of(editor.doc.editor.layout(), id), origin);
  EXPECT_EQ(editor.result(), before.get());
  ASSERT_TRUE(poll_until(editor, [&] { return editor.job.latest()->iteration == 0; }));
  for (int k = 0; k < 10; ++k) editor.poll();
  EXPECT_EQ(editor.result(), before.get()) << "the worker's new state replaced the restored one";
  // Redo: the released layout and its solve.
  editor.redo();
  EXPECT_EQ(vertex_of(editor.doc.editor.layout(), id), vertex_of(released, id));
  EXPECT_EQ(editor.result(), after.get());
}

// Positions issued faster than they are solved: at most one solve in flight, the newest
// position next; the last solve shown is that of the last position.
TEST_F(GuiDrag, NewerPositionsSupersedePendingOnes) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  const int id = free_node(editor);
  ASSERT_GE(id, 0);
  const int origin = vertex_of(editor.doc.editor.layout(), id);
  ASSERT_TRUE(editor.begin_drag(id));
  int positions = 0;
  std::vector<int> path;
  for (int k = 0; k < 40 && step_away(editor, id, origin); ++k) {
    ++positions;
    path.push_back(vertex_of(editor.doc.editor.layout(), id));
  }
  ASSERT_GE(positions, 4);
  // And back over the same (valid) positions, still without polling.
  for (auto it = path.rbegin() + 1; it != path.rend(); ++it) {
    ASSERT_TRUE(editor.drag_to(*it));
    ASSERT_EQ(editor.doc.validation.errors(), 0);
    ++positions;
  }
  const JobControl::LiveStats& stats = editor.job.live_stats();
  EXPECT_EQ(stats.requests, positions);
  EXPECT_EQ(stats.sent, 1) << "requests were sent while a solve was in flight";
  const int last = vertex_of(editor.doc.editor.layout(), id);
  ASSERT_TRUE(poll_until(editor, [&] {
    const Snapshot* s = editor.result();
    return s && s->layout && vertex_of(*s->layout, id) == last;
  }));
  EXPECT_LE(stats.sent, 2);
  EXPECT_LE(stats.shown, 2);
  editor.end_drag();
  ASSERT_TRUE(poll_until(editor, [&] { return !editor.job.live(); }));
  EXPECT_LE(stats.sent, 3);
  EXPECT_LT(stats.sent * 3, positions);
  ASSERT_TRUE(editor.result());
  EXPECT_EQ(vertex_of(*editor.result()->layout, id), last);
}

// Esc during a live drag: the node goes back, and so does the result shown (none here).
TEST_F(GuiDrag, CancelRestoresTheResultShownBefore) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  const int id = free_node(editor);
  const int origin = vertex_of(editor.doc.editor.layout(), id);
  ASSERT_TRUE(editor.begin_drag(id));
  ASSERT_TRUE(step_away(editor, id, origin));
  ASSERT_TRUE(poll_until(editor, [&] { return editor.result() != nullptr; }));
  editor.cancel_drag();
  EXPECT_EQ(vertex_of(editor.doc.editor.layout(), id), origin);
  EXPECT_EQ(editor.result(), nullptr);
  EXPECT_FALSE(editor.job.live());
  for (int k = 0; k < 20; ++k) {
    editor.poll();
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(editor.result(), nullptr);
}

// A drag position where the layout is invalid shows its validation issues, not a solve: here
// the example without arc 10 (a 6-sided patch) at every position.
TEST_F(GuiDrag, InvalidPositionShowsItsIssuesInsteadOfASolve) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  ASSERT_TRUE(editor.doc.editor.delete_arc(10));
  editor.poll();
  ASSERT_GT(editor.doc.validation.errors(), 0);
  const int id = free_node(editor);
  const int origin = vertex_of(editor.doc.editor.layout(), id);
  ASSERT_TRUE(editor.begin_drag(id));
  bool moved = false;
  for (const auto vh : editor.doc.mesh->vv_range(OpenMesh::VertexHandle(origin))) {
    const std::uint64_t version = editor.doc.editor.version();
    if (editor.drag_to(vh.idx()) && editor.doc.editor.version() != version) {
      moved = true;
      break;
    }
  }
  ASSERT_TRUE(moved);
  EXPECT_GT(editor.doc.validation.errors(), 0);
  EXPECT_EQ(editor.status().rfind("Invalid here: ", 0), 0u) << editor.status();
  EXPECT_TRUE(editor.job.live());
  for (int k = 0; k < 20; ++k) {
    editor.poll();
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(editor.result(), nullptr);
  EXPECT_EQ(editor.job.live_stats().sent, 0);
  editor.end_drag();
  for (int k = 0; k < 20; ++k) {
    editor.poll();
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_FALSE(editor.job.live());
  EXPECT_EQ(editor.result(), nullptr);
  EXPECT_EQ(editor.job.live_stats().sent, 0);
  EXPECT_GT(editor.doc.validation.errors(), 0);
}

// With "Live solve while dragging" off, a drag solves nothing; the release is a plain edit.
TEST_F(GuiDrag, OptionOffSolvesNothing) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  editor.live_solve = false;
  const int id = free_node(editor);
  const int origin = vertex_of(editor.doc.editor.layout(), id);
  ASSERT_TRUE(editor.begin_drag(id));
  ASSERT_TRUE(step_away(editor, id, origin));
  ASSERT_TRUE(step_away(editor, id, origin));
  editor.end_drag();
  for (int k = 0; k < 50; ++k) {
    editor.poll();
    std::this_thread::sleep_for(5ms);
  }
  EXPECT_EQ(editor.job.live_stats().sent, 0);
  EXPECT_EQ(editor.result(), nullptr);
  EXPECT_NE(vertex_of(editor.doc.editor.layout(), id), origin);
}

}  // namespace
}  // namespace qs::app
