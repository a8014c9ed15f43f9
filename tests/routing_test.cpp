// Tests of arc routing (core/layout/routing.h).
#include "core/layout/routing.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <set>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/layout/layout_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

//! n x n vertex grid in the plane z = 0 with unit spacing; vertex (i, j) has index j*n + i.
//! Each cell (i, j) has faces (i,j)(i+1,j)(i+1,j+1) and (i,j)(i+1,j+1)(i,j+1).
class Grid {
 public:
  explicit Grid(int n) : n_(n) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) mesh.add_vertex(Vec3(i, j, 0));
    }
    auto vh = [this](int i, int j) { return OpenMesh::VertexHandle(v(i, j)); };
    for (int j = 0; j + 1 < n; ++j) {
      for (int i = 0; i + 1 < n; ++i) {
        mesh.add_face(vh(i, j), vh(i + 1, j), vh(i + 1, j + 1));
        mesh.add_face(vh(i, j), vh(i + 1, j + 1), vh(i, j + 1));
      }
    }
  }
  int v(int i, int j) const { return j * n_ + i; }

  TriMesh mesh;

 private:
  int n_;
};

//! Regular octahedron (closed, no boundary).
TriMesh octahedron() {
  TriMesh mesh;
  const Vec3 p[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<OpenMesh::VertexHandle> v;
  for (const Vec3& q : p) v.push_back(mesh.add_vertex(q));
  const int f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& t : f) mesh.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return mesh;
}

//! A surface point close to vertex \p v (weight 0.8 on it, in one of its faces).
SurfacePoint point_near(const TriMesh& mesh, int v) {
  const OpenMesh::VertexHandle vh(v);
  const auto fh = *mesh.vf_range(vh).begin();
  SurfacePoint p;
  p.face = fh.idx();
  int k = 0;
  for (const auto c : mesh.fv_range(fh)) p.bary[k++] = c == vh ? 0.8 : 0.1;
  return p;
}

LayoutNode node(int id, int vertex) {
  return test::make_node(id, vertex);
}

LayoutArc path_arc(int id, int from, int to, std::vector<int> path) {
  return test::make_arc(id, from, to, std::move(path));
}

LayoutArc points_arc(int id, int from, int to, std::vector<SurfacePoint> points) {
  LayoutArc a = test::make_arc(id, from, to, {});
  a.points = std::move(points);
  return a;
}

//! Checks that \p path is a simple edge path of \p mesh.
void expect_simple_edge_path(const TriMesh& mesh, const std::vector<int>& path) {
  ASSERT_GE(path.size(), 2u);
  std::set<int> seen;
  for (size_t k = 0; k < path.size(); ++k) {
    ASSERT_GE(path[k], 0);
    ASSERT_LT(path[k], static_cast<int>(mesh.n_vertices()));
    EXPECT_TRUE(seen.insert(path[k]).second) << "vertex " << path[k] << " repeated";
    if (k > 0) {
      EXPECT_TRUE(
          mesh.find_halfedge(OpenMesh::VertexHandle(path[k - 1]), OpenMesh::VertexHandle(path[k]))
              .is_valid())
          << "no edge " << path[k - 1] << "-" << path[k];
    }
  }
}

void expect_disjoint_interiors(const std::vector<int>& a, const std::vector<int>& b) {
  const std::set<int> sa(a.begin(), a.end());
  for (int v : b) EXPECT_EQ(sa.count(v), 0u) << "vertex " << v << " shared";
}

RoutingObstacles no_obstacles(const TriMesh& mesh) {
  RoutingObstacles o;
  o.vertex_blocked.assign(mesh.n_vertices(), 0);
  o.edge_blocked.assign(mesh.n_edges(), 0);
  return o;
}

std::string route_error(const TriMesh& mesh, Layout& layout) {
  try {
    route_layout(mesh, layout);
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "route_layout did not fail";
  return {};
}

TEST(Routing, SnapToVertexPicksLargestBarycentric) {
  const Grid g(4);
  std::vector<int> corners;
  for (const auto vh : g.mesh.fv_range(OpenMesh::FaceHandle(5))) corners.push_back(vh.idx());
  ASSERT_EQ(corners.size(), 3u);
  EXPECT_EQ(snap_to_vertex(g.mesh, SurfacePoint{5, {{0.2, 0.5, 0.3}}}), corners[1]);
  EXPECT_EQ(snap_to_vertex(g.mesh, SurfacePoint{5, {{0.6, 0.1, 0.3}}}), corners[0]);
  EXPECT_EQ(snap_to_vertex(g.mesh, SurfacePoint{5, {{0.0, 0.0, 1.0}}}), corners[2]);
  EXPECT_EQ(snap_to_vertex(g.mesh, SurfacePoint{5, {{-1e-10, 0.4, 0.6 + 1e-10}}}), corners[2]);
  // Ties go to the first corner.
  EXPECT_EQ(snap_to_vertex(g.mesh, SurfacePoint{5, {{0.25, 0.5, 0.25}}}), corners[1]);
  EXPECT_EQ(snap_to_vertex(g.mesh, SurfacePoint{5, {{0.4, 0.2, 0.4}}}), corners[0]);
}

TEST(Routing, SnapToVertexRejectsBadPoints) {
  const Grid g(4);  // 18 faces
  const double nan = std::nan("");
  for (const SurfacePoint& p :
       {SurfacePoint{-1, {{1, 0, 0}}}, SurfacePoint{18, {{1, 0, 0}}},
        SurfacePoint{0, {{0.5, 0.5, 0.5}}}, SurfacePoint{0, {{1.2, -0.2, 0}}},
        SurfacePoint{0, {{nan, 0.5, 0.5}}}, SurfacePoint{0, {{0, 0, 0}}}}) {
    EXPECT_THROW(snap_to_vertex(g.mesh, p), InvalidInputError) << p.face;
  }
  try {
    snap_to_vertex(g.mesh, SurfacePoint{18, {{1, 0, 0}}});
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("face 18 out of range (mesh has 18 faces)"),
              std::string::npos)
        << e.what();
  }
}

TEST(Routing, ShortestPathFollowsEdgesAndAvoidsObstacles) {
  const Grid g(6);
  RoutingObstacles o = no_obstacles(g.mesh);
  std::vector<int> straight;
  for (int i = 0; i <= 4; ++i) straight.push_back(g.v(i, 0));
  EXPECT_EQ(shortest_path(g.mesh, g.v(0, 0), g.v(4, 0), o), straight);
  EXPECT_EQ(shortest_path(g.mesh, g.v(2, 2), g.v(2, 2), o), (std::vector<int>{g.v(2, 2)}));

  // A blocked vertex is avoided; blocked source and target are allowed.
  o.vertex_blocked[g.v(2, 0)] = 1;
  o.vertex_blocked[g.v(0, 0)] = 1;
  o.vertex_blocked[g.v(4, 0)] = 1;
  std::vector<int> p = shortest_path(g.mesh, g.v(0, 0), g.v(4, 0), o);
  expect_simple_edge_path(g.mesh, p);
  EXPECT_EQ(p.front(), g.v(0, 0));
  EXPECT_EQ(p.back(), g.v(4, 0));
  EXPECT_EQ(std::count(p.begin(), p.end(), g.v(2, 0)), 0);

  // A blocked edge is avoided.
  o = no_obstacles(g.mesh);
  const auto heh =
      g.mesh.find_halfedge(OpenMesh::VertexHandle(g.v(1, 0)), OpenMesh::VertexHandle(g.v(2, 0)));
  o.edge_blocked[g.mesh.edge_handle(heh).idx()] = 1;
  p = shortest_path(g.mesh, g.v(1, 0), g.v(2, 0), o);
  expect_simple_edge_path(g.mesh, p);
  EXPECT_GT(p.size(), 2u);

  // Unreachable and out-of-range cases give empty paths.
  o = no_obstacles(g.mesh);
  for (const int b : {g.v(0, 1), g.v(1, 1), g.v(1, 0)}) o.vertex_blocked[b] = 1;
  EXPECT_TRUE(shortest_path(g.mesh, g.v(0, 0), g.v(5, 5), o).empty());
  EXPECT_TRUE(shortest_path(g.mesh, g.v(5, 5), g.v(0, 0), o).empty());  // the target enclosed
  // A blocked vertex next to the enclosed corner is a reachable target from either side.
  EXPECT_EQ(shortest_path(g.mesh, g.v(0, 0), g.v(1, 0), o),
            (std::vector<int>{g.v(0, 0), g.v(1, 0)}));
  EXPECT_FALSE(shortest_path(g.mesh, g.v(5, 5), g.v(1, 0), o).empty());
  EXPECT_TRUE(shortest_path(g.mesh, -1, g.v(5, 5), o).empty());
  EXPECT_TRUE(shortest_path(g.mesh, 0, 1000, o).empty());
  // Obstacle vectors of the wrong size do not crash.
  EXPECT_FALSE(shortest_path(g.mesh, 0, 35, RoutingObstacles{}).empty());
}

// The goal-directed search (A*) finds shortest paths and reports unreachable targets: on an
// ellipsoid with some or all of a layout's arcs and its nodes as obstacles, every path's length
// equals the distance of a plain reference Dijkstra over the same edges (blocked vertices only as
// source or target), and a path is empty exactly when the reference finds none (all arcs: patches
// sealed off from each other, the target sometimes on a blocked arc vertex).
TEST(Routing, ShortestPathIsAsShortAsPlainDijkstra) {
  const auto e = test::cube_sphere(10, Vec3(1.4, 1, 0.6));
  const TriMesh& mesh = e.mesh;
  const int nv = static_cast<int>(mesh.n_vertices());
  auto length = [&](int a, int b) {
    return (mesh.point(OpenMesh::VertexHandle(a)) - mesh.point(OpenMesh::VertexHandle(b))).norm();
  };
  for (const int every : {3, 1}) {
    Layout walls = e.layout;  // every third arc: obstacles to go around; every arc: patches
    walls.arcs.clear();
    for (size_t a = 0; a < e.layout.arcs.size(); a += every) walls.arcs.push_back(e.layout.arcs[a]);
    const RoutingObstacles o = obstacles_of_layout(mesh, walls);
    auto reference = [&](int source, int target) {
      std::vector<double> dist(nv, std::numeric_limits<double>::infinity());
      std::vector<char> done(nv, 0);
      dist[source] = 0;
      for (;;) {  // O(V²): plain and obviously right
        int v = -1;
        for (int x = 0; x < nv; ++x)
          if (!done[x] && std::isfinite(dist[x]) && (v < 0 || dist[x] < dist[v])) v = x;
        if (v < 0 || v == target) break;
        done[v] = 1;
        if (v != source && o.vertex_blocked[v]) continue;  // not passed through
        for (auto h : mesh.voh_range(OpenMesh::VertexHandle(v))) {
          if (o.edge_blocked[mesh.edge_handle(h).idx()]) continue;
          const int w = mesh.to_vertex_handle(h).idx();
          dist[w] = std::min(dist[w], dist[v] + length(v, w));
        }
      }
      return dist[target];
    };
    int compared = 0, unreachable = 0;
    for (int k = 0; k < 60; ++k) {
      const int source = (k * 7919) % nv, target = (k * 104729 + 13) % nv;
      if (source == target) continue;
      const std::vector<int> path = shortest_path(mesh, source, target, o);
      const double want = reference(source, target);
      if (!std::isfinite(want)) {
        EXPECT_TRUE(path.empty()) << source << " -> " << target;
        ++unreachable;
        continue;
      }
      ASSERT_FALSE(path.empty()) << source << " -> " << target;
      EXPECT_EQ(path.front(), source);
      EXPECT_EQ(path.back(), target);
      double got = 0;
      for (size_t i = 1; i < path.size(); ++i) {
        got += length(path[i - 1], path[i]);
        if (i + 1 < path.size()) {
          EXPECT_FALSE(o.vertex_blocked[path[i]]) << "passes a blocked vertex";
        }
      }
      EXPECT_NEAR(got, want, 1e-12 * std::max(1.0, want)) << source << " -> " << target;
      ++compared;
    }
    EXPECT_GT(compared, 10);
    if (every == 1) {
      EXPECT_GT(unreachable, 10);
    }
    std::printf(
        "[stat] every %d arcs as walls: %d paths as short as the reference's, %d unreachable\n",
        every, compared, unreachable);
  }
}

TEST(Routing, ShortestPathToBoundary) {
  const Grid g(11);
  RoutingObstacles o = no_obstacles(g.mesh);
  o.vertex_blocked[g.v(4, 5)] = 1;  // left
  o.vertex_blocked[g.v(5, 5)] = 1;  // the source itself may be blocked
  const std::vector<int> p = shortest_path_to_boundary(g.mesh, g.v(6, 5), o);
  expect_simple_edge_path(g.mesh, p);
  EXPECT_EQ(p.front(), g.v(6, 5));
  EXPECT_EQ(p.back(), g.v(10, 5));
  EXPECT_EQ(p.size(), 5u);
  // A boundary source does not count as its own target.
  const std::vector<int> q = shortest_path_to_boundary(g.mesh, g.v(0, 3), o);
  ASSERT_EQ(q.size(), 2u);
  EXPECT_TRUE(g.mesh.is_boundary(OpenMesh::VertexHandle(q.back())));
  // No boundary at all.
  const TriMesh closed = octahedron();
  EXPECT_TRUE(shortest_path_to_boundary(closed, 0, no_obstacles(closed)).empty());
}

TEST(Routing, ObstaclesOfLayout) {
  const Grid g(5);
  Layout layout;
  layout.nodes = {node(0, g.v(1, 1)), node(1, g.v(3, 1)), node(2, g.v(4, 4)), node(3, 99999),
                  node(4, -1)};
  layout.arcs = {path_arc(0, 0, 1, {g.v(1, 1), g.v(2, 1), g.v(3, 1)}),
                 // Broken data is skipped, never a crash.
                 path_arc(1, 0, 1, {-4, g.v(0, 0), g.v(2, 3), 123456})};
  const RoutingObstacles o = obstacles_of_layout(g.mesh, layout);
  ASSERT_EQ(o.vertex_blocked.size(), g.mesh.n_vertices());
  ASSERT_EQ(o.edge_blocked.size(), g.mesh.n_edges());
  std::set<int> blocked;
  for (size_t v = 0; v < o.vertex_blocked.size(); ++v) {
    if (o.vertex_blocked[v]) blocked.insert(static_cast<int>(v));
  }
  EXPECT_EQ(blocked,
            (std::set<int>{g.v(1, 1), g.v(2, 1), g.v(3, 1), g.v(4, 4), g.v(0, 0), g.v(2, 3)}));
  EXPECT_EQ(std::count(o.edge_blocked.begin(), o.edge_blocked.end(), 1), 2);
  for (const auto& [a, b] : {std::pair{g.v(1, 1), g.v(2, 1)}, std::pair{g.v(2, 1), g.v(3, 1)}}) {
    const auto heh = g.mesh.find_halfedge(OpenMesh::VertexHandle(a), OpenMesh::VertexHandle(b));
    EXPECT_TRUE(o.edge_blocked[g.mesh.edge_handle(heh).idx()]);
  }
}

TEST(Routing, PointsArcAvoidsExistingArc) {
  const Grid g(11);
  Layout layout;
  layout.nodes = {node(0, g.v(1, 5)), node(1, g.v(9, 5)), node(2, g.v(5, 1)), node(3, g.v(5, 9))};
  std::vector<int> wall;
  for (int j = 1; j <= 9; ++j) wall.push_back(g.v(5, j));
  layout.arcs = {
      path_arc(0, 2, 3, wall),
      points_arc(1, 0, 1, {point_near(g.mesh, g.v(3, 6)), point_near(g.mesh, g.v(5, 10))})};
  route_layout(g.mesh, layout);
  EXPECT_EQ(layout.arcs[0].path, wall);  // untouched
  const std::vector<int>& p = layout.arcs[1].path;
  expect_simple_edge_path(g.mesh, p);
  EXPECT_EQ(p.front(), g.v(1, 5));
  EXPECT_EQ(p.back(), g.v(9, 5));
  expect_disjoint_interiors(wall, p);
  EXPECT_EQ(std::count(p.begin(), p.end(), g.v(3, 6)), 1);
  EXPECT_EQ(std::count(p.begin(), p.end(), g.v(5, 10)), 1);
}

TEST(Routing, RoutedArcsBlockLaterArcs) {
  const Grid g(11);
  Layout layout;
  layout.nodes = {node(0, g.v(1, 5)), node(1, g.v(9, 5)), node(2, g.v(5, 1)), node(3, g.v(5, 9))};
  // Arc 7 (routed first) runs up column 5; arc 8 must go around it.
  layout.arcs = {points_arc(7, 2, 3, {point_near(g.mesh, g.v(5, 5))}),
                 points_arc(8, 0, 1, {point_near(g.mesh, g.v(6, 5))})};
  route_layout(g.mesh, layout);
  std::vector<int> column;
  for (int j = 1; j <= 9; ++j) column.push_back(g.v(5, j));
  EXPECT_EQ(layout.arcs[0].path, column);
  expect_simple_edge_path(g.mesh, layout.arcs[1].path);
  EXPECT_EQ(layout.arcs[1].path.front(), g.v(1, 5));
  EXPECT_EQ(layout.arcs[1].path.back(), g.v(9, 5));
  expect_disjoint_interiors(layout.arcs[0].path, layout.arcs[1].path);
}

TEST(Routing, PointOnAnotherArcSnapsToAFreeCorner) {
  const Grid g(11);
  Layout layout;
  layout.nodes = {node(0, g.v(1, 5)), node(1, g.v(9, 5)), node(2, g.v(5, 1)), node(3, g.v(5, 9))};
  std::vector<int> wall;
  for (int j = 1; j <= 9; ++j) wall.push_back(g.v(5, j));
  // The point is nearest to vertex (5, 5), which is on arc 0.
  layout.arcs = {path_arc(0, 2, 3, wall), points_arc(1, 0, 1, {point_near(g.mesh, g.v(5, 5))})};
  route_layout(g.mesh, layout);
  const std::vector<int>& p = layout.arcs[1].path;
  expect_simple_edge_path(g.mesh, p);
  expect_disjoint_interiors(wall, p);
  EXPECT_EQ(p.back(), g.v(9, 5));
}

TEST(Routing, EnclosedNodeCannotBeRouted) {
  const Grid g(11);
  Layout layout;
  // A square ring of 4 nodes and 4 arcs around node 1 at (5, 5).
  layout.nodes = {node(10, g.v(3, 3)), node(11, g.v(7, 3)), node(12, g.v(7, 7)),
                  node(13, g.v(3, 7)), node(1, g.v(5, 5)),  node(2, g.v(0, 0)),
                  node(3, g.v(10, 10))};
  auto side = [&](int i0, int j0, int i1, int j1) {
    std::vector<int> path;
    const int steps = std::max(std::abs(i1 - i0), std::abs(j1 - j0));
    for (int s = 0; s <= steps; ++s) {
      path.push_back(g.v(i0 + (i1 - i0) * s / steps, j0 + (j1 - j0) * s / steps));
    }
    return path;
  };
  layout.arcs = {path_arc(20, 10, 11, side(3, 3, 7, 3)),
                 path_arc(21, 11, 12, side(7, 3, 7, 7)),
                 path_arc(22, 12, 13, side(7, 7, 3, 7)),
                 path_arc(23, 13, 10, side(3, 7, 3, 3)),
                 points_arc(4, 1, -1, {point_near(g.mesh, g.v(6, 5))}),
                 points_arc(9, 1, 2, {point_near(g.mesh, g.v(1, 1))}),
                 points_arc(5, 2, 3, {point_near(g.mesh, g.v(9, 1))})};
  const std::string msg = route_error(g.mesh, layout);
  EXPECT_NE(msg.find("cannot route arcs 4, 9: "), std::string::npos) << msg;
  EXPECT_NE(msg.find("arc 4: no path avoiding other arcs from vertex " + std::to_string(g.v(6, 5)) +
                     " to the mesh boundary"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("arc 9: no path avoiding other arcs between vertices " +
                     std::to_string(g.v(5, 5)) + " and " + std::to_string(g.v(1, 1))),
            std::string::npos)
      << msg;
  EXPECT_EQ(msg.find("arcs 4, 9, 5"), std::string::npos) << msg;
  // Failing arcs stay unrouted; the others are routed.
  EXPECT_TRUE(layout.arcs[4].path.empty());
  EXPECT_TRUE(layout.arcs[5].path.empty());
  expect_simple_edge_path(g.mesh, layout.arcs[6].path);
  EXPECT_EQ(layout.arcs[6].path.front(), g.v(0, 0));
  EXPECT_EQ(layout.arcs[6].path.back(), g.v(10, 10));
}

TEST(Routing, SingleFailureMessage) {
  const Grid g(5);
  Layout layout;
  layout.nodes = {node(0, g.v(1, 1))};
  layout.arcs = {points_arc(6, 0, 42, {point_near(g.mesh, g.v(2, 2))}),
                 points_arc(7, 0, -1, {SurfacePoint{0, {{0.9, 0.9, 0.9}}}})};
  const std::string msg = route_error(g.mesh, layout);
  EXPECT_NE(msg.find("cannot route arcs 6, 7: arc 6: unknown to node 42; arc 7: points[0]: "
                     "barycentric coordinates sum to 2.7"),
            std::string::npos)
      << msg;

  layout.arcs = {points_arc(6, 0, 0, {point_near(g.mesh, g.v(1, 1))})};
  const std::string msg2 = route_error(g.mesh, layout);
  EXPECT_NE(msg2.find("cannot route arc 6: all its points snap to the node vertex"),
            std::string::npos)
      << msg2;
}

TEST(Routing, DanglingArcEndsOnBoundary) {
  const Grid g(11);
  Layout layout;
  layout.nodes = {node(0, g.v(5, 5))};
  layout.arcs = {points_arc(3, 0, -1, {point_near(g.mesh, g.v(6, 5))})};
  route_layout(g.mesh, layout);
  const std::vector<int>& p = layout.arcs[0].path;
  expect_simple_edge_path(g.mesh, p);
  EXPECT_EQ(p.front(), g.v(5, 5));
  EXPECT_TRUE(g.mesh.is_boundary(OpenMesh::VertexHandle(p.back())));
  EXPECT_EQ(p.back(), g.v(10, 5));
  for (size_t k = 0; k + 1 < p.size(); ++k) {
    EXPECT_FALSE(g.mesh.is_boundary(OpenMesh::VertexHandle(p[k]))) << k;
  }

  // A dangling arc whose last point is on the boundary ends there.
  layout.arcs = {points_arc(3, 0, -1, {point_near(g.mesh, g.v(5, 0))})};
  route_layout(g.mesh, layout);
  EXPECT_EQ(layout.arcs[0].path.back(), g.v(5, 0));
  EXPECT_EQ(layout.arcs[0].path.size(), 6u);
}

TEST(Routing, ConsecutiveDuplicatePointsAreDropped) {
  const Grid g(9);
  Layout layout;
  layout.nodes = {node(0, g.v(1, 1)), node(1, g.v(7, 1))};
  const SurfacePoint p = point_near(g.mesh, g.v(4, 4));
  layout.arcs = {
      points_arc(0, 0, 1, {point_near(g.mesh, g.v(1, 1)), p, p, p, point_near(g.mesh, g.v(7, 1))})};
  route_layout(g.mesh, layout);
  expect_simple_edge_path(g.mesh, layout.arcs[0].path);
  EXPECT_EQ(layout.arcs[0].path.front(), g.v(1, 1));
  EXPECT_EQ(layout.arcs[0].path.back(), g.v(7, 1));
  EXPECT_EQ(std::count(layout.arcs[0].path.begin(), layout.arcs[0].path.end(), g.v(4, 4)), 1);
}

TEST(Routing, LoopArcReturnsToItsNode) {
  const TriMesh closed = octahedron();
  Layout layout;
  layout.nodes = {node(0, 4)};  // the top vertex
  // Through vertex 0 (face 0 = 0,2,4) and vertex 2 (face 4 = 2,0,5) back to 4, without
  // reusing an edge.
  layout.arcs = {points_arc(
      0, 0, 0, {SurfacePoint{0, {{0.8, 0.1, 0.1}}}, SurfacePoint{4, {{0.8, 0.1, 0.1}}}})};
  route_layout(closed, layout);
  const std::vector<int>& p = layout.arcs[0].path;
  EXPECT_EQ(p, (std::vector<int>{4, 0, 2, 4}));
  expect_simple_edge_path(closed, std::vector<int>(p.begin(), p.end() - 1));
}

TEST(Routing, LoadLayoutSnapsPointNodesAndRoutes) {
  const Grid g(6);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("qs_routing_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "layout.json").string();
  std::vector<int> corners;
  for (const auto vh : g.mesh.fv_range(OpenMesh::FaceHandle(7))) corners.push_back(vh.idx());
  write_file_atomic(path, R"({"format": "quadsketch-layout", "version": 1,
    "nodes": [{"id": 0, "point": {"face": 7, "bary": [0.1, 0.7, 0.2]}}, {"id": 1, "vertex": 33}],
    "arcs": [{"id": 0, "from": 0, "to": 1, "points": [{"face": 30, "bary": [0.2, 0.2, 0.6]}]}]})");
  const Layout layout = load_layout(path, g.mesh);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(layout.nodes[0].vertex, corners[1]);
  expect_simple_edge_path(g.mesh, layout.arcs[0].path);
  EXPECT_EQ(layout.arcs[0].path.front(), corners[1]);
  EXPECT_EQ(layout.arcs[0].path.back(), 33);
}

}  // namespace
}  // namespace qs
