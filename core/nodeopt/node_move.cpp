#include "core/nodeopt/node_move.h"

#include <algorithm>
#include <functional>

#include "core/base/errors.h"
#include "core/layout/separation.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// An (arc, end) pair as one integer, for same_cycle.
std::vector<int> encode(const std::vector<std::pair<int, int>>& seq) {
  std::vector<int> out;
  for (const auto& [a, e] : seq) out.push_back(2 * a + e);
  return out;
}

int node_at_end(const Layout& layout, const LayoutArc& arc, int end) {
  const int id = end == 0 ? arc.from : arc.to;
  return id >= 0 ? layout.node_index(id) : -1;
}

}  // namespace

NodeArcs node_arcs(const Layout& layout) {
  NodeArcs out;
  out.arcs.resize(layout.nodes.size());
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a) {
    for (int end = 0; end < 2; ++end) {
      const int n = node_at_end(layout, layout.arcs[a], end);
      if (n >= 0) out.arcs[n].push_back({a, end});
    }
  }
  return out;
}

std::vector<std::pair<int, int>> arcs_around(const TriMesh& mesh, const Layout& layout, int v,
                                             const std::vector<std::pair<int, int>>& incident) {
  std::vector<std::pair<int, int>> out;
  for (auto h : mesh.voh_ccw_range(VH(v))) {
    const int y = mesh.to_vertex_handle(h).idx();
    for (const auto& [a, e] : incident) {
      const std::vector<int>& p = layout.arcs[a].path;
      if (p.size() < 2) continue;
      const bool here = e == 0 ? p[0] == v && p[1] == y : p.back() == v && p[p.size() - 2] == y;
      if (here) out.push_back({a, e});
    }
  }
  return out;
}

NodeMove move_node(MeshLayout& state, LayoutOccupancy& occ, const NodeArcs& arcs, int n,
                   const SurfacePoint& target, std::vector<int>& freed,
                   const NodeMoveOptions& options) {
  WorkingMesh& w = state.mesh;
  Layout& layout = state.layout;
  const int old_v = layout.nodes[n].vertex;
  const auto& incident = arcs.arcs[n];
  for (const auto& [a, e] : incident)
    if (node_at_end(layout, layout.arcs[a], 1 - e) == n) return NodeMove::kRefused;  // a loop
  try {
    if (!w.is_input_vertex(old_v) && w.can_move_vertex(old_v, target)) {
      w.move_vertex(old_v, target);
      layout.nodes[n].point = w.origin(old_v);
      return NodeMove::kGeometry;
    }
  } catch (const InvalidInputError&) {
    return NodeMove::kRefused;
  }
  const TriMesh& m = w.mesh();
  const Vec3 p = w.position(target);
  const double step = (p - m.point(VH(old_v))).norm();
  const std::vector<int> before = encode(arcs_around(m, layout, old_v, incident));

  // Each arc, oriented from the node, and the vertex from which its old path is kept.
  struct Plan {
    int arc, end;
    std::vector<int> from_node;
    size_t splice;
    std::vector<int> route;
  };
  std::vector<Plan> plans;
  std::vector<std::pair<int, std::vector<int>>> far_before;  // nodes whose arc is re-routed whole
  for (const auto& [a, e] : incident) {
    std::vector<int> path = layout.arcs[a].path;
    if (e == 1) std::reverse(path.begin(), path.end());
    size_t splice = path.size() - 1;
    for (size_t k = options.min_splice; k + 1 < path.size(); ++k) {
      if ((m.point(VH(path[k])) - p).norm() >= options.splice_factor * step) {
        splice = k;
        break;
      }
    }
    if (splice == path.size() - 1) {
      const int far = node_at_end(layout, layout.arcs[a], 1 - e);
      if (far >= 0)
        far_before.push_back(
            {far, encode(arcs_around(m, layout, layout.nodes[far].vertex, arcs.arcs[far]))});
    }
    plans.push_back({a, e, std::move(path), splice, {}});
  }

  // The old first parts and the old node vertex are free while the new vertex is placed and the
  // new parts are routed (the node may move onto or across its old first parts); the kept tails
  // stay occupied.
  std::vector<std::vector<int>> old_paths;
  for (const Plan& plan : plans) {
    old_paths.push_back(layout.arcs[plan.arc].path);
    occ.set_path(layout.arcs[plan.arc].path, -1);
  }
  for (const Plan& plan : plans)
    occ.set_path(std::vector<int>(plan.from_node.begin() + plan.splice, plan.from_node.end()),
                 plan.arc);
  occ.set_node(old_v, -1);
  // Each splice vertex is the end of its kept tail, and no other new part may touch it: held as
  // this node's until the commit (a route may still end there).
  std::vector<int> held;
  for (const Plan& plan : plans) {
    const int s_v = plan.from_node[plan.splice];
    if (occ.node_at(s_v) < 0) {
      occ.set_node(s_v, n);
      held.push_back(s_v);
    }
  }
  auto release = [&] {
    for (int v : held) occ.set_node(v, -1);
    held.clear();
  };
  // Back to the state before the move when no vertex could be placed.
  auto restore = [&] {
    release();
    for (const Plan& plan : plans)
      occ.set_path(std::vector<int>(plan.from_node.begin() + plan.splice, plan.from_node.end()),
                   -1);
    for (size_t k = 0; k < plans.size(); ++k) occ.set_path(old_paths[k], plans[k].arc);
    occ.set_node(old_v, n);
  };
  // The new vertex: never on another arc, never splitting another arc's edge.
  int u = -1;
  try {
    u = w.insert_point(
             target, [&](int v) { return !occ.occupied(v); },
             [&](int e) { return occ.arc_on_edge(e) < 0; })
            .vertex;
  } catch (const InvalidInputError&) {
    restore();
    return NodeMove::kRefused;
  }
  if (u == old_v) {  // the point is (within the snap distance) where the node is
    restore();
    return NodeMove::kRefused;
  }
  occ.set_node(u, n);
  std::vector<std::array<int, 3>> splits;
  // The new vertex may have split an edge of an old first part.
  for (const auto& path : old_paths)
    for (size_t j = 0; j + 1 < path.size(); ++j)
      if (!w.mesh().find_halfedge(VH(path[j]), VH(path[j + 1])).is_valid() &&
          w.mesh().find_halfedge(VH(path[j]), VH(u)).is_valid() &&
          w.mesh().find_halfedge(VH(u), VH(path[j + 1])).is_valid())
        splits.push_back({path[j], path[j + 1], u});
  // Back to the old paths (edges of theirs that a new part split are followed through the split
  // vertex); false when an old edge is gone (a flip), which the caller must treat as a broken
  // state.
  auto revert = [&](size_t routed) {
    release();
    for (size_t k = 0; k < routed; ++k) {
      occ.set_path(plans[k].route, -1);
      freed.insert(freed.end(), plans[k].route.begin() + 1, plans[k].route.end() - 1);
    }
    for (const Plan& plan : plans)
      occ.set_path(std::vector<int>(plan.from_node.begin() + plan.splice, plan.from_node.end()),
                   -1);
    bool intact = true;
    // The vertices from x (excluded) to y (included) along the old edge (x, y).
    std::function<void(int, int, std::vector<int>&, int)> expand =
        [&](int x, int y, std::vector<int>& out, int depth) {
          if (w.mesh().find_halfedge(VH(x), VH(y)).is_valid()) {
            out.push_back(y);
            return;
          }
          int m = -1;
          for (const auto& [a, b, mid] : splits)
            if ((a == x && b == y) || (a == y && b == x)) m = mid;
          if (m < 0 || depth > 64) {
            intact = false;
            out.push_back(y);
            return;
          }
          expand(x, m, out, depth + 1);
          expand(m, y, out, depth + 1);
        };
    for (size_t k = 0; k < plans.size(); ++k) {
      std::vector<int> path{old_paths[k].front()};
      for (size_t j = 1; j < old_paths[k].size(); ++j)
        expand(old_paths[k][j - 1], old_paths[k][j], path, 0);
      layout.arcs[plans[k].arc].path = std::move(path);
      occ.set_path(layout.arcs[plans[k].arc].path, plans[k].arc);
    }
    layout.nodes[n].vertex = old_v;
    occ.set_node(u, -1);
    occ.set_node(old_v, n);
    freed.push_back(u);
    return intact;
  };
  // The corridor: about two edges of the input face the node moves into, or the step.
  double face_edge = 0;
  {
    const TriMesh& in = w.input();
    for (auto h : in.fh_range(in.face_handle(target.face))) face_edge += in.calc_edge_length(h);
    face_edge /= 3;
  }
  const double width = std::max(2 * face_edge, step);
  for (size_t k = 0; k < plans.size(); ++k) {
    Plan& plan = plans[k];
    RouteRequest request;
    request.guide_width = width;
    request.source = u;
    request.target = plan.from_node[plan.splice];
    request.guide.push_back(p);
    for (size_t j = 1; j <= plan.splice; ++j)
      request.guide.push_back(w.mesh().point(VH(plan.from_node[j])));
    plan.route = route_straight(w, occ, u, request.target, 0.15, nullptr, &splits);
    if (plan.route.empty()) plan.route = route_arc(w, occ, request, nullptr, &splits);
    if (plan.route.empty()) {
      return revert(k) ? NodeMove::kRefused : NodeMove::kBroken;
    }
    occ.set_path(plan.route, plan.arc);
  }

  // Commit: the new first parts joined to the tails.
  release();
  for (const Plan& plan : plans) {
    occ.set_path(plan.route, -1);
    occ.set_path(std::vector<int>(plan.from_node.begin() + plan.splice, plan.from_node.end()), -1);
  }
  for (Plan& plan : plans) {
    std::vector<int> path = plan.route;
    path.insert(path.end(), plan.from_node.begin() + plan.splice + 1, plan.from_node.end());
    if (plan.end == 1) std::reverse(path.begin(), path.end());
    layout.arcs[plan.arc].path = std::move(path);
  }
  for (const Plan& plan : plans) occ.set_path(layout.arcs[plan.arc].path, plan.arc);
  layout.nodes[n].vertex = u;

  // The cyclic order of arcs must stay at this node and at nodes whose arc was re-routed whole.
  bool same = same_cycle(before, encode(arcs_around(w.mesh(), layout, u, incident)));
  for (const auto& [far, order] : far_before)
    same = same && same_cycle(order, encode(arcs_around(w.mesh(), layout, layout.nodes[far].vertex,
                                                        arcs.arcs[far])));
  if (!same) {
    for (const Plan& plan : plans) {
      occ.set_path(layout.arcs[plan.arc].path, -1);
      occ.set_path(plan.route, plan.arc);
      occ.set_path(std::vector<int>(plan.from_node.begin() + plan.splice, plan.from_node.end()),
                   plan.arc);
    }
    return revert(plans.size()) ? NodeMove::kRefused : NodeMove::kBroken;
  }
  layout.nodes[n].point = w.origin(u);
  freed.push_back(old_v);
  for (size_t k = 0; k < plans.size(); ++k)
    for (int v : old_paths[k])
      if (!occ.occupied(v)) freed.push_back(v);
  return NodeMove::kRelaid;
}

void fill_occupancy(const MeshLayout& state, LayoutOccupancy& occ) {
  occ.clear();
  for (int n = 0; n < static_cast<int>(state.layout.nodes.size()); ++n)
    if (state.layout.nodes[n].vertex >= 0) occ.set_node(state.layout.nodes[n].vertex, n);
  for (int a = 0; a < static_cast<int>(state.layout.arcs.size()); ++a)
    occ.set_path(state.layout.arcs[a].path, a);
}

int tidy_mesh_layout(MeshLayout& state, const std::vector<int>& candidates) {
  WorkingMesh& w = state.mesh;
  int removed = 0;
  {
    LayoutOccupancy occ(w);
    fill_occupancy(state, occ);
    std::vector<int> list = candidates;
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    const int nv = static_cast<int>(w.mesh().n_vertices());
    // Several passes: a vertex whose collapse was invalid may collapse once a neighbour went.
    for (int pass = 0; pass < 3; ++pass) {
      int now = 0;
      for (int v : list) {
        if (v < 0 || v >= nv || w.is_input_vertex(v) || w.mesh().status(VH(v)).deleted()) continue;
        if (occ.occupied(v)) continue;
        now += w.remove_vertex(v, 0.0);
      }
      removed += now;
      if (now == 0) break;
    }
  }
  // Angles repaired inside input faces (never an arc edge), then room between the arcs.
  {
    LayoutOccupancy occ(w);
    fill_occupancy(state, occ);
    w.improve({}, [&](int e) { return occ.arc_on_edge(e) >= 0; });
  }
  separate_layout(w, state.layout);
  const WorkingMesh::Compaction c = w.compact();
  for (LayoutNode& node : state.layout.nodes)
    if (node.vertex >= 0) node.vertex = c.vertex[node.vertex];
  for (LayoutArc& arc : state.layout.arcs)
    for (int& v : arc.path) v = c.vertex[v];
  for (auto& [a, b] : state.layout.feature_edges) a = c.vertex[a], b = c.vertex[b];
  return removed;
}

}  // namespace qs
