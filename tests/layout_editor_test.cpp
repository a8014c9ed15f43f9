// Sketch edits and their undo/redo (app/gui/layout_editor.cpp, GL-free), autosave and the
// recent-files list. Built from tests/cmake/gui_smoke.cmake with the app sources it needs.
#include "app/gui/layout_editor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/gui/autosave.h"
#include "app/gui/recent_files.h"
#include "core/base/atomic_file.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "tests/scoped_env.h"

namespace qs::app {
namespace {

namespace fs = std::filesystem;

// (n+1) x (n+1) vertices on the unit square, vertex (i, j) has index j * (n + 1) + i.
TriMesh grid(int n) {
  TriMesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.add_vertex(Vec3(double(i) / n, double(j) / n, 0.0));
  auto v = [&](int i, int j) { return OpenMesh::VertexHandle(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.add_face(v(i, j), v(i + 1, j), v(i + 1, j + 1));
      mesh.add_face(v(i, j), v(i + 1, j + 1), v(i, j + 1));
    }
  return mesh;
}

int vid(int i, int j, int n = 10) {
  return j * (n + 1) + i;
}

// Exact comparison through the serializer, which writes every field.
std::string dump(const Layout& layout) {
  return layout_to_json(layout);
}

class LayoutEditorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh_ = grid(10);
    editor_.reset(&mesh_, Layout{});
  }
  // A square of four nodes and four arcs.
  void sketch_square() {
    ids_ = {editor_.add_node(vid(2, 2)).id, editor_.add_node(vid(8, 2)).id,
            editor_.add_node(vid(8, 8)).id, editor_.add_node(vid(2, 8)).id};
    for (int k = 0; k < 4; ++k) ASSERT_TRUE(editor_.add_arc(ids_[k], ids_[(k + 1) % 4]).ok);
  }
  TriMesh mesh_;
  LayoutEditor editor_;
  std::vector<int> ids_;
};

TEST_F(LayoutEditorTest, UndoRedoRestoresTheExactLayoutAfterEveryEdit) {
  std::vector<std::string> states = {dump(editor_.layout())};
  auto record = [&](const EditResult& r) {
    ASSERT_TRUE(r.ok) << r.error;
    states.push_back(dump(editor_.layout()));
  };
  record(editor_.add_node(vid(2, 2)));
  record(editor_.add_node(vid(8, 2)));
  record(editor_.add_node(vid(8, 8)));
  record(editor_.add_node(vid(2, 8)));
  const auto& nodes = editor_.layout().nodes;
  record(editor_.add_arc(nodes[0].id, nodes[1].id));
  record(editor_.add_arc(nodes[1].id, nodes[2].id));
  record(editor_.add_arc(nodes[2].id, nodes[3].id));
  record(editor_.add_arc(nodes[3].id, nodes[0].id));
  const int arc0 = editor_.layout().arcs[0].id;
  const int interior = editor_.layout().arcs[0].path[2];
  record(editor_.split_arc(arc0, interior));
  record(editor_.toggle_node_pin(editor_.layout().nodes[0].id));
  record(editor_.toggle_arc_pin(editor_.layout().arcs[1].id));
  record(editor_.move_node(editor_.layout().nodes[2].id, vid(9, 9)));
  record(editor_.delete_arc(editor_.layout().arcs[2].id));
  record(editor_.delete_node(editor_.layout().nodes[0].id));
  ASSERT_EQ(editor_.history_size(), states.size() - 1);

  for (std::size_t k = states.size() - 1; k > 0; --k) {
    ASSERT_TRUE(editor_.undo());
    EXPECT_EQ(dump(editor_.layout()), states[k - 1]) << "after undoing step " << k;
  }
  EXPECT_FALSE(editor_.undo());
  for (std::size_t k = 1; k < states.size(); ++k) {
    ASSERT_TRUE(editor_.redo());
    EXPECT_EQ(dump(editor_.layout()), states[k]) << "after redoing step " << k;
  }
  EXPECT_FALSE(editor_.redo());
}

TEST_F(LayoutEditorTest, ANewEditDropsTheRedoBranch) {
  sketch_square();
  ASSERT_TRUE(editor_.undo());
  EXPECT_TRUE(editor_.can_redo());
  ASSERT_TRUE(editor_.add_node(vid(5, 5)).ok);
  EXPECT_FALSE(editor_.can_redo());
}

TEST_F(LayoutEditorTest, ArcsFollowMeshEdgesBetweenTheirNodes) {
  sketch_square();
  const Layout& layout = editor_.layout();
  ASSERT_EQ(layout.arcs.size(), 4u);
  for (const auto& arc : layout.arcs) {
    ASSERT_GE(arc.path.size(), 2u);
    EXPECT_EQ(arc.path.front(), layout.nodes[layout.node_index(arc.from)].vertex);
    EXPECT_EQ(arc.path.back(), layout.nodes[layout.node_index(arc.to)].vertex);
    for (std::size_t i = 0; i + 1 < arc.path.size(); ++i)
      EXPECT_TRUE(mesh_
                      .find_halfedge(OpenMesh::VertexHandle(arc.path[i]),
                                     OpenMesh::VertexHandle(arc.path[i + 1]))
                      .is_valid());
  }
}

TEST_F(LayoutEditorTest, DeletingANodeDeletesItsArcs) {
  sketch_square();
  ASSERT_TRUE(editor_.delete_node(ids_[0]).ok);
  EXPECT_EQ(editor_.layout().nodes.size(), 3u);
  EXPECT_EQ(editor_.layout().arcs.size(), 2u);
  for (const auto& arc : editor_.layout().arcs) {
    EXPECT_NE(arc.from, ids_[0]);
    EXPECT_NE(arc.to, ids_[0]);
  }
}

TEST_F(LayoutEditorTest, RefusedEditsChangeNothing) {
  sketch_square();
  const std::string before = dump(editor_.layout());
  const auto history = editor_.history_size();
  const auto version = editor_.version();
  EXPECT_FALSE(editor_.add_node(vid(2, 2)).ok);                         // node already there
  EXPECT_FALSE(editor_.add_node(editor_.layout().arcs[0].path[1]).ok);  // on an arc
  EXPECT_FALSE(editor_.add_node(100000).ok);                            // out of range
  EXPECT_FALSE(editor_.add_arc(ids_[0], ids_[0]).ok);                   // loop
  EXPECT_FALSE(editor_.add_arc(ids_[0], 999).ok);                       // unknown node
  EXPECT_FALSE(editor_.delete_arc(999).ok);
  EXPECT_FALSE(editor_.move_node(ids_[0], vid(8, 8)).ok);                      // occupied by a node
  EXPECT_FALSE(editor_.split_arc(editor_.layout().arcs[0].id, vid(2, 2)).ok);  // an end
  EXPECT_EQ(dump(editor_.layout()), before);
  EXPECT_EQ(editor_.history_size(), history);
  EXPECT_EQ(editor_.version(), version);
}

TEST_F(LayoutEditorTest, SplitKeepsTheRouteAndAddsANode) {
  sketch_square();
  const LayoutArc arc = editor_.layout().arcs[0];
  const int mid = arc.path[arc.path.size() / 2];
  const auto r = editor_.split_arc(arc.id, mid);
  ASSERT_TRUE(r.ok) << r.error;
  const Layout& layout = editor_.layout();
  EXPECT_EQ(layout.nodes.size(), 5u);
  EXPECT_EQ(layout.arcs.size(), 5u);
  const auto& first = layout.arcs[layout.arc_index(arc.id)];
  EXPECT_EQ(first.to, r.id);
  EXPECT_EQ(first.path.back(), mid);
  EXPECT_EQ(node_valence(layout, r.id), 2);
}

TEST_F(LayoutEditorTest, MovingANodeReroutesItsArcs) {
  sketch_square();
  ASSERT_TRUE(editor_.move_node(ids_[2], vid(9, 9)).ok);
  const Layout& layout = editor_.layout();
  for (const auto& arc : layout.arcs) {
    if (arc.from == ids_[2]) {
      EXPECT_EQ(arc.path.front(), vid(9, 9));
    }
    if (arc.to == ids_[2]) {
      EXPECT_EQ(arc.path.back(), vid(9, 9));
    }
  }
}

TEST_F(LayoutEditorTest, ADragIsOneUndoStep) {
  sketch_square();
  const std::string before = dump(editor_.layout());
  const auto history = editor_.history_size();
  ASSERT_TRUE(editor_.begin_drag(ids_[2]));
  EXPECT_TRUE(editor_.drag_to(vid(9, 8)).ok);
  EXPECT_TRUE(editor_.drag_to(vid(9, 9)).ok);
  EXPECT_FALSE(editor_.add_node(vid(5, 5)).ok);  // no edits in the middle of a drag
  editor_.end_drag();
  EXPECT_EQ(editor_.history_size(), history + 1);
  EXPECT_EQ(editor_.layout().nodes[editor_.layout().node_index(ids_[2])].vertex, vid(9, 9));
  ASSERT_TRUE(editor_.undo());
  EXPECT_EQ(dump(editor_.layout()), before);

  // A cancelled drag restores the layout and records nothing.
  ASSERT_TRUE(editor_.begin_drag(ids_[2]));
  EXPECT_TRUE(editor_.drag_to(vid(9, 9)).ok);
  editor_.cancel_drag();
  EXPECT_EQ(dump(editor_.layout()), before);
  EXPECT_EQ(editor_.history_size(), history + 1);
  EXPECT_TRUE(editor_.can_redo());
}

TEST_F(LayoutEditorTest, OnChangeFiresForEditsUndoAndRedo) {
  int calls = 0;
  editor_.on_change = [&](const Layout&) { ++calls; };
  ASSERT_TRUE(editor_.add_node(vid(1, 1)).ok);
  EXPECT_FALSE(editor_.add_node(vid(1, 1)).ok);
  editor_.undo();
  editor_.redo();
  EXPECT_EQ(calls, 3);
}

// The surface point at (x, y) of grid(n) (face and barycentrics in face-vertex order).
SurfacePoint grid_point(const TriMesh& mesh, double x, double y, int n = 10) {
  const int i = std::clamp(int(x * n), 0, n - 1), j = std::clamp(int(y * n), 0, n - 1);
  const double lx = x * n - i, ly = y * n - j;
  SurfacePoint p;
  p.face = 2 * (j * n + i) + (lx >= ly ? 0 : 1);
  // Weights of the corners (i, j), (i+1, j), (i+1, j+1), (i, j+1) for this triangle.
  const double w[4] = {lx >= ly ? 1 - lx : 1 - ly, lx >= ly ? lx - ly : 0.0, lx >= ly ? ly : lx,
                       lx >= ly ? 0.0 : ly - lx};
  const int corner[4] = {vid(i, j, n), vid(i + 1, j, n), vid(i + 1, j + 1, n), vid(i, j + 1, n)};
  int k = 0;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(p.face))) {
    double b = 0.0;
    for (int c = 0; c < 4; ++c)
      if (corner[c] == vh.idx()) b = w[c];
    p.bary[k++] = b;
  }
  return p;
}

// Mouse-like samples every `step` along the polyline through `corners` (x, y).
std::vector<SurfacePoint> stroke_through(const TriMesh& mesh,
                                         const std::vector<std::array<double, 2>>& corners,
                                         double step = 0.02) {
  std::vector<SurfacePoint> out;
  for (std::size_t k = 0; k + 1 < corners.size(); ++k) {
    const auto a = corners[k], b = corners[k + 1];
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    const int count = std::max(1, int(std::ceil(len / step)));
    for (int s = 0; s < count; ++s) {
      const double t = double(s) / count;
      out.push_back(grid_point(mesh, a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])));
    }
  }
  out.push_back(grid_point(mesh, corners.back()[0], corners.back()[1]));
  return out;
}

Vec3 position(const TriMesh& mesh, int v) {
  return mesh.point(OpenMesh::VertexHandle(v));
}

void expect_edge_path(const TriMesh& mesh, const std::vector<int>& path) {
  for (std::size_t i = 0; i + 1 < path.size(); ++i)
    EXPECT_TRUE(
        mesh.find_halfedge(OpenMesh::VertexHandle(path[i]), OpenMesh::VertexHandle(path[i + 1]))
            .is_valid())
        << "no mesh edge between " << path[i] << " and " << path[i + 1];
}

TEST_F(LayoutEditorTest, StrokeArcFollowsTheStrokeNotTheShortestPath) {
  const int a = editor_.add_node(vid(1, 1)).id;
  const int b = editor_.add_node(vid(9, 1)).id;
  // A U-shaped stroke: up the left side, across at y = 0.8, down the right side.
  const auto stroke = stroke_through(mesh_, {{0.1, 0.1}, {0.1, 0.8}, {0.9, 0.8}, {0.9, 0.1}});
  const auto r = editor_.add_stroke_arc(a, b, stroke);
  ASSERT_TRUE(r.ok) << r.error;
  const Layout& layout = editor_.layout();
  const LayoutArc& arc = layout.arcs[layout.arc_index(r.id)];
  EXPECT_EQ(arc.from, a);
  EXPECT_EQ(arc.to, b);
  ASSERT_GE(arc.path.size(), 2u);
  EXPECT_EQ(arc.path.front(), vid(1, 1));
  EXPECT_EQ(arc.path.back(), vid(9, 1));
  expect_edge_path(mesh_, arc.path);
  // Every vertex stays within one edge length of the stroke, and the route reaches its top.
  double top = 0.0;
  for (int v : arc.path) {
    const Vec3 x = position(mesh_, v);
    const double d =
        std::min({std::abs(x[0] - 0.1) + std::max(0.0, x[1] - 0.8),
                  std::abs(x[0] - 0.9) + std::max(0.0, x[1] - 0.8),
                  std::abs(x[1] - 0.8) + std::max(0.0, std::max(0.1 - x[0], x[0] - 0.9))});
    EXPECT_LE(d, 0.1 + 1e-9) << "vertex " << v << " strays from the stroke";
    top = std::max(top, x[1]);
  }
  EXPECT_NEAR(top, 0.8, 1e-9);
  // Click-click routing of the same nodes takes the short way instead.
  ASSERT_TRUE(editor_.undo());
  const auto straight = editor_.add_arc(a, b);
  ASSERT_TRUE(straight.ok);
  for (int v : editor_.layout().arcs.back().path) EXPECT_LE(position(mesh_, v)[1], 0.1 + 1e-9);
}

TEST_F(LayoutEditorTest, StrokeIntoEmptySpaceAddsTheEndNodeInTheSameUndoStep) {
  const int a = editor_.add_node(vid(1, 1)).id;
  const std::string before = dump(editor_.layout());
  const auto history = editor_.history_size();
  const auto r = editor_.add_stroke_arc(a, -1, stroke_through(mesh_, {{0.1, 0.1}, {0.52, 0.48}}));
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_GE(r.node_id, 0);
  const Layout& layout = editor_.layout();
  ASSERT_EQ(layout.nodes.size(), 2u);
  EXPECT_EQ(layout.nodes[layout.node_index(r.node_id)].vertex, vid(5, 5));
  const LayoutArc& arc = layout.arcs[layout.arc_index(r.id)];
  EXPECT_EQ(arc.to, r.node_id);
  EXPECT_EQ(arc.path.back(), vid(5, 5));
  expect_edge_path(mesh_, arc.path);
  EXPECT_EQ(editor_.history_size(), history + 1);
  const std::string after = dump(editor_.layout());
  ASSERT_TRUE(editor_.undo());
  EXPECT_EQ(dump(editor_.layout()), before);
  ASSERT_TRUE(editor_.redo());
  EXPECT_EQ(dump(editor_.layout()), after);
  // Ending at an existing node uses it instead of adding one.
  const int c = editor_.add_node(vid(9, 2)).id;
  const auto r2 =
      editor_.add_stroke_arc(r.node_id, -1, stroke_through(mesh_, {{0.5, 0.5}, {0.9, 0.21}}));
  ASSERT_TRUE(r2.ok) << r2.error;
  EXPECT_EQ(r2.node_id, -1);
  EXPECT_EQ(editor_.layout().arcs.back().to, c);
}

TEST_F(LayoutEditorTest, StrokeArcsAvoidOtherArcs) {
  sketch_square();
  const int inner = editor_.add_node(vid(5, 5)).id;
  // Drawn straight over the square's bottom arc towards a corner node (reachable from inside
  // over the diagonal edge (3, 3)-(2, 2)): the route may not share any vertex or edge with the
  // other arcs.
  const RoutingObstacles obstacles = obstacles_of_layout(mesh_, editor_.layout());
  const auto r = editor_.add_stroke_arc(
      inner, ids_[0], stroke_through(mesh_, {{0.5, 0.5}, {0.5, 0.2}, {0.2, 0.2}}));
  ASSERT_TRUE(r.ok) << r.error;
  const auto& path = editor_.layout().arcs.back().path;
  expect_edge_path(mesh_, path);
  for (std::size_t i = 1; i + 1 < path.size(); ++i)
    EXPECT_FALSE(obstacles.vertex_blocked[path[i]]) << "vertex " << path[i] << " is taken";
  // Leaving the closed square is impossible without crossing an arc: refused, nothing changes.
  const std::string before = dump(editor_.layout());
  const auto out =
      editor_.add_stroke_arc(inner, -1, stroke_through(mesh_, {{0.5, 0.5}, {0.5, 0.05}}));
  EXPECT_FALSE(out.ok);
  EXPECT_FALSE(out.error.empty());
  EXPECT_EQ(dump(editor_.layout()), before);
}

TEST_F(LayoutEditorTest, InvalidStrokesAreRefusedWithAMessage) {
  sketch_square();
  const std::string before = dump(editor_.layout());
  const auto history = editor_.history_size();
  const auto good = stroke_through(mesh_, {{0.2, 0.2}, {0.5, 0.5}});
  auto bad_face = good;
  bad_face[3].face = 100000;
  auto nan_bary = good;
  nan_bary[2].bary = {std::nan(""), 0.5, 0.5};
  const std::vector<EditResult> refused = {
      editor_.add_stroke_arc(ids_[0], ids_[2], {}),              // empty
      editor_.add_stroke_arc(ids_[0], ids_[2], {good.front()}),  // one sample
      editor_.add_stroke_arc(999, ids_[2], good),                // unknown start
      editor_.add_stroke_arc(ids_[0], 999, good),                // unknown end
      editor_.add_stroke_arc(ids_[0], ids_[0], good),            // loop
      editor_.add_stroke_arc(ids_[0], ids_[2], bad_face),        // face out of range
      editor_.add_stroke_arc(ids_[0], ids_[2], nan_bary),        // NaN barycentrics
      editor_.add_stroke_arc(ids_[0], -1, stroke_through(mesh_, {{0.2, 0.2}, {0.5, 0.21}})),
  };
  for (std::size_t k = 0; k < refused.size(); ++k) {
    EXPECT_FALSE(refused[k].ok) << "stroke " << k;
    EXPECT_FALSE(refused[k].error.empty()) << "stroke " << k;
  }
  EXPECT_NE(refused.back().error.find("arc"), std::string::npos) << refused.back().error;
  EXPECT_EQ(dump(editor_.layout()), before);
  EXPECT_EQ(editor_.history_size(), history);
}

TEST_F(LayoutEditorTest, RouteStrokeToTheBoundaryEndsNearTheLastSample) {
  std::string error;
  const RoutingObstacles none = obstacles_of_layout(mesh_, Layout{});
  const auto path =
      route_stroke(mesh_, vid(5, 5), -1,
                   stroke_through(mesh_, {{0.5, 0.5}, {0.7, 0.7}, {0.98, 0.7}}), none, &error);
  ASSERT_GE(path.size(), 2u) << error;
  EXPECT_EQ(path.back(), vid(10, 7));
  expect_edge_path(mesh_, path);
}

TEST_F(LayoutEditorTest, DanglingArcEndsOnTheBoundary) {
  const int a = editor_.add_node(vid(4, 5)).id;
  const std::string before = dump(editor_.layout());
  // Nearest free boundary vertex: 4 edges to the left.
  const auto r = editor_.add_dangling_arc(a);
  ASSERT_TRUE(r.ok) << r.error;
  const Layout& layout = editor_.layout();
  const LayoutArc& arc = layout.arcs[layout.arc_index(r.id)];
  EXPECT_TRUE(arc.dangling());
  EXPECT_EQ(arc.path.front(), vid(4, 5));
  EXPECT_EQ(arc.path.back(), vid(0, 5));
  EXPECT_EQ(arc.path.size(), 5u);
  expect_edge_path(mesh_, arc.path);
  EXPECT_EQ(node_valence(layout, a), 1);
  for (const auto& issue : validate_layout(mesh_, layout).issues)
    EXPECT_NE(issue.code, "dangling_not_on_boundary") << issue.message;
  // A chosen boundary vertex; the taken one and interior vertices are refused.
  const auto r2 = editor_.add_dangling_arc(a, vid(10, 5));
  ASSERT_TRUE(r2.ok) << r2.error;
  EXPECT_EQ(editor_.layout().arcs.back().path.back(), vid(10, 5));
  const std::string two = dump(editor_.layout());
  EXPECT_FALSE(editor_.add_dangling_arc(a, vid(0, 5)).ok);  // taken by the first arc
  EXPECT_FALSE(editor_.add_dangling_arc(a, vid(5, 6)).ok);  // not on the boundary
  EXPECT_FALSE(editor_.add_dangling_arc(a, 100000).ok);     // out of range
  EXPECT_FALSE(editor_.add_dangling_arc(999).ok);           // unknown node
  EXPECT_EQ(dump(editor_.layout()), two);
  ASSERT_TRUE(editor_.undo());
  ASSERT_TRUE(editor_.undo());
  EXPECT_EQ(dump(editor_.layout()), before);
}

TEST(LayoutEditorClosed, DanglingArcsNeedABoundary) {
  // An octahedron: closed, so a dangling arc has nowhere to end.
  TriMesh mesh;
  std::vector<OpenMesh::VertexHandle> v;
  for (const auto& p : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1),
                        Vec3(0, 0, -1)})
    v.push_back(mesh.add_vertex(p));
  const int faces[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                           {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& f : faces) mesh.add_face(v[f[0]], v[f[1]], v[f[2]]);
  ASSERT_EQ(mesh.n_faces(), 8u);
  LayoutEditor editor;
  editor.reset(&mesh, Layout{});
  const int a = editor.add_node(0).id;
  const auto r = editor.add_dangling_arc(a);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("boundary"), std::string::npos) << r.error;
  EXPECT_TRUE(editor.layout().arcs.empty());
  // The stroke router says the same for a stroke that should end on the boundary.
  std::string error;
  SurfacePoint p;
  p.face = 0;
  EXPECT_TRUE(
      route_stroke(mesh, 0, -1, {p, p}, obstacles_of_layout(mesh, Layout{}), &error).empty());
  EXPECT_NE(error.find("boundary"), std::string::npos) << error;
}

using test::ScopedEnv;

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("qs_gui_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST_F(LayoutEditorTest, AutosaveIsValidJsonAfterAnEdit) {
  const fs::path dir = fresh_dir("autosave");
  ScopedEnv env("QS_AUTOSAVE_DIR", dir.string());
  ASSERT_EQ(autosave_path(), dir / "autosave.layout.json");
  const fs::path mesh_file = dir / "grid.obj";
  std::ofstream(mesh_file) << "# placeholder name only\n";
  editor_.on_change = [&](const Layout& layout) {
    write_autosave(layout, &mesh_, mesh_file.string(), "");
  };
  sketch_square();

  const auto json = nlohmann::json::parse(read_file(autosave_path().string()));
  EXPECT_EQ(json.at("format"), "quadsketch-layout");
  EXPECT_EQ(json.at("nodes").size(), 4u);
  EXPECT_EQ(json.at("arcs").size(), 4u);
  // And it loads back as the same layout.
  const Layout back = load_layout(autosave_path().string(), mesh_);
  EXPECT_EQ(back.arcs.size(), 4u);
  EXPECT_EQ(back.arcs[2].path, editor_.layout().arcs[2].path);

  const auto offer = find_autosave(mesh_file.string());
  ASSERT_TRUE(offer.has_value());
  EXPECT_EQ(offer->path, autosave_path());
  EXPECT_EQ(offer->mesh_path, fs::weakly_canonical(mesh_file).string());
  EXPECT_FALSE(offer->saved_at.empty());
  EXPECT_FALSE(find_autosave((dir / "other.obj").string()).has_value());
  EXPECT_TRUE(find_autosave().has_value());  // whatever mesh is open
  // One file carries the layout and its description (a single atomic write), no sidecar.
  EXPECT_EQ(json.at("autosave").at("mesh"), fs::weakly_canonical(mesh_file).string());
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 2u);  // grid.obj and autosave.layout.json
  // A torn or foreign file is never offered.
  std::ofstream(autosave_path()) << "{ \"format\": \"quadsketch-layout\", \"nod";
  EXPECT_FALSE(find_autosave(mesh_file.string()).has_value());
  EXPECT_FALSE(find_autosave().has_value());
  fs::remove_all(dir);
}

// An autosave made while editing a layout file is not offered once that file was saved after
// it; set aside, it is no longer the autosave; removed, nothing is offered.
TEST_F(LayoutEditorTest, AutosaveOfferFollowsSavesAndCanBeSetAside) {
  const fs::path dir = fresh_dir("autosave_saved");
  ScopedEnv env("QS_AUTOSAVE_DIR", dir.string());
  const fs::path mesh_file = dir / "grid.obj";
  const fs::path layout_file = dir / "grid.layout.json";
  std::ofstream(mesh_file) << "# placeholder name only\n";
  std::ofstream(layout_file) << "{}";
  fs::last_write_time(layout_file, fs::file_time_type::clock::now() - std::chrono::hours(1));
  sketch_square();
  write_autosave(editor_.layout(), &mesh_, mesh_file.string(), layout_file.string());
  const auto offer = find_autosave();
  ASSERT_TRUE(offer.has_value());
  EXPECT_EQ(offer->layout_path, fs::weakly_canonical(layout_file).string());
  fs::last_write_time(layout_file, fs::file_time_type::clock::now() + std::chrono::hours(1));
  EXPECT_FALSE(find_autosave().has_value());  // saved after the autosave

  fs::last_write_time(layout_file, fs::file_time_type::clock::now() - std::chrono::hours(1));
  ASSERT_TRUE(find_autosave().has_value());
  const std::string aside = set_autosave_aside();
  EXPECT_EQ(aside, (dir / "autosave.previous.layout.json").string());
  EXPECT_TRUE(fs::exists(aside));
  EXPECT_FALSE(find_autosave().has_value());
  write_autosave(editor_.layout(), &mesh_, mesh_file.string(), "");
  ASSERT_TRUE(find_autosave().has_value());
  remove_autosave();
  EXPECT_FALSE(find_autosave().has_value());
  EXPECT_EQ(set_autosave_aside(), "");
  fs::remove_all(dir);
}

TEST(RecentFiles, ToleratesMissingAndCorruptFiles) {
  const fs::path dir = fresh_dir("recent");
  RecentFiles recent;
  recent.load(dir / "missing" / "recent.json");
  EXPECT_TRUE(recent.meshes().empty());
  recent.add_mesh("/a/b.obj");
  recent.add_mesh("/a/c.obj");
  recent.add_mesh("/a/b.obj");
  recent.add_layout("/a/b.layout.json");
  ASSERT_TRUE(recent.save());

  RecentFiles again;
  again.load(dir / "missing" / "recent.json");
  ASSERT_EQ(again.meshes().size(), 2u);
  EXPECT_EQ(again.meshes()[0], "/a/b.obj");  // most recent first, no duplicates
  EXPECT_EQ(again.layouts().size(), 1u);

  std::ofstream(dir / "corrupt.json") << "{ not json";
  RecentFiles corrupt;
  corrupt.load(dir / "corrupt.json");
  EXPECT_TRUE(corrupt.meshes().empty());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace qs::app
