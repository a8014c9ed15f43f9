#include "core/layout/embed.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <string>

#include "core/base/errors.h"
#include "core/layout/arc_router.h"
#include "core/layout/separation.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using HH = OpenMesh::HalfedgeHandle;

std::string list_problems(const std::vector<std::string>& problems) {
  std::string out =
      "cannot place the layout on the mesh (" + std::to_string(problems.size()) + " problem(s)):";
  const size_t shown = std::min<size_t>(problems.size(), 20);
  for (size_t k = 0; k < shown; ++k) out += "\n  " + problems[k];
  if (problems.size() > shown)
    out += "\n  ... and " + std::to_string(problems.size() - shown) + " more";
  return out;
}

// Arcs in breadth-first order over the layout graph (from each component's first node), so
// that each arc is routed next to arcs already placed around its nodes.
std::vector<int> breadth_first_arcs(const Layout& layout) {
  const int n = static_cast<int>(layout.nodes.size());
  std::vector<std::vector<int>> incident(n);
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a) {
    const int from = layout.node_index(layout.arcs[a].from);
    const int to = layout.arcs[a].to >= 0 ? layout.node_index(layout.arcs[a].to) : -1;
    if (from >= 0) incident[from].push_back(a);
    if (to >= 0 && to != from) incident[to].push_back(a);
  }
  std::vector<char> seen_node(n, 0), seen_arc(layout.arcs.size(), 0);
  std::vector<int> order;
  for (int start = 0; start < n; ++start) {
    if (seen_node[start]) continue;
    std::deque<int> queue{start};
    seen_node[start] = 1;
    while (!queue.empty()) {
      const int x = queue.front();
      queue.pop_front();
      for (int a : incident[x]) {
        if (seen_arc[a]) continue;
        seen_arc[a] = 1;
        order.push_back(a);
        for (int id : {layout.arcs[a].from, layout.arcs[a].to}) {
          const int y = id >= 0 ? layout.node_index(id) : -1;
          if (y >= 0 && !seen_node[y]) seen_node[y] = 1, queue.push_back(y);
        }
      }
    }
  }
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a)
    if (!seen_arc[a]) order.push_back(a);  // arcs whose nodes are unknown (reported later)
  return order;
}

double mean_input_edge(const TriMesh& m) {
  double sum = 0;
  for (auto e : m.edges()) sum += m.calc_edge_length(e);
  return m.n_edges() > 0 ? sum / m.n_edges() : 1.0;
}

// Whether surface point p of the input lies on the input's boundary (exact zeros: on a boundary
// edge, or at a boundary vertex).
bool on_input_boundary(const TriMesh& in, const SurfacePoint& p) {
  if (p.face < 0 || p.face >= static_cast<int>(in.n_faces())) return false;
  std::array<VH, 3> corner;
  int k = 0;
  for (auto v : in.fv_range(in.face_handle(p.face))) corner[k++] = v;
  for (int j = 0; j < 3; ++j) {
    if (p.bary[j] == 1 && in.is_boundary(corner[j])) return true;
    if (p.bary[j] != 0) continue;
    const HH h = in.find_halfedge(corner[(j + 1) % 3], corner[(j + 2) % 3]);
    if (h.is_valid() && in.is_boundary(in.edge_handle(h))) return true;
  }
  return false;
}

// A vertex for surface point p: a free vertex (no node, no arc) nearby is reused; a point on
// the boundary gets a boundary vertex, any other point an interior vertex; arc edges are never
// split. Throws InvalidInputError as WorkingMesh::insert_point.
WorkingMesh::Inserted insert_free(WorkingMesh& w, const LayoutOccupancy& occ,
                                  const SurfacePoint& p) {
  const bool boundary = on_input_boundary(w.input(), p);
  const TriMesh& m = w.mesh();
  const auto may_reuse = [&](int v) {
    return !occ.occupied(v) && m.is_boundary(VH(v)) == boundary;
  };
  const auto may_split = [&](int e) {
    return occ.arc_on_edge(e) < 0 && m.is_boundary(m.edge_handle(e)) == boundary;
  };
  return w.insert_point(p, may_reuse, may_split);
}

// The path along the mesh boundary from boundary vertex source to boundary vertex target
// through free vertices and free edges, the shorter of the two ways round, at most max_length
// long; empty when neither way is free.
std::vector<int> route_along_boundary(const WorkingMesh& w, const LayoutOccupancy& occ, int source,
                                      int target, double max_length) {
  const TriMesh& m = w.mesh();
  HH out;  // the boundary halfedge leaving source
  for (auto h : m.voh_range(VH(source)))
    if (m.is_boundary(h)) out = h;
  if (!out.is_valid() || !m.is_boundary(VH(target))) return {};
  std::vector<int> best;
  double best_length = max_length;
  for (int way = 0; way < 2; ++way) {
    // way 0 follows the boundary loop forwards (next halfedges), way 1 backwards.
    HH h = way == 0 ? out : m.prev_halfedge_handle(out);
    std::vector<int> path{source};
    double length = 0;
    while (true) {
      const int v = (way == 0 ? m.to_vertex_handle(h) : m.from_vertex_handle(h)).idx();
      length += m.calc_edge_length(h);
      if (length > best_length || occ.arc_on_edge(m.edge_handle(h).idx()) >= 0) break;
      path.push_back(v);
      if (v == target) {
        best = path;
        best_length = length;
        break;
      }
      if (v == source || occ.occupied(v)) break;
      h = way == 0 ? m.next_halfedge_handle(h) : m.prev_halfedge_handle(h);
    }
  }
  return best;
}

// Routes arc a from vertex source to vertex target through its points in order (see
// EmbedOptions::through_points); along the boundary when `boundary`. Returns the path, or an
// empty path (then the occupancy is as before; vertices placed for points stay, free).
std::vector<int> route_through_points(WorkingMesh& w, LayoutOccupancy& occ, int a, int source,
                                      int target, const std::vector<SurfacePoint>& points,
                                      bool boundary, EmbedStats& stats) {
  const TriMesh& m = w.mesh();
  std::vector<int> path{source};
  // Marks path[from..] (the new segment and the vertex before it) as arc a's.
  auto mark_tail = [&](size_t from) {
    occ.set_path(std::vector<int>(path.begin() + static_cast<long>(from), path.end()), a);
  };
  for (size_t i = 0; i <= points.size(); ++i) {
    const bool last = i == points.size();
    int goal = target;
    if (!last) {
      try {
        goal = insert_free(w, occ, points[i]).vertex;
      } catch (const InvalidInputError&) {
        ++stats.skipped_points;
        continue;
      }
      occ.sync();
      if (goal == path.back() || occ.occupied(goal)) {
        ++stats.skipped_points;
        continue;
      }
      ++stats.point_vertices;
    }
    const int c = path.back();
    const Vec3 xc = m.point(VH(c)), xg = m.point(VH(goal));
    const double length = (xg - xc).norm();
    std::vector<int> segment;
    if (boundary) {
      segment = route_along_boundary(w, occ, c, goal, 3 * length + 1e-12);
    } else {
      segment = route_straight(w, occ, c, goal, 0.15, &stats.route_splits);
      if (segment.empty()) {
        RouteRequest request;
        request.source = c;
        request.target = goal;
        request.guide = {xc, xg};
        request.guide_width = length;
        segment = route_arc(w, occ, request, &stats.route_splits);
      }
    }
    if (segment.size() < 2) {
      if (!last) {
        ++stats.skipped_points;
        continue;
      }
      occ.set_path(path, -1);
      return {};
    }
    const size_t from = path.size() >= 2 ? path.size() - 2 : 0;
    path.insert(path.end(), segment.begin() + 1, segment.end());
    mark_tail(from);
  }
  return path;
}

}  // namespace

void validate_embed_options(const EmbedOptions& options) {
  validate_working_mesh_options(options.mesh);
  if (!std::isfinite(options.corridor) || options.corridor <= 0 || options.corridor > 1e3)
    throw InvalidInputError("embedding: corridor must be in (0, 1000] mean edge lengths, got " +
                            std::to_string(options.corridor));
}

std::vector<int> working_path_of_input_path(const WorkingMesh& mesh,
                                            const std::vector<int>& input_path) {
  const TriMesh& in = mesh.input();
  const TriMesh& m = mesh.mesh();
  std::vector<int> out;
  if (input_path.empty()) return out;
  out.push_back(input_path[0]);
  for (size_t k = 0; k + 1 < input_path.size(); ++k) {
    const int a = input_path[k], b = input_path[k + 1];
    const int n = static_cast<int>(in.n_vertices());
    if (a < 0 || b < 0 || a >= n || b >= n || !in.find_halfedge(VH(a), VH(b)).is_valid()) return {};
    const std::array<int, 2> key{std::min(a, b), std::max(a, b)};
    int current = a, previous = -1;
    for (size_t guard = 0; guard <= m.n_vertices() && current != b; ++guard) {
      int next = -1;
      for (auto x : m.vv_range(VH(current))) {
        const int xi = x.idx();
        if (xi == b) {
          next = b;
          break;
        }
        if (xi == previous || mesh.is_input_vertex(xi)) continue;
        const auto edge = mesh.input_edge_of(xi);
        if (edge && *edge == key) next = xi;
      }
      if (next < 0) return {};
      previous = current;
      current = next;
      out.push_back(current);
    }
    if (current != b) return {};
  }
  return out;
}

namespace {

// Arcs that found no route in one attempt of embed_layout.
struct RouteFailures {
  std::vector<std::string> problems;
  std::vector<int> arcs;
};

// One attempt of embed_layout, routing the arcs in \p first right after the boundary arcs.
// \throw RouteFailures when only arc routes failed, InvalidInputError for other problems.
EmbeddedLayout embed_attempt(std::shared_ptr<const TriMesh> input, const Layout& layout_in,
                             const EmbedOptions& options, const std::vector<int>& first) {
  EmbeddedLayout result;
  result.mesh = std::make_shared<WorkingMesh>(input, options.mesh);
  WorkingMesh& w = *result.mesh;
  Layout& layout = result.layout;
  layout = layout_in;
  std::vector<std::string> problems;
  LayoutOccupancy occ(w);

  // 1. Nodes. Two nodes at one surface point cannot both get a vertex there.
  {
    std::vector<std::pair<std::array<double, 3>, int>> at;
    for (int i = 0; i < static_cast<int>(layout.nodes.size()); ++i) {
      const LayoutNode& node = layout.nodes[i];
      if (node.vertex >= 0 || !node.point) continue;
      try {
        const Vec3 p = w.position(*node.point);
        at.push_back({{p[0], p[1], p[2]}, i});
      } catch (const InvalidInputError&) {
      }
    }
    std::sort(at.begin(), at.end());
    for (size_t k = 1; k < at.size(); ++k) {
      if (at[k].first == at[k - 1].first) {
        problems.push_back("node " + std::to_string(layout.nodes[at[k].second].id) + " and node " +
                           std::to_string(layout.nodes[at[k - 1].second].id) +
                           " are at the same surface point");
      }
    }
    if (!problems.empty()) throw InvalidInputError(list_problems(problems));
  }
  const int n_input = w.input_vertices();
  for (int i = 0; i < static_cast<int>(layout.nodes.size()); ++i) {
    LayoutNode& node = layout.nodes[i];
    const std::string who = "node " + std::to_string(node.id);
    if (node.vertex >= 0) {
      if (node.vertex >= n_input) {
        problems.push_back(who + ": vertex " + std::to_string(node.vertex) +
                           " is not a vertex of the mesh (" + std::to_string(n_input) +
                           " vertices)");
        node.vertex = -1;
        continue;
      }
    } else if (node.point) {
      try {
        // A node on the boundary gets a boundary vertex, any other node an interior vertex.
        const bool boundary = on_input_boundary(w.input(), *node.point);
        const TriMesh& m = w.mesh();
        const auto may_reuse = [&](int v) {
          return occ.node_at(v) < 0 && m.is_boundary(VH(v)) == boundary;
        };
        const auto may_split = [&](int e) { return m.is_boundary(m.edge_handle(e)) == boundary; };
        const WorkingMesh::Inserted ins = w.insert_point(*node.point, may_reuse, may_split);
        node.vertex = ins.vertex;
        ++(ins.created ? result.stats.inserted_nodes : result.stats.snapped_nodes);
      } catch (const InvalidInputError& e) {
        problems.push_back(who + ": " + e.what());
        continue;
      }
    } else {
      problems.push_back(who + ": neither a vertex nor a point");
      continue;
    }
    const int other = occ.node_at(node.vertex);
    if (other >= 0) {
      problems.push_back(who + " and node " + std::to_string(layout.nodes[other].id) +
                         " are on the same vertex " + std::to_string(node.vertex));
      continue;
    }
    occ.set_node(node.vertex, i);
  }
  if (!problems.empty()) throw InvalidInputError(list_problems(problems));

  // 2. Arcs along input edge paths.
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a) {
    LayoutArc& arc = layout.arcs[a];
    if (arc.path.empty()) continue;
    const std::vector<int> path = working_path_of_input_path(w, arc.path);
    const std::string who = "arc " + std::to_string(arc.id);
    if (path.empty()) {
      problems.push_back(who + ": its path is not a chain of mesh edges");
      continue;
    }
    for (size_t k = 1; k + 1 < path.size(); ++k) {
      const int n = occ.node_at(path[k]);
      if (n >= 0)
        problems.push_back(who + " passes through node " + std::to_string(layout.nodes[n].id));
    }
    arc.path = path;
    occ.set_path(path, a);
  }
  if (!problems.empty()) throw InvalidInputError(list_problems(problems));

  // 3. Arcs along the boundary (all their points on it) first, then the others breadth-first.
  const double width = options.corridor * mean_input_edge(w.input());
  std::vector<char> along_boundary(layout.arcs.size(), 0);
  std::vector<int> order;
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a) {
    const LayoutArc& arc = layout.arcs[a];
    const int from = layout.node_index(arc.from);
    const int to = arc.to >= 0 ? layout.node_index(arc.to) : -1;
    if (!arc.path.empty() || arc.points.empty() || from < 0 || to < 0) continue;
    bool on = w.mesh().is_boundary(VH(layout.nodes[from].vertex)) &&
              w.mesh().is_boundary(VH(layout.nodes[to].vertex));
    for (const SurfacePoint& p : arc.points) on = on && on_input_boundary(w.input(), p);
    if (!on) continue;
    along_boundary[a] = 1;
    order.push_back(a);
  }
  std::vector<char> queued = along_boundary;
  for (int a : first) {
    if (queued[a]) continue;
    queued[a] = 1;
    order.push_back(a);
  }
  for (int a : breadth_first_arcs(layout))
    if (!queued[a]) order.push_back(a);
  std::vector<int> failed;
  for (int a : order) {
    LayoutArc& arc = layout.arcs[a];
    if (!arc.path.empty()) continue;
    const std::string who = "arc " + std::to_string(arc.id);
    const int from = layout.node_index(arc.from);
    const int to = arc.to >= 0 ? layout.node_index(arc.to) : -1;
    if (from < 0 || (arc.to >= 0 && to < 0)) {
      problems.push_back(who + ": unknown node id " + std::to_string(from < 0 ? arc.from : arc.to));
      continue;
    }
    RouteRequest request;
    request.source = layout.nodes[from].vertex;
    request.target = to >= 0 ? layout.nodes[to].vertex : -1;
    if (along_boundary[a] || (options.through_points && to >= 0)) {
      std::vector<SurfacePoint> points = arc.points;
      bool valid = true;
      for (const SurfacePoint& p : points) {
        try {
          w.position(p);
        } catch (const InvalidInputError& e) {
          problems.push_back(who + ": " + e.what());
          valid = false;
          break;
        }
      }
      if (!valid) continue;
      std::vector<int> path = route_through_points(w, occ, a, request.source, request.target,
                                                   points, along_boundary[a] != 0, result.stats);
      if (path.empty() && !along_boundary[a]) {
        // The points may crowd another arc's (polylines that touch): one route guided by them.
        request.guide.push_back(w.mesh().point(VH(request.source)));
        for (const SurfacePoint& p : points) request.guide.push_back(w.position(p));
        request.guide.push_back(w.mesh().point(VH(request.target)));
        request.guide_width = width;
        path = route_arc(w, occ, request, &result.stats.route_splits);
        if (!path.empty()) ++result.stats.guided_arcs;
      }
      if (path.empty()) {
        failed.push_back(a);
        problems.push_back(who + " (node " + std::to_string(arc.from) + " to node " +
                           std::to_string(arc.to) + "): no route through its points that " +
                           "avoids the arcs and nodes placed before it" +
                           (along_boundary[a] ? " along the boundary" : ""));
        continue;
      }
      arc.path = std::move(path);
      arc.points.clear();
      occ.set_path(arc.path, a);
      continue;
    }
    if (!arc.points.empty()) {
      request.guide.push_back(w.mesh().point(VH(request.source)));
      try {
        for (const SurfacePoint& p : arc.points) request.guide.push_back(w.position(p));
      } catch (const InvalidInputError& e) {
        problems.push_back(who + ": " + e.what());
        continue;
      }
      if (request.target >= 0) request.guide.push_back(w.mesh().point(VH(request.target)));
      request.guide_width = width;
    }
    std::vector<int> path = route_arc(w, occ, request, &result.stats.route_splits);
    if (path.empty() && !request.guide.empty()) {  // the corridor may be too tight: unguided
      request.guide.clear();
      path = route_arc(w, occ, request, &result.stats.route_splits);
    }
    if (path.empty()) {
      failed.push_back(a);
      problems.push_back(who + " (node " + std::to_string(arc.from) + " to " +
                         (arc.to >= 0 ? "node " + std::to_string(arc.to) : "the boundary") +
                         "): no route that avoids the arcs and nodes placed before it");
      continue;
    }
    arc.path = std::move(path);
    arc.points.clear();
    occ.set_path(arc.path, a);
  }
  if (!problems.empty() && failed.size() == problems.size()) throw RouteFailures{problems, failed};
  if (!problems.empty()) throw InvalidInputError(list_problems(problems));

  // 4. Angles, then room.
  result.stats.flips = w.improve({}, [&](int e) { return occ.arc_on_edge(e) >= 0; });
  result.stats.separation_splits = separate_layout(w, layout);

  // Feature edges follow their input edges' pieces.
  std::vector<std::array<int, 2>> features;
  for (const auto& [a, b] : layout.feature_edges) {
    const std::vector<int> chain = working_path_of_input_path(w, {a, b});
    for (size_t k = 0; k + 1 < chain.size(); ++k) features.push_back({chain[k], chain[k + 1]});
  }
  layout.feature_edges = std::move(features);
  for (LayoutNode& node : layout.nodes) node.point = w.origin(node.vertex);
  // The working mesh changes as nodes move: the layout names no mesh size.
  layout.mesh_vertices = layout.mesh_faces = -1;
  return result;
}

}  // namespace

EmbeddedLayout embed_layout(std::shared_ptr<const TriMesh> input, const Layout& layout,
                            const EmbedOptions& options) {
  validate_embed_options(options);
  // Arcs that find no route are routed first in up to 3 more attempts: an arc routed earlier
  // may have taken the room it needed.
  std::vector<int> first;
  for (int attempt = 1;; ++attempt) {
    try {
      EmbeddedLayout result = embed_attempt(input, layout, options, first);
      result.stats.attempts = attempt;
      return result;
    } catch (const RouteFailures& failures) {
      if (attempt == 4) throw InvalidInputError(list_problems(failures.problems));
      for (int a : failures.arcs)
        if (std::find(first.begin(), first.end(), a) == first.end()) first.push_back(a);
    }
  }
}

}  // namespace qs
