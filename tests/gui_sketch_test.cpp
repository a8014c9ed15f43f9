// The editor's sketching aids without a window (app/gui/sketch_edits.h, symmetry_state.h,
// field_hints.h, layout_editor.h's groups): mirrored sketching on the bundled ellipsoid (a
// mirrored sketch is a symmetric layout, every edit and its mirror are one undo step, nodes
// near the plane go onto it, a mirror image whose place is taken refuses the edit), edge loops
// inserted and removed through the editor, and the field hints computed off the UI thread.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <optional>
#include <thread>

#include "app/gui/editor.h"
#include "app/gui/pipeline_job.h"
#include "app/gui/sketch_edits.h"
#include "core/layout/layout_io.h"
#include "core/layout/routing.h"
#include "core/layout/symmetry.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/symmetric_step.h"
#include "tests/fixtures.h"
#include "tests/gui_editor_fixture.h"
#include "tests/scoped_env.h"
#ifdef QS_TEST_RENDER
#include "render/guide_layer.h"
#endif

namespace qs::app {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kAssets = QS_ASSETS_DIR;
const fs::path kExampleMesh = kAssets / "example" / "ellipsoid.obj";
const fs::path kExactLayout = kAssets / "example" / "ellipsoid_exact.layout.json";

// Own home, config and autosave folders (the editor autosaves every edit).
class GuiSketch : public ::testing::Test {
 protected:
  GuiSketch()
      : sandbox_("qs_gui_sketch", ::testing::UnitTest::GetInstance()->current_test_info()->name()),
        dir_(sandbox_.dir()) {}
  static EditorConfig config() { return test::editor_test_config(); }
  static bool poll_until(Editor& editor, const std::function<bool()>& done,
                         std::chrono::seconds timeout = 60s) {
    return test::poll_editor_until(editor, done, timeout);
  }
  // The example mesh with an empty layout and mirrored sketching about x = 0.
  static void start_mirrored(Editor& editor) {
    ASSERT_TRUE(editor.start(kExampleMesh.string(), ""));
    editor.symmetry.enable(SymmetryAxis::X);
    ASSERT_TRUE(poll_until(editor, [&] { return editor.mirror() != nullptr; }));
  }

  test::EditorSandbox sandbox_;
  const fs::path dir_;
};

const TriMesh& mesh_of(const Editor& editor) {
  return *editor.doc.mesh;
}

Vec3 position(const TriMesh& mesh, int v) {
  return mesh.point(OpenMesh::VertexHandle(v));
}

int nearest_vertex(const TriMesh& mesh, const Vec3& p) {
  int best = -1;
  double best_d = 1e300;
  for (const auto vh : mesh.vertices())
    if (const double d = (mesh.point(vh) - p).sqrnorm(); d < best_d) {
      best_d = d;
      best = vh.idx();
    }
  return best;
}

// The vertices exactly \p rings edge rings away from vertex \p v.
std::vector<int> ring_vertices(const TriMesh& mesh, int v, int rings) {
  std::vector<int> depth(mesh.n_vertices(), -1);
  std::vector<int> front{v};
  depth[v] = 0;
  for (int r = 1; r <= rings; ++r) {
    std::vector<int> next;
    for (int u : front)
      for (const auto wh : mesh.vv_range(OpenMesh::VertexHandle(u)))
        if (depth[wh.idx()] < 0) {
          depth[wh.idx()] = r;
          next.push_back(wh.idx());
        }
    front = std::move(next);
  }
  return front;
}

// The layout must pair up about the plane within 1e-6 of the diagonal.
void expect_symmetric(const Editor& editor) {
  SymmetryPairOptions options;
  options.tolerance = 1e-6;
  options.edge_lengths = 0.0;
  const SymmetryPairs pairs = match_mirror_pairs(mesh_of(editor), editor.doc.editor.layout(),
                                                 editor.mirror()->plane, options);
  EXPECT_TRUE(pairs.symmetric()) << pairs.problem;
  EXPECT_LT(pairs.node_error, 1e-6);
  EXPECT_LT(pairs.arc_error, 1e-6);
}

TEST_F(GuiSketch, GroupIsOneUndoStepAndAFailedGroupChangesNothing) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(), ""));
  LayoutEditor& e = editor.doc.editor;
  ASSERT_TRUE(e.add_node(10));
  ASSERT_TRUE(e.add_node(20));
  ASSERT_TRUE(e.undo());  // a redo branch that a failed group must keep
  const std::size_t history = e.history_size();
  const Layout before = e.layout();
  const EditResult failed = e.group("two nodes", [&] {
    EXPECT_TRUE(e.add_node(30));
    return EditResult::fail("no");
  });
  EXPECT_FALSE(failed);
  EXPECT_EQ(e.layout().nodes.size(), before.nodes.size());
  EXPECT_EQ(e.history_size(), history);
  EXPECT_TRUE(e.can_redo());
  const EditResult ok = e.group("two nodes", [&] {
    EXPECT_TRUE(e.add_node(30));
    return e.add_node(40);
  });
  EXPECT_TRUE(ok);
  EXPECT_EQ(e.layout().nodes.size(), before.nodes.size() + 2);
  EXPECT_EQ(e.undo_label(), "two nodes");
  ASSERT_TRUE(e.undo());
  EXPECT_EQ(e.layout().nodes.size(), before.nodes.size());
}

TEST_F(GuiSketch, AMirroredSketchIsASymmetricLayout) {
  Editor editor(config());
  start_mirrored(editor);
  const TriMesh& mesh = mesh_of(editor);
  const Mirror& m = *editor.mirror();
  EXPECT_LT(editor.symmetry.fit()->relative, 1e-12);  // the example is exactly symmetric
  LayoutEditor& e = editor.doc.editor;
  // A node on the +x side: its mirror appears; a node clicked next to the plane goes onto it.
  const int side = nearest_vertex(mesh, Vec3(1.2, 0.1, 0.55));
  const EditResult a = sketch_add_node(e, &m, side);
  ASSERT_TRUE(a) << a.error;
  EXPECT_EQ(e.layout().nodes.size(), 2u);
  // Near the top, the vertex nearest to the plane but off it (one row over): with a snap
  // distance that reaches it, the node goes onto the plane.
  int near_top = -1;
  for (const auto vh : mesh.vertices()) {
    const double d = std::abs(m.plane.signed_distance(mesh.point(vh)));
    if (d > 0.0 && mesh.point(vh)[1] > 0.0 &&
        (near_top < 0 || (mesh.point(vh) - Vec3(0, 1, 0)).norm() <
                             (position(mesh, near_top) - Vec3(0, 1, 0)).norm()))
      near_top = vh.idx();
  }
  ASSERT_GE(near_top, 0);
  Mirror wide = m;
  wide.snap = 1.01 * std::abs(m.plane.signed_distance(position(mesh, near_top)));
  const EditResult top = sketch_add_node(e, &wide, near_top);
  ASSERT_TRUE(top) << top.error;
  const EditResult bottom = sketch_add_node(e, &m, nearest_vertex(mesh, Vec3(0.0, -1.0, 0.0)));
  ASSERT_TRUE(bottom) << bottom.error;
  EXPECT_EQ(e.layout().nodes.size(), 4u);  // the plane nodes have no twin
  for (int id : {top.id, bottom.id}) {
    const int v = e.layout().nodes[e.layout().node_index(id)].vertex;
    EXPECT_LT(std::abs(m.plane.signed_distance(position(mesh, v))), 1e-12) << "node " << id;
  }
  // Arcs from the side node to both plane nodes, each mirrored: one undo step each.
  const std::size_t steps = e.history_size();
  ASSERT_TRUE(sketch_add_arc(e, &m, a.id, top.id));
  EXPECT_EQ(e.history_size(), steps + 1);
  EXPECT_EQ(e.layout().arcs.size(), 2u);
  ASSERT_TRUE(sketch_add_arc(e, &m, a.id, bottom.id));
  EXPECT_EQ(e.layout().arcs.size(), 4u);
  editor.poll();
  expect_symmetric(editor);
  EXPECT_TRUE(validate_layout(mesh, e.layout()).valid());  // a ring: two 4-sided patches
  ASSERT_TRUE(e.undo());
  EXPECT_EQ(e.layout().arcs.size(), 2u);  // the arc and its mirror went together
  ASSERT_TRUE(e.redo());
  expect_symmetric(editor);

  // Split, move, pin: mirrored.
  const LayoutArc arc0 = e.layout().arcs[0];
  ASSERT_GE(arc0.path.size(), 3u);
  const EditResult split = sketch_split_arc(e, &m, arc0.id, arc0.path[arc0.path.size() / 2]);
  ASSERT_TRUE(split) << split.error;
  EXPECT_EQ(e.layout().arcs.size(), 6u);
  expect_symmetric(editor);
  const int moved_to = nearest_vertex(mesh, Vec3(1.3, -0.1, 0.45));
  const EditResult move = sketch_move_node(e, &m, a.id, moved_to);
  ASSERT_TRUE(move) << move.error;
  EXPECT_EQ(e.layout().nodes[e.layout().node_index(a.id)].vertex, moved_to);
  expect_symmetric(editor);
  editor.toggle_node_pin(a.id);
  const int twin = mirror_node_id(mesh, e.layout(), m, a.id);
  ASSERT_GE(twin, 0);
  EXPECT_NE(twin, a.id);
  EXPECT_TRUE(e.layout().nodes[e.layout().node_index(twin)].pinned);
  // A plane node moved stays on the plane.
  const EditResult slide =
      sketch_move_node(e, &m, top.id, nearest_vertex(mesh, Vec3(0.3, 0.95, 0.3)));
  ASSERT_TRUE(slide) << slide.error;
  const int top_vertex = e.layout().nodes[e.layout().node_index(top.id)].vertex;
  EXPECT_LT(std::abs(m.plane.signed_distance(position(mesh, top_vertex))), 1e-12);
  expect_symmetric(editor);
  // Delete: the node, its mirror and their arcs.
  editor.select(a.id, -1);
  editor.delete_selection();
  EXPECT_LT(e.layout().node_index(twin), 0);
  expect_symmetric(editor);
}

TEST_F(GuiSketch, ADraggedNodeTakesItsMirrorAlong) {
  Editor editor(config());
  start_mirrored(editor);
  const TriMesh& mesh = mesh_of(editor);
  const Mirror& m = *editor.mirror();
  LayoutEditor& e = editor.doc.editor;
  const EditResult a = sketch_add_node(e, &m, nearest_vertex(mesh, Vec3(1.2, 0.2, 0.5)));
  const EditResult top = sketch_add_node(e, &m, nearest_vertex(mesh, Vec3(0.0, 1.0, 0.0)));
  ASSERT_TRUE(a && top);
  ASSERT_TRUE(sketch_add_arc(e, &m, a.id, top.id));
  editor.poll();
  const std::size_t steps = e.history_size();
  ASSERT_TRUE(e.begin_drag(a.id));
  for (const Vec3& p : {Vec3(1.25, 0.1, 0.5), Vec3(1.3, 0.0, 0.45), Vec3(1.35, -0.1, 0.4)}) {
    const EditResult r = e.drag_to(nearest_vertex(mesh, p));
    EXPECT_TRUE(r) << r.error;
    expect_symmetric(editor);  // the preview too
  }
  e.end_drag();
  EXPECT_EQ(e.history_size(), steps + 1);
  expect_symmetric(editor);
}

TEST_F(GuiSketch, AMirrorImageWhosePlaceIsTakenRefusesTheEdit) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(), ""));
  const TriMesh& mesh = mesh_of(editor);
  LayoutEditor& e = editor.doc.editor;
  // Without symmetry: an arc on the -x side.
  const EditResult p = e.add_node(nearest_vertex(mesh, Vec3(-1.2, 0.6, 0.3)));
  const EditResult q = e.add_node(nearest_vertex(mesh, Vec3(-1.2, -0.6, 0.3)));
  ASSERT_TRUE(p && q);
  ASSERT_TRUE(e.add_arc(p.id, q.id));
  const LayoutArc arc = e.layout().arcs[0];
  editor.symmetry.enable(SymmetryAxis::X);
  ASSERT_TRUE(poll_until(editor, [&] { return editor.mirror() != nullptr; }));
  const Mirror& m = *editor.mirror();
  // A node whose mirror image falls on that arc.
  const int on_arc = arc.path[arc.path.size() / 2];
  const int v = mirror_vertex(mesh, *m.tree, m.plane, on_arc);
  const Layout before = e.layout();
  const std::size_t steps = e.history_size();
  const EditResult r = sketch_add_node(e, &m, v);
  EXPECT_FALSE(r);
  EXPECT_NE(r.error.find("falls on arc " + std::to_string(arc.id)), std::string::npos) << r.error;
  EXPECT_EQ(e.layout().nodes.size(), before.nodes.size());
  EXPECT_EQ(e.history_size(), steps);
}

TEST_F(GuiSketch, EdgeLoopsAreInsertedAndRemovedThroughTheEditor) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(), kExactLayout.string()));
  editor.poll();
  ASSERT_TRUE(editor.doc.validation.valid());
  const Layout original = editor.doc.editor.layout();
  editor.insert_edge_loop(0);
  editor.poll();
  const Layout& with = editor.doc.editor.layout();
  EXPECT_EQ(with.nodes.size(), original.nodes.size() + 4) << editor.status();
  EXPECT_EQ(with.arcs.size(), original.arcs.size() + 8);
  EXPECT_TRUE(editor.doc.validation.valid());
  EXPECT_EQ(editor.doc.editor.undo_label(), "insert edge loop at arc 0");
  const int patches = int(build_topology(mesh_of(editor), with).patches.size());
  EXPECT_EQ(patches, 10);
  // Remove it again through one of its arcs: the layout before.
  const int loop_arc = with.arcs.back().id;
  editor.remove_edge_loop(loop_arc);
  editor.poll();
  const Layout& back = editor.doc.editor.layout();
  ASSERT_EQ(back.arcs.size(), original.arcs.size()) << editor.status();
  for (std::size_t k = 0; k < back.arcs.size(); ++k) {
    EXPECT_EQ(back.arcs[k].id, original.arcs[k].id);
    EXPECT_EQ(back.arcs[k].path, original.arcs[k].path);
  }
  // A cube edge runs through valence-3 corners: refused, said why, nothing changed.
  const std::size_t steps = editor.doc.editor.history_size();
  editor.remove_edge_loop(0);
  EXPECT_NE(editor.status().find("Not done"), std::string::npos);
  EXPECT_NE(editor.status().find("valence 3"), std::string::npos) << editor.status();
  EXPECT_EQ(editor.doc.editor.history_size(), steps);
}

TEST_F(GuiSketch, MirroredEdgeLoopKeepsTheLayoutSymmetric) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(), kExactLayout.string()));
  editor.symmetry.enable(SymmetryAxis::X);
  ASSERT_TRUE(poll_until(editor, [&] { return editor.mirror() != nullptr; }));
  const SymmetryPairs before =
      match_mirror_pairs(mesh_of(editor), editor.doc.editor.layout(), editor.mirror()->plane);
  ASSERT_TRUE(before.symmetric()) << before.problem;
  // An arc off the plane (its mirror is another arc of the same chord or of its mirror chord).
  const Layout layout = editor.doc.editor.layout();
  int arc = -1;
  for (int a = 0; a < int(layout.arcs.size()) && arc < 0; ++a)
    if (before.arc_mirror[a] != a) arc = layout.arcs[a].id;
  ASSERT_GE(arc, 0);
  editor.insert_edge_loop(arc);
  editor.poll();
  // Every chord of the cube is its own mirror image about x = 0: one loop of 4 nodes, and the
  // status does not claim a mirror loop.
  EXPECT_EQ(editor.doc.editor.layout().nodes.size(), layout.nodes.size() + 4) << editor.status();
  EXPECT_NE(editor.status().find("Edge loop inserted"), std::string::npos) << editor.status();
  EXPECT_EQ(editor.status().find("mirror"), std::string::npos) << editor.status();
  EXPECT_TRUE(editor.doc.validation.valid());
  const SymmetryPairs after =
      match_mirror_pairs(mesh_of(editor), editor.doc.editor.layout(), editor.mirror()->plane);
  EXPECT_TRUE(after.symmetric()) << after.problem;
}

// Run with mirrored sketching on keeps a mirrored sketch symmetric: on the example bent about
// x = 0 (still exactly mirror symmetric, but its lowest E no longer at symmetric cube corners),
// the cube corners with an edge loop in the plane x = 0 (four nodes on the plane) and a corner
// moved two rings (its mirror with it) end with the mirror pairs as mirror images and the plane
// nodes in the plane.
TEST_F(GuiSketch, RunKeepsAMirroredSketchSymmetric) {
  TriMesh bent = load_mesh(kExampleMesh.string());
  for (const auto vh : bent.vertices()) {
    Vec3 p = bent.point(vh);
    p[1] += 0.3 * p[0] * p[0];
    p[2] *= 1 + 0.15 * p[1];
    bent.set_point(vh, p);
  }
  const fs::path bent_path = dir_ / "bent_ellipsoid.obj";
  save_mesh_obj(bent, bent_path.string());
  Editor editor(config());
  ASSERT_TRUE(editor.start(bent_path.string(), kExactLayout.string()));
  editor.symmetry.enable(SymmetryAxis::X);
  ASSERT_TRUE(poll_until(editor, [&] { return editor.mirror() != nullptr; }));
  const TriMesh& mesh = mesh_of(editor);
  const Mirror& m = *editor.mirror();
  LayoutEditor& e = editor.doc.editor;
  const SymmetryPairs cube = match_mirror_pairs(mesh, e.layout(), m.plane);
  int crossing = -1;
  for (int a = 0; a < int(e.layout().arcs.size()) && crossing < 0; ++a)
    if (cube.arc_mirror[a] == a) crossing = e.layout().arcs[a].id;
  ASSERT_GE(crossing, 0);
  editor.insert_edge_loop(crossing);
  ASSERT_EQ(e.layout().nodes.size(), 12u) << editor.status();
  const LayoutNode corner = e.layout().nodes[0];
  bool moved = false;
  for (int v : ring_vertices(mesh, corner.vertex, 2))
    if (sketch_move_node(e, &m, corner.id, v)) {
      moved = true;
      break;
    }
  ASSERT_TRUE(moved);
  editor.poll();
  ASSERT_TRUE(editor.doc.validation.valid());
  expect_symmetric(editor);
  const Layout sketch = e.layout();
  SymmetryPairOptions exact;
  exact.tolerance = 1e-6;
  exact.edge_lengths = 0.0;
  const NodeSymmetry pairs{m.plane, match_mirror_pairs(mesh, sketch, m.plane, exact).node_mirror};

  editor.job.options.publish_interval_ms = 0;
  editor.run();
  ASSERT_TRUE(poll_until(
      editor,
      [&] {
        const SnapshotPtr& s = editor.job.latest();
        return s && (s->status == WorkerStatus::Finished || s->status == WorkerStatus::Failed);
      },
      120s));
  const Snapshot* s = editor.result();
  ASSERT_TRUE(s && s->exports) << editor.job.latest()->message;
  EXPECT_EQ(s->status, WorkerStatus::Finished) << s->message;
  const JobExports& out = *s->exports;
  ASSERT_EQ(out.layout.nodes.size(), sketch.nodes.size());
  double travel = 0;
  for (std::size_t k = 0; k < sketch.nodes.size(); ++k) {
    ASSERT_EQ(out.layout.nodes[k].id, sketch.nodes[k].id);
    travel = std::max(travel, (position(out.mesh, out.layout.nodes[k].vertex) -
                               position(mesh, sketch.nodes[k].vertex))
                                  .norm());
  }
  EXPECT_GT(travel, 0.02);  // the run moved the nodes (the mean edge is 0.14)
  const NodeSymmetryMeasure measure = measure_node_symmetry(out.mesh, out.layout, pairs);
  EXPECT_EQ(measure.pairs, 4);
  EXPECT_EQ(measure.plane_nodes, 4);
  EXPECT_LT(measure.max_pair_error, 1e-6);
  EXPECT_LT(measure.max_plane_error, 1e-6);
  EXPECT_EQ(s->metrics.foldovers, 0);
}

TEST_F(GuiSketch, FieldHintsAreComputedInTheBackgroundOncePerMesh) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(), ""));
  editor.poll();
  EXPECT_FALSE(editor.field_hints.computing());  // not shown: nothing computed
  EXPECT_EQ(editor.field_hints.field(), nullptr);
  editor.field_hints.enabled = true;
  editor.poll();
  EXPECT_TRUE(editor.field_hints.computing() || editor.field_hints.field());
  ASSERT_TRUE(poll_until(editor, [&] { return editor.field_hints.field() != nullptr; }));
  // The example is an ellipsoid: 8 singularities of +1/4 where a cube layout has its corners.
  EXPECT_EQ(editor.field_hints.count(1), 8);
  EXPECT_EQ(editor.field_hints.count(-1), 0);
  const std::uint64_t version = editor.field_hints.version();
  editor.field_hints.enabled = false;
  editor.poll();
  editor.field_hints.enabled = true;
  editor.poll();
  EXPECT_FALSE(editor.field_hints.computing());  // cached
  EXPECT_EQ(editor.field_hints.version(), version);
  // Another mesh: computed again, for it.
  ASSERT_TRUE(editor.open_mesh(kExampleMesh.string()));
  editor.poll();
  EXPECT_EQ(editor.field_hints.field(), nullptr);
  ASSERT_TRUE(poll_until(editor, [&] { return editor.field_hints.field() != nullptr; }));
}

// The hint scale hides pairs of opposite singularities closer than the scale: on a bumpy
// rounded cube, a scale of 0 shows every singularity of the field, the default fewer, with the
// same index sum; a change shows after the next poll without a new field computation.
TEST_F(GuiSketch, HintScaleHidesClosePairs) {
  const auto bumpy = test::bumpy_rounded_cube();
  const fs::path path = dir_ / "bumpy_cube.obj";
  save_mesh_obj(bumpy.mesh, path.string());
  Editor editor(config());
  ASSERT_TRUE(editor.start(path.string(), ""));
  editor.field_hints.enabled = true;
  ASSERT_TRUE(poll_until(editor, [&] { return editor.field_hints.field() != nullptr; }));
  const auto sum = [](const NaturalField& f) {
    int total = 0;
    for (const auto& s : f.singularities) total += s.index;
    return total;
  };
  const std::size_t all = editor.field_hints.raw_field()->singularities.size();
  const std::size_t shown = editor.field_hints.field()->singularities.size();
  EXPECT_LT(shown, all);
  EXPECT_EQ(sum(*editor.field_hints.field()), 8);
  editor.field_hints.set_scale(0.0);
  const std::uint64_t version = editor.field_hints.version();
  ASSERT_TRUE(
      poll_until(editor, [&] { return editor.field_hints.field()->singularities.size() == all; }));
  EXPECT_GT(editor.field_hints.version(), version);
  EXPECT_FALSE(editor.field_hints.computing());  // the field itself is not computed again
  editor.field_hints.set_scale(std::nan(""));    // not a number: the default
  ASSERT_TRUE(poll_until(
      editor, [&] { return editor.field_hints.field()->singularities.size() == shown; }));
  editor.field_hints.set_scale(7.0);  // clamped
  EXPECT_EQ(editor.field_hints.scale(), FieldHints::kMaxScale);
}

TEST_F(GuiSketch, FittedPlaneOfTheExampleHasNoResidual) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(), ""));
  editor.symmetry.enable(SymmetryAxis::Auto);
  ASSERT_TRUE(poll_until(editor, [&] { return editor.mirror() != nullptr; }));
  ASSERT_TRUE(editor.symmetry.fit());
  EXPECT_LT(editor.symmetry.fit()->relative, 1e-9);
  // Shown as the plane it is: rounding noise in the fit is no "-0.000" and no "offset 1e-18".
  const std::string d = editor.symmetry.description();
  EXPECT_NE(d.find("residual"), std::string::npos) << d;
  EXPECT_NE(d.find("offset 0;"), std::string::npos) << d;
  EXPECT_EQ(d.find("-0.000"), std::string::npos) << d;
  editor.symmetry.disable();
  editor.poll();
  EXPECT_EQ(editor.mirror(), nullptr);
}

#ifdef QS_TEST_RENDER
TEST(GuiGuides, PlaneSectionOfTheEllipsoidLiesInThePlane) {
  const TriMesh mesh = load_mesh(kExampleMesh.string());
  const MirrorPlane plane = axis_plane(mesh, 0);
  const auto segments = render::plane_section(mesh, plane);
  ASSERT_GT(segments.size(), 10u);
  for (const auto& s : segments)
    for (const auto& p : s) EXPECT_LT(std::abs(p.x), 1e-6f);
}
#endif

}  // namespace
}  // namespace qs::app
