#include "core/import/quad_import.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>

#include "core/base/errors.h"
#include "core/layout/path_finder.h"
#include "core/layout/routing.h"
#include "core/layout/validate.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/write_checks.h"

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;
using VH = OpenMesh::VertexHandle;

std::string join_ids(const std::vector<int>& ids, size_t max_count = 20) {
  std::ostringstream ss;
  for (size_t i = 0; i < ids.size() && i < max_count; ++i) ss << (i ? ", " : "") << ids[i];
  if (ids.size() > max_count) ss << ", ... (" << ids.size() << " in all)";
  return ss.str();
}

// The triangulation passes the mesh reader's checks; degenerate triangles are traced to their
// quads (2·refine² triangles per quad). \throw InvalidInputError otherwise.
void require_readable_triangulation(const TriMesh& mesh, int refine) {
  const MeshReport report = check_as_read(mesh);
  if (report.ok()) return;
  std::vector<int> quads;
  for (int f : report.degenerate_faces) quads.push_back(f / (2 * refine * refine));
  quads.erase(std::unique(quads.begin(), quads.end()), quads.end());
  throw InvalidInputError(
      rejection_message(report, "the triangulation of the quad mesh (refine " +
                                    std::to_string(refine) + "; face ids are its triangles)") +
      (quads.empty() ? ""
                     : "\n  the degenerate triangles lie in quads " + join_ids(quads) +
                           ": too thin or too small to triangulate"));
}

std::string format_length(double d) {
  std::ostringstream ss;
  ss.precision(3);
  ss << d;
  return ss.str();
}

// Mean edge length and bounding-box diagonal.
template <typename MeshT>
std::pair<double, double> mesh_scales(const MeshT& mesh) {
  double sum = 0;
  for (const auto e : mesh.edges()) sum += mesh.calc_edge_length(e);
  const double mean = mesh.n_edges() ? sum / mesh.n_edges() : 0.0;
  const double inf = std::numeric_limits<double>::infinity();
  Vec3 lo(inf, inf, inf), hi(-inf, -inf, -inf);
  for (const auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  return {mean, mesh.n_vertices() ? (hi - lo).norm() : 0.0};
}

// Routes a quad complex onto a target triangle mesh (see transfer_complex).
class Transfer {
 public:
  Transfer(const PolyMesh& quads, const QuadComplex& complex, const TriMesh& target,
           const QuadImportOptions& options)
      : quads_(quads),
        complex_(complex),
        target_(target),
        options_(options),
        tree_(target),
        finder_(target) {
    std::tie(mean_edge_, diagonal_) = mesh_scales(target);
    max_distance_ = options.max_distance_fraction * diagonal_;
    const size_t nv = target.n_vertices();
    obstacles_.vertex_blocked.assign(nv, 0);
    obstacles_.edge_blocked.assign(target.n_edges(), 0);
    allowed_.assign(nv, 0);
    cost_.assign(nv, 1.0);
    curve_distance_.assign(nv, std::numeric_limits<double>::infinity());
    visit_stamp_.assign(nv, 0);
    exit_owner_.assign(nv, -1);
  }

  Layout run() {
    Layout layout;
    layout.mesh_vertices = static_cast<int>(target_.n_vertices());
    layout.mesh_faces = static_cast<int>(target_.n_faces());
    place_nodes(layout);
    route_arcs(layout);
    require_valid_layout(target_, layout, "the transferred layout");
    check_cyclic_orders(layout);
    return layout;
  }

 private:
  struct Sample {
    Vec3 point;  // on the target surface
    int face = -1;
  };

  void place_nodes(Layout& layout) {
    const int n_nodes = static_cast<int>(complex_.node_vertex.size());
    std::vector<int> far, stuck;
    std::vector<std::string> far_text;
    node_target_vertex_.assign(n_nodes, -1);
    for (int n = 0; n < n_nodes; ++n) {
      const VH qv(complex_.node_vertex[n]);
      const ClosestPoint cp = tree_.closest(quads_.point(qv));
      if (cp.face < 0 || cp.distance > max_distance_) {
        far.push_back(n);
        far_text.push_back("node " + std::to_string(n) + " (quad vertex " +
                           std::to_string(qv.idx()) + ") is " + format_length(cp.distance) +
                           " away");
        continue;
      }
      const int v = snap_node(cp, quads_.is_boundary(qv), complex_.valence[n]);
      if (v < 0) {
        stuck.push_back(n);
        continue;
      }
      node_target_vertex_[n] = v;
      obstacles_.vertex_blocked[v] = 1;
    }
    if (!far.empty()) {
      std::string msg =
          "the quad mesh does not lie on the target mesh: " + std::to_string(far.size()) +
          " node(s) are farther than " + format_length(max_distance_) + " (" +
          format_length(100 * options_.max_distance_fraction) +
          "% of its bounding-box diagonal) from its surface: ";
      for (size_t i = 0; i < far_text.size() && i < 10; ++i) msg += (i ? "; " : "") + far_text[i];
      if (far_text.size() > 10) msg += "; ...";
      throw InvalidInputError(msg);
    }
    if (!stuck.empty()) {
      throw InvalidInputError(
          "nodes " + join_ids(stuck) +
          " found no free target vertex near their position (other nodes took them, or a "
          "boundary node has no boundary vertex nearby); the target mesh is too coarse for "
          "this layout (" +
          std::to_string(n_nodes) + " nodes, " + std::to_string(complex_.arcs.size()) +
          " arcs; the target mesh has " + std::to_string(target_.n_vertices()) + " vertices)" +
          coarsen_hint());
    }
    for (int n = 0; n < n_nodes; ++n) {
      LayoutNode node;
      node.id = n;
      node.vertex = node_target_vertex_[n];
      layout.nodes.push_back(node);
    }
    reserve_exits();
  }

  std::string coarsen_hint() const {
    if (options_.coarsen > 0 || options_.all_edges) return "";
    return "; --coarsen 3 collapses the layout's thin patch strips first";
  }

  // Nearest free vertex of the closest face, else of that face's 1-ring, with at least
  // \p valence neighbours (the node's arcs need distinct exits).
  int snap_node(const ClosestPoint& cp, bool boundary, int valence) {
    // The closest face's vertices and their 1-ring first; farther rings (up to 3) only when
    // none of them is free (dense layouts, boundary nodes on a coarse boundary).
    std::vector<int> candidates, ring;
    for (const auto v : target_.fv_range(OpenMesh::FaceHandle(cp.face))) ring.push_back(v.idx());
    for (int rings = 1; rings <= 3; ++rings) {
      std::vector<int> next = ring;
      for (int v : ring)
        for (const auto w : target_.vv_range(VH(v))) next.push_back(w.idx());
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      ring = next;
      candidates = next;
      std::stable_sort(candidates.begin(), candidates.end(), [&](int a, int b) {
        return (target_.point(VH(a)) - cp.point).sqrnorm() <
               (target_.point(VH(b)) - cp.point).sqrnorm();
      });
      for (int v : candidates) {
        if (obstacles_.vertex_blocked[v]) continue;
        if (boundary != target_.is_boundary(VH(v))) continue;
        if (static_cast<int>(target_.valence(VH(v))) < valence) continue;
        return v;
      }
    }
    return -1;
  }

  // Point of the source arc at arc length \p length from the node end of half-arc \p half.
  Vec3 point_along(int half, double length) const {
    const auto& p = complex_.arcs[half >> 1].path;
    auto at = [&](size_t i) { return quads_.point(VH((half & 1) ? p[p.size() - 1 - i] : p[i])); };
    double walked = 0;
    for (size_t i = 0; i + 1 < p.size(); ++i) {
      const Vec3 a = at(i), b = at(i + 1);
      const double l = (b - a).norm();
      if (walked + l >= length && l > 0) return a + (b - a) * ((length - walked) / l);
      walked += l;
    }
    return at(p.size() - 1);
  }

  // Area-weighted normal of a vertex (works for polygons too: Newell's cross products).
  template <typename MeshT>
  static Vec3 vertex_normal(const MeshT& mesh, VH v) {
    Vec3 n(0, 0, 0);
    for (const auto f : mesh.vf_range(v)) {
      Vec3 fn(0, 0, 0);
      for (const auto h : mesh.fh_range(f)) {
        const Vec3& a = mesh.point(mesh.from_vertex_handle(h));
        const Vec3& b = mesh.point(mesh.to_vertex_handle(h));
        fn += OpenMesh::cross(a, b);
      }
      n += fn;
    }
    return n;
  }

  // Chooses, for every half-arc, the neighbour of its node's target vertex through which it
  // leaves: distinct per node, in the source's cyclic order (a cyclic monotone assignment
  // minimising the squared distance to the source arc one target edge away from the node).
  // Reserved exits are blocked for every other arc, so no arc can seal off a node.
  void reserve_exits() {
    const int n_nodes = static_cast<int>(complex_.node_vertex.size());
    exit_.assign(2 * complex_.arcs.size(), -1);
    double agreement = 0;
    for (int n = 0; n < n_nodes; ++n) {
      agreement += OpenMesh::dot(vertex_normal(quads_, VH(complex_.node_vertex[n])),
                                 vertex_normal(target_, VH(node_target_vertex_[n])));
    }
    reversed_ = agreement < 0;
    std::vector<int> node_of_vertex(target_.n_vertices(), -1);
    for (int n = 0; n < n_nodes; ++n) node_of_vertex[node_target_vertex_[n]] = n;
    std::vector<int> stuck;
    const double inf = std::numeric_limits<double>::infinity();
    // Exits of node n at its current vertex; false when its free neighbours do not suffice.
    auto assign = [&](int n) -> bool {
      const int t = node_target_vertex_[n];
      std::vector<int> ring;
      double reach = 0;
      for (const auto h : target_.voh_ccw_range(VH(t))) {
        ring.push_back(target_.to_vertex_handle(h).idx());
        reach += target_.calc_edge_length(h);
      }
      std::vector<int> halves = complex_.node_half_arcs[n];
      if (reversed_) std::reverse(halves.begin(), halves.end());
      const int k = static_cast<int>(halves.size()), m = static_cast<int>(ring.size());
      if (k == 0) return true;
      if (k > m) {
        return false;
      }
      reach /= m;
      std::vector<double> cost(k * m, inf);
      for (int i = 0; i < k; ++i) {
        const int h = halves[i];
        const int arc = h >> 1;
        const auto& qa = complex_.arcs[arc];
        const int other_node = (h & 1) ? qa.from : qa.to;
        const int other_vertex = node_target_vertex_[other_node];
        const int other_exit = exit_[h ^ 1];
        const bool boundary_arc = is_boundary_arc(qa);
        const Vec3 wanted = point_along(h, reach);
        for (int j = 0; j < m; ++j) {
          const int w = ring[j];
          const auto e = target_.edge_handle(target_.find_halfedge(VH(t), VH(w)));
          if (boundary_arc != target_.is_boundary(e)) continue;
          if (!boundary_arc && target_.is_boundary(VH(w)) && node_of_vertex[w] < 0) continue;
          if (other_exit == t && w != other_vertex) continue;  // the other end took the edge
          if (node_of_vertex[w] >= 0) {
            if (w != other_vertex || other_node == n) continue;
            if (other_exit >= 0 && other_exit != t) continue;
          } else if (exit_owner_[w] >= 0 && exit_owner_[w] != (h ^ 1)) {
            continue;
          }
          cost[i * m + j] = (target_.point(VH(w)) - wanted).sqrnorm();
        }
      }
      // Cyclic monotone assignment: for each rotation of the ring, a DP over (half, neighbour).
      double best = inf;
      std::vector<int> best_choice;
      std::vector<double> f((k + 1) * (m + 1));
      std::vector<char> take((k + 1) * (m + 1));
      for (int r = 0; r < m; ++r) {
        for (int j = 0; j <= m; ++j) f[j] = 0;
        for (int i = 1; i <= k; ++i) {
          f[i * (m + 1)] = inf;
          for (int j = 1; j <= m; ++j) {
            const double skip = f[i * (m + 1) + j - 1];
            const double use = f[(i - 1) * (m + 1) + j - 1] + cost[(i - 1) * m + (j - 1 + r) % m];
            take[i * (m + 1) + j] = use < skip;
            f[i * (m + 1) + j] = std::min(use, skip);
          }
        }
        if (f[k * (m + 1) + m] < best) {
          best = f[k * (m + 1) + m];
          best_choice.assign(k, -1);
          for (int i = k, j = m; i > 0; --j) {
            if (take[i * (m + 1) + j]) best_choice[--i] = ring[(j - 1 + r) % m];
          }
        }
      }
      if (!(best < inf)) {
        return false;
      }
      for (int i = 0; i < k; ++i) {
        const int w = best_choice[i];
        exit_[halves[i]] = w;
        if (node_of_vertex[w] < 0) {
          exit_owner_[w] = halves[i];
          obstacles_.vertex_blocked[w] = 1;
        }
      }
      return true;
    };
    for (int n = 0; n < n_nodes; ++n) {
      if (assign(n)) continue;
      // Crowded: move the node to another free vertex nearby (if no arc end has claimed the
      // edge to its vertex yet) and try again.
      const int old = node_target_vertex_[n];
      bool claimed = false;
      for (int e : exit_) claimed = claimed || e == old;
      bool placed = false;
      if (!claimed) {
        std::vector<int> near{old};
        for (int rings = 0; rings < 2; ++rings) {
          const size_t size = near.size();
          for (size_t i = 0; i < size; ++i)
            for (const auto w : target_.vv_range(VH(near[i]))) near.push_back(w.idx());
        }
        std::sort(near.begin(), near.end());
        near.erase(std::unique(near.begin(), near.end()), near.end());
        const Vec3 want = target_.point(VH(old));
        std::stable_sort(near.begin(), near.end(), [&](int a, int b) {
          return (target_.point(VH(a)) - want).sqrnorm() < (target_.point(VH(b)) - want).sqrnorm();
        });
        const bool boundary = target_.is_boundary(VH(old));
        for (int c : near) {
          if (c == old || obstacles_.vertex_blocked[c] || target_.is_boundary(VH(c)) != boundary)
            continue;
          node_of_vertex[old] = -1;
          obstacles_.vertex_blocked[old] = 0;
          node_target_vertex_[n] = c;
          node_of_vertex[c] = n;
          obstacles_.vertex_blocked[c] = 1;
          if (assign(n)) {
            placed = true;
            break;
          }
          node_of_vertex[c] = -1;
          obstacles_.vertex_blocked[c] = 0;
          node_target_vertex_[n] = old;
          node_of_vertex[old] = n;
          obstacles_.vertex_blocked[old] = 1;
        }
      }
      if (!placed) stuck.push_back(n);
    }
    if (!stuck.empty()) {
      throw InvalidInputError(
          "nodes " + join_ids(stuck) +
          " cannot keep their arcs in order on the target mesh: their target vertices have too "
          "few free neighbours (the target mesh is too coarse for this layout near them)" +
          coarsen_hint());
    }
  }

  // Routes arc a: node vertex, its reserved exit, a corridor path to the other exit, node.
  std::vector<int> route_between_exits(int a, const std::vector<Sample>& samples, bool boundary) {
    const auto& arc = complex_.arcs[a];
    const int s = node_target_vertex_[arc.from], t = node_target_vertex_[arc.to];
    const int out = exit_[2 * a], in = exit_[2 * a + 1];
    if (out == t) return {s, t};
    if (out == in) return {s, out, t};
    double radius = options_.corridor_radius * mean_edge_;
    std::vector<int> middle;
    for (int attempt = 0; attempt <= options_.corridor_growths && middle.empty(); ++attempt) {
      build_corridor(samples, radius, boundary);
      middle = finder_.find(out, in, obstacles_, &allowed_, &cost_);
      radius *= 2;
    }
    clear_corridor();
    if (middle.empty()) return {};
    middle.insert(middle.begin(), s);
    middle.push_back(t);
    return middle;
  }

  // Closest-point projections of the source arc, at most half a target edge apart.
  std::vector<Sample> sample_arc(const QuadComplex::Arc& arc, double& worst_distance) {
    std::vector<Sample> samples;
    worst_distance = 0;
    const double spacing = 0.5 * mean_edge_;
    Vec3 last(std::numeric_limits<double>::infinity(), 0, 0);
    auto add = [&](const Vec3& q, bool force) {
      if (!force && (q - last).norm() < 0.5 * spacing) return;
      last = q;
      const ClosestPoint cp = tree_.closest(q);
      worst_distance = std::max(worst_distance, cp.distance);
      samples.push_back({cp.point, cp.face});
    };
    const auto& p = arc.path;
    for (size_t k = 0; k + 1 < p.size(); ++k) {
      const Vec3 a = quads_.point(VH(p[k])), b = quads_.point(VH(p[k + 1]));
      const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / spacing)));
      for (int s = 0; s < steps; ++s) add(a + (b - a) * (static_cast<double>(s) / steps), k == 0);
    }
    add(quads_.point(VH(p.back())), true);
    return samples;
  }

  bool is_boundary_arc(const QuadComplex::Arc& arc) const {
    for (size_t k = 0; k + 1 < arc.path.size(); ++k) {
      const HH h = quads_.find_halfedge(VH(arc.path[k]), VH(arc.path[k + 1]));
      if (!h.is_valid() || !quads_.is_boundary(quads_.edge_handle(h))) return false;
    }
    return true;
  }

  // Marks the vertices within \p radius of the samples (grown over mesh edges from each
  // sample's face) as allowed, with a cost growing with the distance from the curve.
  void build_corridor(const std::vector<Sample>& samples, double radius, bool boundary_only) {
    clear_corridor();
    std::vector<int> queue;
    for (const Sample& s : samples) {
      ++stamp_;
      queue.clear();
      for (const auto v : target_.fv_range(OpenMesh::FaceHandle(s.face))) {
        visit_stamp_[v.idx()] = stamp_;
        queue.push_back(v.idx());
      }
      for (size_t head = 0; head < queue.size(); ++head) {
        const int v = queue[head];
        const double d = (target_.point(VH(v)) - s.point).norm();
        if (curve_distance_[v] == std::numeric_limits<double>::infinity()) corridor_.push_back(v);
        curve_distance_[v] = std::min(curve_distance_[v], d);
        for (const auto w : target_.vv_range(VH(v))) {
          if (visit_stamp_[w.idx()] == stamp_) continue;
          visit_stamp_[w.idx()] = stamp_;
          if ((target_.point(w) - s.point).norm() <= radius) queue.push_back(w.idx());
        }
      }
    }
    for (int v : corridor_) {
      allowed_[v] = !boundary_only || target_.is_boundary(VH(v));
      // Interior arcs must not touch the boundary (it belongs to the boundary arcs).
      if (!boundary_only && target_.is_boundary(VH(v))) allowed_[v] = 0;
      const double x = curve_distance_[v] / mean_edge_;
      cost_[v] = 1.0 + 2.0 * x * x;
      if (boundary_only && allowed_[v]) {
        // A boundary arc runs along boundary edges only: no inner edge between two boundary
        // vertices (it would cut off a corner of the surface).
        for (const auto h : target_.voh_range(VH(v))) {
          const int e = target_.edge_handle(h).idx();
          if (target_.is_boundary(target_.edge_handle(h)) || obstacles_.edge_blocked[e]) continue;
          if (!target_.is_boundary(target_.to_vertex_handle(h))) continue;
          obstacles_.edge_blocked[e] = 1;
          corridor_blocked_edges_.push_back(e);
        }
      }
    }
  }

  void clear_corridor() {
    for (int e : corridor_blocked_edges_) obstacles_.edge_blocked[e] = 0;
    corridor_blocked_edges_.clear();
    for (int v : corridor_) {
      allowed_[v] = 0;
      cost_[v] = 1.0;
      curve_distance_[v] = std::numeric_limits<double>::infinity();
    }
    corridor_.clear();
  }

  void block_path(const std::vector<int>& path) {
    for (size_t k = 0; k < path.size(); ++k) {
      obstacles_.vertex_blocked[path[k]] = 1;
      if (k == 0) continue;
      const auto h = target_.find_halfedge(VH(path[k - 1]), VH(path[k]));
      obstacles_.edge_blocked[target_.edge_handle(h).idx()] = 1;
    }
  }

  void route_arcs(Layout& layout) {
    const int n_arcs = static_cast<int>(complex_.arcs.size());
    std::vector<double> length(n_arcs, 0);
    std::vector<char> boundary(n_arcs, 0);
    for (int a = 0; a < n_arcs; ++a) {
      const auto& p = complex_.arcs[a].path;
      for (size_t k = 0; k + 1 < p.size(); ++k)
        length[a] += (quads_.point(VH(p[k + 1])) - quads_.point(VH(p[k]))).norm();
      boundary[a] = is_boundary_arc(complex_.arcs[a]);
    }
    std::vector<int> order(n_arcs);
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      if (boundary[a] != boundary[b]) return boundary[a] > boundary[b];
      return length[a] < length[b];
    });

    std::vector<std::vector<int>> paths(n_arcs);
    std::vector<int> failed, far;
    // Arcs that could not be routed go first in the next attempt (at most 3 more), on a clean
    // slate (node and exit reservations only).
    const RoutingObstacles reserved = obstacles_;
    std::vector<char> priority(n_arcs, 0);
    for (int attempt = 0; attempt < 4; ++attempt) {
      obstacles_ = reserved;
      failed.clear();
      far.clear();
      std::stable_partition(order.begin(), order.end(), [&](int a) { return priority[a] != 0; });
      for (int a : order) {
        const auto& arc = complex_.arcs[a];
        double worst = 0;
        const std::vector<Sample> samples = sample_arc(arc, worst);
        if (worst > max_distance_) {
          far.push_back(a);
          continue;
        }
        paths[a] = route_between_exits(a, samples, boundary[a] != 0);
        clear_corridor();
        if (paths[a].empty()) {
          failed.push_back(a);
          continue;
        }
        block_path(paths[a]);
      }
      if (failed.empty() || !far.empty()) break;
      for (int a : failed) priority[a] = 1;
    }
    if (!far.empty()) {
      throw InvalidInputError("the quad mesh does not lie on the target mesh: arcs " +
                              join_ids(far) + " pass farther than " + format_length(max_distance_) +
                              " from its surface");
    }
    if (!failed.empty()) {
      std::sort(failed.begin(), failed.end());
      throw InvalidInputError(
          "cannot route arcs " + join_ids(failed) +
          " onto the target mesh: no edge path near the source arc avoids the arcs routed "
          "before (the target mesh may be too coarse for this layout)" +
          coarsen_hint());
    }
    for (int a = 0; a < n_arcs; ++a) {
      LayoutArc arc;
      arc.id = a;
      arc.from = complex_.arcs[a].from;
      arc.to = complex_.arcs[a].to;
      arc.path = std::move(paths[a]);
      layout.arcs.push_back(std::move(arc));
    }
  }

  void check_cyclic_orders(const Layout& layout) {
    const LayoutTopology topo = build_topology(target_, layout);
    std::vector<int> bad;
    for (size_t n = 0; n < complex_.node_vertex.size(); ++n) {
      std::vector<int> expected = complex_.node_half_arcs[n];
      // A target oriented against the quad mesh reverses every order; that is fine.
      if (reversed_) std::reverse(expected.begin(), expected.end());
      if (!same_cycle(expected, topo.node_half_arcs[n])) bad.push_back(static_cast<int>(n));
    }
    if (!bad.empty()) {
      throw InvalidInputError(
          "the transferred layout changes the cyclic order of the arcs at nodes " + join_ids(bad));
    }
  }

  const PolyMesh& quads_;
  const QuadComplex& complex_;
  const TriMesh& target_;
  const QuadImportOptions& options_;
  ClosestPointTree tree_;
  PathFinder finder_;
  double mean_edge_ = 0, diagonal_ = 0, max_distance_ = 0;
  RoutingObstacles obstacles_;
  std::vector<int> node_target_vertex_;
  // Corridor state (reset per arc through corridor_).
  std::vector<char> allowed_;
  std::vector<double> cost_;
  std::vector<double> curve_distance_;
  std::vector<int> corridor_;
  std::vector<int> corridor_blocked_edges_;  // inner edges blocked for a boundary arc
  std::vector<int> visit_stamp_;
  int stamp_ = 0;
  // Per half-arc: the target vertex next to its node through which it must leave (the other
  // end's node vertex for a direct edge). Per vertex: the half-arc that reserved it, or -1.
  std::vector<int> exit_;
  std::vector<int> exit_owner_;
  bool reversed_ = false;  // the target is oriented against the quad mesh
};

}  // namespace

Layout transfer_complex(const PolyMesh& quads, const QuadComplex& complex, const TriMesh& target,
                        const QuadImportOptions& options) {
  if (target.n_faces() == 0) throw InvalidInputError("the target mesh has no faces");
  return Transfer(quads, complex, target, options).run();
}

QuadImportResult import_quads(const PolyMesh& quads, const TriMesh* target,
                              const QuadImportOptions& options) {
  QuadImportResult result;
  if (is_pure_quad(quads)) {
    result.quads = quads;
  } else {
    std::vector<int> counts(8, 0);
    int other = 0;
    for (const auto f : quads.faces()) {
      const size_t n = quads.valence(f);
      if (n < counts.size())
        ++counts[n];
      else
        ++other;
    }
    std::string mix;
    for (size_t n = 3; n < counts.size(); ++n) {
      if (counts[n] && n != 4)
        mix += (mix.empty() ? "" : ", ") + std::to_string(counts[n]) + " with " +
               std::to_string(n) + " sides";
    }
    if (other) mix += (mix.empty() ? "" : ", ") + std::to_string(other) + " with more sides";
    result.warnings.push_back("the mesh is not pure quad (" + mix +
                              "): split every face once into quads (face centroid + edge "
                              "midpoints, Catmull-Clark-style, no smoothing)");
    result.quads = split_to_quads(quads);
    result.split = true;
  }
  BaseComplexOptions bc;
  bc.all_edges = options.all_edges;
  result.complex = base_complex(result.quads, bc);
  const bool coarsen = options.coarsen > 0 && !options.all_edges;
  if (target) {
    if (options.refine != 1) {
      result.warnings.push_back("--refine is ignored when transferring onto another mesh");
    }
  } else {
    result.mesh = triangulate_quads(result.quads, options.refine);
    require_readable_triangulation(result.mesh, options.refine);
  }
  if (coarsen) {
    CoarsenOptions co;
    co.max_width =
        options.coarsen * (target ? mesh_scales(*target).first : mesh_scales(result.quads).first);
    result.complex = coarsen_complex(result.quads, result.complex, co, &result.coarsen);
    if (!result.coarsen.skipped.empty())
      result.warnings.push_back("the base complex was not coarsened: " + result.coarsen.skipped);
  } else {
    result.coarsen.nodes_before = result.coarsen.nodes_after =
        static_cast<int>(result.complex.node_vertex.size());
    result.coarsen.arcs_before = result.coarsen.arcs_after =
        static_cast<int>(result.complex.arcs.size());
    result.coarsen.patches_before = result.coarsen.patches_after = result.complex.num_patches;
  }
  if (target || !result.complex.simple_paths) {
    // Onto the target, or (a coarsened complex, whose arcs are no edge paths of the quad mesh)
    // onto the triangulated quad mesh: on a working mesh of it.
    TransferOptions transfer;
    transfer.max_distance_fraction = options.max_distance_fraction;
    TransferResult t =
        transfer_quads(quads, result.quads, result.complex,
                       std::make_shared<const TriMesh>(target ? *target : result.mesh), transfer);
    result.working = t.mesh;
    result.transfer = t.stats;
    result.mesh = t.mesh->mesh();
    result.layout = std::move(t.layout);
  } else {
    result.layout = layout_on_triangulation(result.quads, result.complex, options.refine);
    result.layout.mesh_vertices = static_cast<int>(result.mesh.n_vertices());
    result.layout.mesh_faces = static_cast<int>(result.mesh.n_faces());
    require_valid_layout(result.mesh, result.layout, "the base complex of the quad mesh");
  }
  return result;
}

}  // namespace qs
