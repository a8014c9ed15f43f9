#include "core/nodeopt/relocation.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/layout/routing.h"
#include "core/layout/validate.h"

namespace qs {

namespace {

Vec3 face_cross(const TriMesh& mesh, OpenMesh::FaceHandle f, int moved, const Vec3& target,
                int restored, const TriMesh& original) {
  Vec3 p[3];
  int k = 0;
  for (auto vh : mesh.fv_range(f)) {
    if (vh.idx() == moved)
      p[k] = target;
    else if (vh.idx() == restored)
      p[k] = original.point(vh);
    else
      p[k] = mesh.point(vh);
    ++k;
  }
  return (p[1] - p[0]) % (p[2] - p[0]);
}

bool ring_ok(const TriMesh& mesh, const TriMesh& original, int center, int restored, int moved,
             const Vec3& target, const RelocationOptions& options) {
  for (auto fh : mesh.vf_range(mesh.vertex_handle(center))) {
    const Vec3 c = face_cross(mesh, fh, moved, target, restored, original);
    const Vec3 c0 = face_cross(original, fh, -1, target, -1, original);
    const double l = c.norm(), l0 = c0.norm();
    if (l0 <= 0) continue;
    if (l < options.min_area_ratio * l0) return false;
    if ((c | c0) < options.min_normal_cos * l * l0) return false;
  }
  return true;
}

bool cyclic_equal(const std::vector<int>& a, const std::vector<int>& b) {
  if (a.size() != b.size()) return false;
  if (a.empty()) return true;
  for (size_t s = 0; s < b.size(); ++s) {
    if (b[s] != a[0]) continue;
    bool same = true;
    for (size_t k = 0; k < a.size() && same; ++k) same = a[k] == b[(s + k) % b.size()];
    if (same) return true;
  }
  return false;
}

}  // namespace

bool relocation_keeps_orientation(const TriMesh& mesh, const TriMesh& original, int restored,
                                  int vertex, const Vec3& target,
                                  const RelocationOptions& options) {
  if (!ring_ok(mesh, original, vertex, restored, vertex, target, options)) return false;
  if (restored >= 0 && restored != vertex &&
      !ring_ok(mesh, original, restored, restored, vertex, target, options))
    return false;
  return true;
}

int choose_relocation_vertex(const TriMesh& mesh, const TriMesh& original,
                             const SurfacePoint& target_point, const Vec3& target, int node_vertex,
                             const std::vector<char>& forbidden, const RelocationOptions& options) {
  return choose_relocation_vertex(
      mesh, original, target_point, target, node_vertex, [&](int v) { return forbidden[v] != 0; },
      options);
}

int choose_relocation_vertex(const TriMesh& mesh, const TriMesh& original,
                             const SurfacePoint& target_point, const Vec3& target, int node_vertex,
                             const std::function<bool(int)>& forbidden,
                             const RelocationOptions& options) {
  std::vector<std::pair<double, int>> candidates;
  for (auto vh : original.fv_range(original.face_handle(target_point.face))) {
    const int v = vh.idx();
    if (v != node_vertex && forbidden(v)) continue;
    candidates.push_back({(original.point(vh) - target).sqrnorm(), v});
  }
  std::sort(candidates.begin(), candidates.end());
  if (options.prefer_node_vertex) {
    for (const auto& [dist, v] : candidates)
      if (v == node_vertex && relocation_keeps_orientation(mesh, original, -1, v, target, options))
        return v;
  }
  for (const auto& [dist, v] : candidates) {
    const int restored = v == node_vertex ? -1 : node_vertex;
    if (relocation_keeps_orientation(mesh, original, restored, v, target, options)) return v;
  }
  return -1;
}

std::vector<char> forbidden_relocation_vertices(const TriMesh& mesh, const Layout& layout,
                                                int node_index, bool keep_apart) {
  std::vector<char> out(mesh.n_vertices(), 0);
  for (auto vh : mesh.vertices())
    if (mesh.is_boundary(vh)) out[vh.idx()] = 1;
  for (const auto& [a, b] : layout.feature_edges) {
    if (a >= 0 && a < static_cast<int>(out.size())) out[a] = 1;
    if (b >= 0 && b < static_cast<int>(out.size())) out[b] = 1;
  }
  const int id = layout.nodes[node_index].id;
  for (const auto& arc : layout.arcs) {
    if (arc.from == id || arc.to == id) continue;
    for (int v : arc.path) out[v] = 1;
  }
  for (size_t n = 0; n < layout.nodes.size(); ++n)
    if (static_cast<int>(n) != node_index) out[layout.nodes[n].vertex] = 1;
  if (keep_apart) {
    const std::vector<char> near = next_to_other_nodes(mesh, layout, node_index);
    for (size_t v = 0; v < out.size(); ++v) out[v] |= near[v];
  }
  return out;
}

std::vector<char> next_to_other_nodes(const TriMesh& mesh, const Layout& layout, int node_index) {
  std::vector<char> out(mesh.n_vertices(), 0);
  for (size_t n = 0; n < layout.nodes.size(); ++n) {
    if (static_cast<int>(n) == node_index) continue;
    const auto vh = mesh.vertex_handle(layout.nodes[n].vertex);
    out[vh.idx()] = 1;
    for (auto wh : mesh.vv_range(vh)) out[wh.idx()] = 1;
  }
  return out;
}

LayoutObstacles make_layout_obstacles(const TriMesh& mesh, const Layout& layout,
                                      const CurveNetwork* curves) {
  LayoutObstacles out;
  out.routing = obstacles_of_layout(mesh, layout);
  out.fixed.assign(mesh.n_vertices(), 0);
  for (auto vh : mesh.vertices())
    if (mesh.is_boundary(vh)) out.fixed[vh.idx()] = 1;
  for (const auto& [a, b] : layout.feature_edges) {
    if (a >= 0 && a < static_cast<int>(out.fixed.size())) out.fixed[a] = 1;
    if (b >= 0 && b < static_cast<int>(out.fixed.size())) out.fixed[b] = 1;
  }
  if (curves && !curves->empty())
    for (size_t v = 0; v < out.fixed.size(); ++v)
      if (!curves->neighbours[v].empty()) out.fixed[v] = 1;
  return out;
}

bool occupied_by_layout(const Layout& layout, int node_index, const LayoutObstacles& obstacles,
                        int v) {
  for (size_t n = 0; n < layout.nodes.size(); ++n)
    if (static_cast<int>(n) != node_index && layout.nodes[n].vertex == v) return true;
  if (!obstacles.routing.vertex_blocked[v]) return false;
  const int id = layout.nodes[node_index].id;
  for (const auto& arc : layout.arcs)
    if ((arc.from == id || arc.to == id) &&
        std::find(arc.path.begin(), arc.path.end(), v) != arc.path.end())
      return false;
  return true;
}

bool relocation_forbidden(const Layout& layout, int node_index, const LayoutObstacles& obstacles,
                          int v) {
  // forbidden_relocation_vertices: fixed or blocked vertices, except the node's own vertex and
  // arcs when they are not fixed, and every other node's vertex.
  if (obstacles.fixed[v] || v == layout.nodes[node_index].vertex) return obstacles.fixed[v] != 0;
  return occupied_by_layout(layout, node_index, obstacles, v);
}

bool same_layout_structure(const LayoutTopology& a, const LayoutTopology& b) {
  if (a.patches.size() != b.patches.size() || a.num_nodes != b.num_nodes) return false;
  for (int n = 0; n < a.num_nodes; ++n)
    if (!cyclic_equal(a.node_half_arcs[n], b.node_half_arcs[n])) return false;
  return true;
}

namespace {

using HH = OpenMesh::HalfedgeHandle;

// Outgoing halfedges of v in ccw order; for a boundary vertex the list starts right after the
// exterior wedge (the order build_topology uses).
std::vector<HH> outgoing_ccw(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  std::vector<HH> out;
  const HH start = mesh.halfedge_handle(v);
  if (!start.is_valid()) return out;
  auto ccw_next = [&](HH h) { return mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(h)); };
  HH boundary;
  HH h = start;
  do {
    if (mesh.is_boundary(h)) boundary = h;
    h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));
  } while (h != start);
  const HH first = boundary.is_valid() ? ccw_next(boundary) : start;
  h = first;
  do {
    out.push_back(h);
    h = ccw_next(h);
  } while (h != first);
  return out;
}

// Half-arcs at node n in counter-clockwise order (as LayoutTopology::node_half_arcs), from the
// first edges of the arcs around the node's vertex only.
std::vector<int> rotation_at(const TriMesh& mesh, const Layout& layout, int n) {
  const int id = layout.nodes[n].id;
  const int v = layout.nodes[n].vertex;
  std::vector<std::pair<int, int>> firsts;  // (second vertex of the arc from v, half-arc)
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a) {
    const LayoutArc& arc = layout.arcs[a];
    const auto& p = arc.path;
    if (p.size() < 2) continue;
    if (arc.from == id && p.front() == v) firsts.push_back({p[1], 2 * a});
    if (!arc.dangling() && arc.to == id && p.back() == v)
      firsts.push_back({p[p.size() - 2], 2 * a + 1});
  }
  std::vector<int> out;
  for (HH h : outgoing_ccw(mesh, mesh.vertex_handle(v))) {
    const int w = mesh.to_vertex_handle(h).idx();
    for (const auto& [second, half] : firsts)
      if (second == w) out.push_back(half);
  }
  return out;
}

}  // namespace

int count_patches(const TriMesh& mesh, const Layout& layout) {
  std::vector<char> wall = arc_edge_mask(mesh, layout);
  for (auto e : mesh.edges())
    if (mesh.is_boundary(e)) wall[e.idx()] = 1;
  std::vector<char> seen(mesh.n_faces(), 0);
  std::vector<int> stack;
  int patches = 0;
  for (auto f0 : mesh.faces()) {
    if (seen[f0.idx()]) continue;
    ++patches;
    seen[f0.idx()] = 1;
    stack.assign(1, f0.idx());
    while (!stack.empty()) {
      const auto f = mesh.face_handle(stack.back());
      stack.pop_back();
      for (auto h : mesh.fh_range(f)) {
        if (wall[mesh.edge_handle(h).idx()]) continue;
        const int g = mesh.opposite_face_handle(h).idx();
        if (!seen[g]) {
          seen[g] = 1;
          stack.push_back(g);
        }
      }
    }
  }
  return patches;
}

RerouteContext make_reroute_context(const TriMesh& mesh, const Layout& layout) {
  RerouteContext c;
  c.patches = count_patches(mesh, layout);
  bool closed = true;
  for (auto e : mesh.edges()) closed = closed && !mesh.is_boundary(e);
  const long chi = static_cast<long>(mesh.n_vertices()) - static_cast<long>(mesh.n_edges()) +
                   static_cast<long>(mesh.n_faces());
  // Connected: one component of faces across edges.
  std::vector<char> seen(mesh.n_faces(), 0);
  std::vector<int> stack{0};
  size_t reached = mesh.n_faces() > 0 ? 1 : 0;
  if (mesh.n_faces() > 0) seen[0] = 1;
  while (!stack.empty()) {
    const auto f = mesh.face_handle(stack.back());
    stack.pop_back();
    for (auto g : mesh.ff_range(f))
      if (!seen[g.idx()]) {
        seen[g.idx()] = 1;
        ++reached;
        stack.push_back(g.idx());
      }
  }
  c.sphere = closed && chi == 2 && reached == mesh.n_faces();
  return c;
}

CurveNetwork make_curve_network(const TriMesh& mesh, const Layout& layout, double corner_deg,
                                const std::vector<char>* sharp) {
  CurveNetwork out;
  const int nv = static_cast<int>(mesh.n_vertices());
  out.neighbours.assign(nv, {});
  out.slides.assign(nv, 0);
  auto join = [&](int a, int b) {
    if (a < 0 || b < 0 || a >= nv || b >= nv || a == b) return;
    auto& na = out.neighbours[a];
    if (std::find(na.begin(), na.end(), b) != na.end()) return;
    na.push_back(b);
    out.neighbours[b].push_back(a);
  };
  for (auto e : mesh.edges())
    if (mesh.is_boundary(e) || (sharp && (*sharp)[e.idx()])) {
      const auto h = mesh.halfedge_handle(e, 0);
      join(mesh.from_vertex_handle(h).idx(), mesh.to_vertex_handle(h).idx());
    }
  for (const auto& [a, b] : layout.feature_edges) join(a, b);
  const double min_cos = std::cos(corner_deg * M_PI / 180.0);
  for (int v = 0; v < nv; ++v) {
    const auto& n = out.neighbours[v];
    if (n.size() != 2) continue;
    const Vec3 p = mesh.point(mesh.vertex_handle(v));
    Vec3 in = p - mesh.point(mesh.vertex_handle(n[0]));
    Vec3 on = mesh.point(mesh.vertex_handle(n[1])) - p;
    const double li = in.norm(), lo = on.norm();
    if (li <= 0 || lo <= 0) continue;
    out.slides[v] = (in | on) / (li * lo) >= min_cos;
  }
  return out;
}

CurveWalk make_curve_walk(const CurveNetwork& curves, std::vector<int> vertices) {
  CurveWalk walk;
  for (int x : curves.neighbours[vertices[0]])
    if (x != vertices[1]) walk.behind = x;
  walk.vertices = std::move(vertices);
  return walk;
}

std::vector<CurveCarrier> curve_carriers(int a, int b, double s, int node_vertex,
                                         const std::vector<char>& slides,
                                         const std::function<bool(int)>& may_take) {
  std::vector<CurveCarrier> out;
  const bool b_nearer = s > 0.5;
  for (int w : b_nearer ? std::array<int, 2>{b, a} : std::array<int, 2>{a, b}) {
    if (w != node_vertex && !may_take(w)) continue;
    const bool nearer = (w == b) == b_nearer;
    const double fraction = nearer ? s : 0.5;
    const bool at_own_place = w == a ? fraction <= 0 : fraction >= 1;
    if (!slides[w] && !at_own_place) continue;
    out.push_back({w, fraction});
  }
  return out;
}

bool move_node_and_reroute(const TriMesh& mesh, Layout& layout, int node_index, int new_vertex,
                           const RelocationOptions& options, const RerouteContext* context,
                           LayoutObstacles* cache, const CurveWalk* curve) {
  const std::vector<int>* curve_walk = curve ? &curve->vertices : nullptr;
  const int old_vertex = layout.nodes[node_index].vertex;
  if (new_vertex == old_vertex) return true;
  if (curve_walk && (curve_walk->size() < 2 || curve_walk->front() != old_vertex ||
                     curve_walk->back() != new_vertex))
    return false;
  const int id = layout.nodes[node_index].id;
  // The new vertex must be free: no other node, no arc that is not incident to the node.
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n)
    if (n != node_index && layout.nodes[n].vertex == new_vertex) return false;
  for (const LayoutArc& arc : layout.arcs) {
    if (arc.from == id || arc.to == id) continue;
    if (std::find(arc.path.begin(), arc.path.end(), new_vertex) != arc.path.end()) return false;
    if (curve_walk)  // the walk is free as well
      for (size_t j = 1; j < curve_walk->size(); ++j)
        if (std::find(arc.path.begin(), arc.path.end(), (*curve_walk)[j]) != arc.path.end())
          return false;
  }
  if (curve_walk)
    for (size_t n = 0; n < layout.nodes.size(); ++n)
      for (size_t j = 1; j < curve_walk->size(); ++j)
        if (static_cast<int>(n) != node_index && layout.nodes[n].vertex == (*curve_walk)[j])
          return false;
  const std::vector<int> rotation = rotation_at(mesh, layout, node_index);
  // Incident arcs, in the node's cyclic order (a loop arc appears twice: skip those).
  std::vector<int> incident;
  for (int h : rotation) {
    const int a = LayoutTopology::arc_of(h);
    if (std::find(incident.begin(), incident.end(), a) != incident.end()) return false;
    incident.push_back(a);
  }
  for (int a : incident)
    if (layout.arcs[a].pinned) return false;
  // Nodes whose first arc edges may change: this node and the far ends of its arcs.
  std::vector<int> affected{node_index};
  for (int a : incident) {
    const LayoutArc& arc = layout.arcs[a];
    if (arc.dangling()) continue;
    const int other = layout.node_index(arc.from == id ? arc.to : arc.from);
    if (other >= 0 && std::find(affected.begin(), affected.end(), other) == affected.end())
      affected.push_back(other);
  }
  std::vector<std::vector<int>> rotations_before;
  for (int n : affected) rotations_before.push_back(rotation_at(mesh, layout, n));
  int patches_before = context ? context->patches : -1;
  LayoutTopology before;
  if (options.full_validation) before = build_topology(mesh, layout);

  // Obstacles of the layout without the node's arcs and with the node on its new vertex (the
  // same for every splice attempt).
  auto edge_of = [&](int a, int b) {
    return mesh.edge_handle(mesh.find_halfedge(mesh.vertex_handle(a), mesh.vertex_handle(b))).idx();
  };
  RoutingObstacles base;
  if (cache) {
    base = cache->routing;
    for (int a : incident) {
      const auto& path = layout.arcs[a].path;
      for (size_t j = 0; j < path.size(); ++j) {
        base.vertex_blocked[path[j]] = 0;
        if (j > 0) base.edge_blocked[edge_of(path[j - 1], path[j])] = 0;
      }
    }
    base.vertex_blocked[old_vertex] = 0;
    for (size_t n = 0; n < layout.nodes.size(); ++n)
      if (static_cast<int>(n) != node_index) base.vertex_blocked[layout.nodes[n].vertex] = 1;
    base.vertex_blocked[new_vertex] = 1;
  } else {
    Layout cleared = layout;
    cleared.nodes[node_index].vertex = new_vertex;
    for (int a : incident) cleared.arcs[a].path.clear();
    base = obstacles_of_layout(mesh, cleared);
  }

  // A slide along a curve: the arcs along the curve get their paths from the walk (the same
  // for every splice attempt); `along[i]`: 1 follows the walk, 2 leaves the other way.
  std::vector<char> along(incident.size(), 0);
  if (curve_walk) {
    const std::vector<int>& walk = *curve_walk;
    for (size_t i = 0; i < incident.size(); ++i) {
      const LayoutArc& arc = layout.arcs[incident[i]];
      std::vector<int> path = arc.path;
      if (arc.from != id) std::reverse(path.begin(), path.end());
      if (path.size() < 2) continue;
      if (path[1] == walk[1]) {  // must follow the whole walk and go on beyond it
        if (path.size() < walk.size() || (path.size() == walk.size() && !arc.dangling()))
          return false;
        if (!std::equal(walk.begin(), walk.end(), path.begin())) return false;
        along[i] = 1;
      }
    }
    // An arc leaving along the curve edge the walk turns its back on takes the walk back.
    for (size_t i = 0; i < incident.size() && curve->behind >= 0; ++i) {
      if (along[i]) continue;
      const LayoutArc& arc = layout.arcs[incident[i]];
      std::vector<int> path = arc.path;
      if (arc.from != id) std::reverse(path.begin(), path.end());
      if (path.size() >= 2 && path[1] == curve->behind) along[i] = 2;
    }
  }

  for (int k = 2; k <= std::max(2, options.max_splice_edges); ++k) {
    Layout trial = layout;
    trial.nodes[node_index].vertex = new_vertex;
    // Oriented paths (from the moving node) and the kept tails.
    std::vector<std::vector<int>> tails(incident.size()), fixed_heads(incident.size());
    for (size_t i = 0; i < incident.size(); ++i) {
      LayoutArc& arc = trial.arcs[incident[i]];
      std::vector<int> path = arc.path;
      if (arc.from != id) std::reverse(path.begin(), path.end());
      if (along[i] == 1) {  // from the new vertex on
        tails[i].assign(path.begin() + (curve_walk->size() - 1), path.end());
        fixed_heads[i] = {new_vertex};
      } else if (along[i] == 2) {  // the walk back, then the whole old path
        tails[i] = path;
        fixed_heads[i].assign(curve_walk->rbegin(), curve_walk->rend());
      } else {
        // If the new vertex lies on this arc, keep everything after it.
        const auto on = std::find(path.begin(), path.end(), new_vertex);
        size_t cut = std::min<size_t>(k, path.size() - 1);
        if (on != path.end()) cut = std::max<size_t>(cut, on - path.begin());
        // Never cut at the far end of a non-dangling arc beyond its last vertex.
        tails[i].assign(path.begin() + cut, path.end());
      }
      arc.path.clear();
    }
    RoutingObstacles obstacles = base;
    auto mark = [&](const std::vector<int>& chain) {
      for (size_t j = 0; j < chain.size(); ++j) {
        obstacles.vertex_blocked[chain[j]] = 1;
        if (j > 0) obstacles.edge_blocked[edge_of(chain[j - 1], chain[j])] = 1;
      }
    };
    for (const auto& tail : tails) mark(tail);
    for (const auto& head : fixed_heads) mark(head);
    bool ok = true;
    for (size_t i = 0; i < incident.size() && ok; ++i) {
      LayoutArc& arc = trial.arcs[incident[i]];
      std::vector<int> head;
      if (!fixed_heads[i].empty()) {
        head = fixed_heads[i];
      } else if (tails[i].front() == new_vertex) {
        head = {new_vertex};
      } else {
        head = shortest_path(mesh, new_vertex, tails[i].front(), obstacles);
        if (head.empty()) {
          ok = false;
          break;
        }
      }
      for (size_t j = 0; j < head.size(); ++j) {
        obstacles.vertex_blocked[head[j]] = 1;
        if (j > 0) obstacles.edge_blocked[edge_of(head[j - 1], head[j])] = 1;
      }
      std::vector<int> path = head;
      path.insert(path.end(), tails[i].begin() + 1, tails[i].end());
      if (arc.from != id) std::reverse(path.begin(), path.end());
      arc.path = std::move(path);
    }
    if (!ok) continue;
    if (options.full_validation) {
      if (!validate_layout(mesh, trial).valid()) continue;
      if (!same_layout_structure(before, build_topology(mesh, trial))) continue;
    } else {
      bool same = true;
      for (size_t i = 0; i < affected.size() && same; ++i)
        same = cyclic_equal(rotations_before[i], rotation_at(mesh, trial, affected[i]));
      if (!same) continue;
      if (!(context && context->sphere)) {
        if (patches_before < 0) patches_before = count_patches(mesh, layout);
        if (count_patches(mesh, trial) != patches_before) continue;
      }
    }
    layout = std::move(trial);
    if (cache) cache->routing = std::move(obstacles);  // the new paths are all marked
    return true;
  }
  return false;
}

}  // namespace qs
