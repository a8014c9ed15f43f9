#include "core/layout/routing.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <tuple>
#include <unordered_map>
#include <utility>

#include "core/base/errors.h"

namespace qs {

namespace {

using VertexHandle = OpenMesh::VertexHandle;

bool is_set(const std::vector<char>& flags, int i) {
  return i >= 0 && static_cast<size_t>(i) < flags.size() && flags[i] != 0;
}

bool valid_vertex(const TriMesh& mesh, int v) {
  return v >= 0 && static_cast<size_t>(v) < mesh.n_vertices();
}

//! Shortest text that reads back as \p d.
std::string format_double(double d) {
  std::array<char, 32> buffer{};
  const auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), d);
  return std::string(buffer.data(), result.ptr);
}

//! Dijkstra over mesh edges from \p source, never entering blocked vertices (except a vertex
//! for which \p is_target holds) or crossing blocked edges. Stops at the first settled vertex
//! for which \p is_target holds and returns the vertex path to it (empty when none is
//! reachable). The source itself is never a target. With \p goal (the position of the only
//! target vertex), the search is A*: vertices are settled in the order of their distance plus
//! the straight-line distance to the goal, a consistent lower bound of the remaining length
//! (every edge is at least as long as the difference of its ends' distances to the goal), so
//! the path is still a shortest one while the search settles mostly vertices towards the goal.
std::vector<int> dijkstra(const TriMesh& mesh, int source, const RoutingObstacles& obstacles,
                          const std::function<bool(int)>& is_target, const Vec3* goal = nullptr) {
  if (!valid_vertex(mesh, source)) return {};
  const double inf = std::numeric_limits<double>::infinity();
  // Per-thread distances and parents, reset only where a search wrote: re-routing a node runs
  // thousands of short searches per descent step on a 70K-face mesh, and filling two
  // #V-sized arrays per search cost more than the searches.
  struct Workspace {
    std::vector<double> dist;
    std::vector<int> parent, touched;
  };
  thread_local Workspace ws;
  const size_t nv = mesh.n_vertices();
  if (ws.dist.size() < nv) {
    ws.dist.assign(nv, inf);
    ws.parent.assign(nv, -1);
  }
  std::vector<double>& dist = ws.dist;
  std::vector<int>& parent = ws.parent;
  auto set = [&](int v, double d, int p) {
    if (dist[v] == inf) ws.touched.push_back(v);
    dist[v] = d;
    parent[v] = p;
  };
  // (key, distance, vertex): the key is the distance, plus the goal bound for A*.
  using Entry = std::tuple<double, double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  auto bound = [&](VertexHandle w) { return goal ? (mesh.point(w) - *goal).norm() : 0.0; };
  set(source, 0.0, -1);
  queue.emplace(bound(VertexHandle(source)), 0.0, source);
  int found = -1;
  while (!queue.empty()) {
    const auto [key, d, v] = queue.top();
    queue.pop();
    if (d > dist[v]) continue;
    if (v != source && is_target(v)) {
      found = v;
      break;
    }
    const VertexHandle vh(v);
    for (const auto heh : mesh.voh_range(vh)) {
      if (is_set(obstacles.edge_blocked, mesh.edge_handle(heh).idx())) continue;
      const int w = mesh.to_vertex_handle(heh).idx();
      if (is_set(obstacles.vertex_blocked, w) && !is_target(w)) continue;
      const double nd = d + (mesh.point(mesh.to_vertex_handle(heh)) - mesh.point(vh)).norm();
      if (nd < dist[w]) {
        set(w, nd, v);
        queue.emplace(nd + bound(mesh.to_vertex_handle(heh)), nd, w);
      }
    }
  }
  std::vector<int> path;
  for (int v = found; v >= 0; v = parent[v]) path.push_back(v);
  std::reverse(path.begin(), path.end());
  for (int v : ws.touched) {
    dist[v] = inf;
    parent[v] = -1;
  }
  ws.touched.clear();
  return path;
}

//! Whether \p target can be reached from \p source by the paths dijkstra takes (no blocked
//! edge crossed, no blocked vertex entered except the target itself). Breadth-first searches from
//! both ends, one vertex of each in turn, until they meet (reachable) or one of them has nothing
//! left (not reachable): re-routing a moved node asks for many paths that do not exist (the
//! arcs around enclose the start), and such a search then costs about twice the smaller of the
//! two enclosed regions, unweighted, instead of an A* search of the whole region around the
//! start.
bool reachable(const TriMesh& mesh, int source, int target, const RoutingObstacles& obstacles) {
  if (source == target) return true;
  struct Workspace {
    std::vector<char> side;  // 0: unseen, 1: from the source, 2: from the target
    std::vector<int> queue[2], touched;
  };
  thread_local Workspace ws;
  const size_t nv = mesh.n_vertices();
  if (ws.side.size() < nv) ws.side.assign(nv, 0);
  ws.queue[0].assign(1, source);
  ws.queue[1].assign(1, target);
  ws.side[source] = 1;
  ws.side[target] = 2;
  ws.touched.assign({source, target});
  size_t head[2] = {0, 0};
  const int ends[2] = {target, source};  // the vertex each search may enter although blocked
  bool met = false;
  while (!met && head[0] < ws.queue[0].size() && head[1] < ws.queue[1].size()) {
    for (int k = 0; k < 2 && !met; ++k) {
      const int v = ws.queue[k][head[k]++];
      for (const auto heh : mesh.voh_range(VertexHandle(v))) {
        if (is_set(obstacles.edge_blocked, mesh.edge_handle(heh).idx())) continue;
        const int w = mesh.to_vertex_handle(heh).idx();
        if (w != ends[k] && is_set(obstacles.vertex_blocked, w)) continue;
        if (ws.side[w] == k + 1) continue;
        if (ws.side[w] != 0) {  // reached by the other search
          met = true;
          break;
        }
        ws.side[w] = static_cast<char>(k + 1);
        ws.touched.push_back(w);
        ws.queue[k].push_back(w);
      }
    }
  }
  for (int v : ws.touched) ws.side[v] = 0;
  return met;
}

//! Marks vertices and edges and remembers which flags it set, so they can be cleared again.
class ObstacleMarker {
 public:
  ObstacleMarker(const TriMesh& mesh, RoutingObstacles& obstacles)
      : mesh_(mesh), obstacles_(obstacles) {}

  void mark_vertex(int v) {
    if (!valid_vertex(mesh_, v) || static_cast<size_t>(v) >= obstacles_.vertex_blocked.size()) {
      return;
    }
    if (!obstacles_.vertex_blocked[v]) {
      obstacles_.vertex_blocked[v] = 1;
      vertices_.push_back(v);
    }
  }

  //! Marks the path's vertices and its edges (pairs that are not mesh edges are skipped).
  void mark_path(const std::vector<int>& path) {
    for (size_t k = 0; k < path.size(); ++k) {
      mark_vertex(path[k]);
      if (k == 0 || !valid_vertex(mesh_, path[k - 1]) || !valid_vertex(mesh_, path[k])) continue;
      const auto heh = mesh_.find_halfedge(VertexHandle(path[k - 1]), VertexHandle(path[k]));
      if (!heh.is_valid()) continue;
      const int e = mesh_.edge_handle(heh).idx();
      if (static_cast<size_t>(e) < obstacles_.edge_blocked.size() && !obstacles_.edge_blocked[e]) {
        obstacles_.edge_blocked[e] = 1;
        edges_.push_back(e);
      }
    }
  }

  //! Clears every flag this marker set.
  void undo() {
    for (int v : vertices_) obstacles_.vertex_blocked[v] = 0;
    for (int e : edges_) obstacles_.edge_blocked[e] = 0;
    vertices_.clear();
    edges_.clear();
  }

 private:
  const TriMesh& mesh_;
  RoutingObstacles& obstacles_;
  std::vector<int> vertices_;
  std::vector<int> edges_;
};

//! Vertices of face \p p.face ordered by decreasing barycentric coordinate (ties: corner order).
std::array<int, 3> vertices_by_weight(const TriMesh& mesh, const SurfacePoint& p) {
  std::array<int, 3> corners{};
  int k = 0;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(p.face))) {
    if (k < 3) corners[k++] = vh.idx();
  }
  std::array<int, 3> order{{0, 1, 2}};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return p.bary[a] > p.bary[b]; });
  return {{corners[order[0]], corners[order[1]], corners[order[2]]}};
}

//! Routes one arc given by points. Returns the path, or an empty path and sets \p reason.
//! On success the path is marked in \p obstacles; on failure \p obstacles is unchanged.
std::vector<int> route_arc(const TriMesh& mesh, const LayoutArc& arc, int from_vertex,
                           int to_vertex, RoutingObstacles& obstacles, std::string& reason) {
  ObstacleMarker marker(mesh, obstacles);
  std::vector<int> path{from_vertex};
  marker.mark_vertex(from_vertex);

  auto fail = [&](std::string why) {
    marker.undo();
    reason = std::move(why);
    return std::vector<int>();
  };
  auto no_path = [&](int a, int b) {
    return "no path avoiding other arcs between vertices " + std::to_string(a) + " and " +
           std::to_string(b);
  };
  // Extends the path to \p target along a shortest path (target may be blocked).
  auto extend_to = [&](int target) {
    const int current = path.back();
    if (target == current) return true;
    const std::vector<int> piece = shortest_path(mesh, current, target, obstacles);
    if (piece.empty()) return false;
    marker.mark_path(piece);
    path.insert(path.end(), piece.begin() + 1, piece.end());
    return true;
  };

  for (size_t k = 0; k < arc.points.size(); ++k) {
    const SurfacePoint& p = arc.points[k];
    try {
      snap_to_vertex(mesh, p);  // validates the point
    } catch (const InvalidInputError& e) {
      return fail("points[" + std::to_string(k) + "]: " + e.what());
    }
    // Snap to the heaviest corner that the route may still use: the current end (a duplicate,
    // dropped), the arc's own end node after its last point, or any unblocked vertex.
    const bool last = k + 1 == arc.points.size();
    int waypoint = -1;
    for (int v : vertices_by_weight(mesh, p)) {
      if (v == path.back() || (last && v == to_vertex) || !is_set(obstacles.vertex_blocked, v)) {
        waypoint = v;
        break;
      }
    }
    if (waypoint < 0) {
      return fail("points[" + std::to_string(k) + "] lies in face " + std::to_string(p.face) +
                  " whose vertices are all used by other arcs or nodes");
    }
    if (!extend_to(waypoint)) return fail(no_path(path.back(), waypoint));
  }

  if (to_vertex >= 0) {
    if (!extend_to(to_vertex)) return fail(no_path(path.back(), to_vertex));
  } else if (!(path.size() > 1 && mesh.is_boundary(VertexHandle(path.back())))) {
    const std::vector<int> piece = shortest_path_to_boundary(mesh, path.back(), obstacles);
    if (piece.empty()) {
      return fail("no path avoiding other arcs from vertex " + std::to_string(path.back()) +
                  " to the mesh boundary");
    }
    marker.mark_path(piece);
    path.insert(path.end(), piece.begin() + 1, piece.end());
  }
  if (path.size() < 2) {
    return fail("all its points snap to the node vertex " + std::to_string(from_vertex));
  }
  return path;
}

}  // namespace

int snap_to_vertex(const TriMesh& mesh, const SurfacePoint& p) {
  if (p.face < 0 || static_cast<size_t>(p.face) >= mesh.n_faces()) {
    throw InvalidInputError("face " + std::to_string(p.face) + " out of range (mesh has " +
                            std::to_string(mesh.n_faces()) + " faces)");
  }
  double sum = 0.0;
  for (double b : p.bary) {
    if (!std::isfinite(b)) throw InvalidInputError("barycentric coordinates are not finite");
    if (b < -1e-9) {
      throw InvalidInputError("barycentric coordinate " + format_double(b) + " is negative");
    }
    sum += b;
  }
  if (std::fabs(sum - 1.0) > 1e-6) {
    throw InvalidInputError("barycentric coordinates sum to " + format_double(sum) +
                            ", not 1 (tolerance 1e-6)");
  }
  if (mesh.valence(OpenMesh::FaceHandle(p.face)) != 3) {
    throw InvalidInputError("face " + std::to_string(p.face) + " is not a triangle");
  }
  return vertices_by_weight(mesh, p)[0];
}

RoutingObstacles obstacles_of_layout(const TriMesh& mesh, const Layout& layout) {
  RoutingObstacles obstacles;
  obstacles.vertex_blocked.assign(mesh.n_vertices(), 0);
  obstacles.edge_blocked.assign(mesh.n_edges(), 0);
  ObstacleMarker marker(mesh, obstacles);
  for (const LayoutArc& arc : layout.arcs) marker.mark_path(arc.path);
  for (const LayoutNode& node : layout.nodes) marker.mark_vertex(node.vertex);
  return obstacles;
}

std::vector<int> shortest_path(const TriMesh& mesh, int source, int target,
                               const RoutingObstacles& obstacles) {
  if (!valid_vertex(mesh, source) || !valid_vertex(mesh, target)) return {};
  if (source == target) return {source};
  if (!reachable(mesh, source, target, obstacles)) return {};
  const Vec3 goal = mesh.point(VertexHandle(target));
  return dijkstra(
      mesh, source, obstacles, [target](int v) { return v == target; }, &goal);
}

std::vector<int> shortest_path_to_boundary(const TriMesh& mesh, int source,
                                           const RoutingObstacles& obstacles) {
  return dijkstra(mesh, source, obstacles, [&](int v) {
    return mesh.is_boundary(VertexHandle(v)) && !is_set(obstacles.vertex_blocked, v);
  });
}

void route_layout(const TriMesh& mesh, Layout& layout) {
  bool any = false;
  for (const LayoutArc& arc : layout.arcs) any = any || (arc.path.empty() && !arc.points.empty());
  if (!any) return;

  // First node with each id (duplicate ids are reported by validate_layout).
  std::unordered_map<int, int> node_vertex;
  for (const LayoutNode& node : layout.nodes) node_vertex.emplace(node.id, node.vertex);
  auto vertex_of = [&](int id, const std::string& role, std::string& reason) {
    const auto it = node_vertex.find(id);
    if (it == node_vertex.end()) {
      reason = "unknown " + role + " node " + std::to_string(id);
      return -1;
    }
    if (!valid_vertex(mesh, it->second)) {
      reason = role + " node " + std::to_string(id) + " has no valid vertex (" +
               std::to_string(it->second) + ")";
      return -1;
    }
    return it->second;
  };

  RoutingObstacles obstacles = obstacles_of_layout(mesh, layout);
  std::vector<int> failed;
  std::vector<std::string> reasons;
  for (LayoutArc& arc : layout.arcs) {
    if (!arc.path.empty() || arc.points.empty()) continue;
    std::string reason;
    const int from_vertex = vertex_of(arc.from, "from", reason);
    const int to_vertex = arc.dangling() ? -1 : vertex_of(arc.to, "to", reason);
    if (reason.empty()) {
      arc.path = route_arc(mesh, arc, from_vertex, to_vertex, obstacles, reason);
    }
    if (!reason.empty()) {
      arc.path.clear();
      failed.push_back(arc.id);
      reasons.push_back(std::move(reason));
    }
  }
  if (failed.empty()) return;

  std::string msg = failed.size() == 1 ? "cannot route arc " : "cannot route arcs ";
  for (size_t k = 0; k < failed.size(); ++k) msg += (k ? ", " : "") + std::to_string(failed[k]);
  if (failed.size() == 1) {
    msg += ": " + reasons[0];
  } else {
    for (size_t k = 0; k < failed.size(); ++k) {
      msg += (k ? "; arc " : ": arc ") + std::to_string(failed[k]) + ": " + reasons[k];
    }
  }
  throw InvalidInputError(msg);
}

}  // namespace qs
