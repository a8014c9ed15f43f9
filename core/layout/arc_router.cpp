#include "core/layout/arc_router.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

#include "core/base/errors.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using HH = OpenMesh::HalfedgeHandle;
using EH = OpenMesh::EdgeHandle;
using FH = OpenMesh::FaceHandle;

double segment_distance(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double l2 = ab.sqrnorm();
  double t = l2 > 0 ? ((p - a) | ab) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// The search graph of one route: sites are the working mesh's vertices (id v) and the
// midpoints of its edges (id #V + e). Moves go along a free edge (vertex to vertex) or across
// a face (vertex to the opposite edge's midpoint, or midpoint to midpoint); never along the
// same edge to its midpoint.
class RouteSearch {
 public:
  RouteSearch(const WorkingMesh& w, const LayoutOccupancy& occ, const RouteRequest& r)
      : m_(w.mesh()), occ_(occ), r_(r), nv_(static_cast<int>(m_.n_vertices())) {
    if (!r.guide.empty()) {
      for (size_t k = 1; k < r.guide.size(); ++k)
        guide_length_ += (r.guide[k] - r.guide[k - 1]).norm();
    }
    double local = 0;
    int count = 0;
    for (auto h : m_.voh_range(VH(r.source))) {
      local += m_.calc_edge_length(h);
      ++count;
    }
    local_edge_ = count > 0 ? local / count : 1.0;
    width_ = r.guide_width > 0 ? r.guide_width : 2 * local_edge_;
    if (r.target >= 0) target_point_ = m_.point(VH(r.target));
    source_node_ = occ.node_at(r.source);
    target_node_ = r.target >= 0 ? occ.node_at(r.target) : -1;
  }

  // The cheapest site sequence from source to target (empty: none).
  std::vector<int> run() {
    struct Item {
      double f;
      double g;
      int site;
      bool operator<(const Item& o) const { return f > o.f; }
    };
    std::priority_queue<Item> open;
    const double cap = r_.guide.empty()
                           ? std::numeric_limits<double>::infinity()
                           : r_.max_length_factor * guide_length_ + 6 * local_edge_ + 4 * width_;
    best_[r_.source] = {0.0, -1, 0.0};
    open.push({heuristic(r_.source), 0.0, r_.source});
    // The cap bounds the path's length, not its cost (the weights only choose among paths).
    while (!open.empty()) {
      const Item it = open.top();
      open.pop();
      auto found = best_.find(it.site);
      if (found == best_.end() || it.g > found->second.g) continue;
      if (is_goal(it.site)) return trace(it.site);
      const double length = found->second.length;
      if (length > cap) continue;
      neighbours(it.site, [&](int next, bool along_edge) {
        if (!enterable(next, along_edge)) return;
        const double l = (position(next) - position(it.site)).norm();
        const double g = it.g + l * 0.5 * (weight(it.site) + weight(next));
        auto b = best_.find(next);
        if (b != best_.end() && b->second.g <= g) return;
        best_[next] = {g, it.site, length + l};
        open.push({g + heuristic(next), g, next});
      });
    }
    return {};
  }

  bool is_edge_site(int s) const { return s >= nv_; }
  int edge_of(int s) const { return s - nv_; }

 private:
  struct Best {
    double g;
    int parent;
    double length;  // unweighted length of the best path (length units)
  };

  bool is_goal(int s) const {
    if (is_edge_site(s) || s == r_.source) return false;
    if (r_.target >= 0) return s == r_.target;
    return m_.is_boundary(VH(s)) && !occ_.occupied(s);
  }

  Vec3 position(int s) const {
    if (!is_edge_site(s)) return m_.point(VH(s));
    const HH h = m_.halfedge_handle(EH(edge_of(s)), 0);
    return 0.5 * (m_.point(m_.from_vertex_handle(h)) + m_.point(m_.to_vertex_handle(h)));
  }

  double heuristic(int s) const {
    return r_.target >= 0 ? (position(s) - target_point_).norm() : 0.0;
  }

  bool foreign_node(int v) const {
    const int n = occ_.node_at(v);
    return n >= 0 && n != source_node_ && n != target_node_;
  }

  // Cost factor of a site (cached): the corridor around the guide and the rings kept for
  // other nodes' arcs.
  double weight(int s) {
    auto it = weight_.find(s);
    if (it != weight_.end()) return it->second;
    double w = 1.0;
    if (!r_.guide.empty()) {
      const Vec3 p = position(s);
      double d = std::numeric_limits<double>::infinity();
      if (r_.guide.size() == 1) d = (p - r_.guide[0]).norm();
      for (size_t k = 1; k < r_.guide.size(); ++k)
        d = std::min(d, segment_distance(p, r_.guide[k - 1], r_.guide[k]));
      w += std::min(50.0, (d / width_) * (d / width_));
    }
    bool near_foreign = false;
    if (is_edge_site(s)) {
      const HH h = m_.halfedge_handle(EH(edge_of(s)), 0);
      near_foreign = foreign_node(m_.from_vertex_handle(h).idx()) ||
                     foreign_node(m_.to_vertex_handle(h).idx());
    } else {
      for (auto u : m_.vv_range(VH(s))) near_foreign = near_foreign || foreign_node(u.idx());
    }
    if (near_foreign) w *= r_.foreign_ring_cost;
    weight_.emplace(s, w);
    return w;
  }

  // Whether the search may enter site \p s (\p along_edge: from a vertex along edge `via_`).
  bool enterable(int s, bool along_edge) const {
    if (along_edge && occ_.arc_on_edge(via_) >= 0) return false;
    if (is_edge_site(s)) {
      const EH e(edge_of(s));
      if (m_.status(e).deleted() || m_.is_boundary(e)) return false;
      return occ_.arc_on_edge(e.idx()) < 0;
    }
    if (m_.status(VH(s)).deleted()) return false;
    if (s == r_.target) return true;
    return !occ_.occupied(s);
  }

  // Calls f(site, along_edge) for every move out of site s; along_edge moves set via_.
  template <typename F>
  void neighbours(int s, F&& f) {
    if (!is_edge_site(s)) {
      for (auto h : m_.voh_range(VH(s))) {
        via_ = m_.edge_handle(h).idx();
        f(m_.to_vertex_handle(h).idx(), true);
        if (m_.is_boundary(h)) continue;
        const HH opposite = m_.next_halfedge_handle(h);  // the edge of this face opposite s
        f(nv_ + m_.edge_handle(opposite).idx(), false);
      }
      return;
    }
    const EH e(edge_of(s));
    for (int k = 0; k < 2; ++k) {
      const HH h = m_.halfedge_handle(e, k);
      if (m_.is_boundary(h)) continue;
      const HH n = m_.next_halfedge_handle(h);
      f(m_.to_vertex_handle(n).idx(), false);
      f(nv_ + m_.edge_handle(n).idx(), false);
      f(nv_ + m_.edge_handle(m_.next_halfedge_handle(n)).idx(), false);
    }
  }

  std::vector<int> trace(int s) const {
    std::vector<int> out;
    for (int x = s; x >= 0; x = best_.at(x).parent) out.push_back(x);
    std::reverse(out.begin(), out.end());
    return out;
  }

  const TriMesh& m_;
  const LayoutOccupancy& occ_;
  const RouteRequest& r_;
  const int nv_;
  double guide_length_ = 0, local_edge_ = 1, width_ = 1;
  Vec3 target_point_{0, 0, 0};
  int source_node_ = -1, target_node_ = -1;
  int via_ = -1;
  std::unordered_map<int, Best> best_;
  std::unordered_map<int, double> weight_;
};

// The edge between two vertices, or -1.
int edge_between(const TriMesh& m, int a, int b) {
  const HH h = m.find_halfedge(VH(a), VH(b));
  return h.is_valid() ? m.edge_handle(h).idx() : -1;
}

// Makes a and b adjacent by flipping the edge that separates them in two faces (a, x, y) and
// (y, x, b), when the working mesh allows it and no arc runs along that edge.
bool join_by_flip(WorkingMesh& w, const LayoutOccupancy& occ, int a, int b) {
  const TriMesh& m = w.mesh();
  for (auto h : m.voh_range(VH(a))) {
    if (m.is_boundary(h)) continue;
    const HH across = m.next_halfedge_handle(h);  // edge (x, y) opposite a in this face
    const HH other = m.opposite_halfedge_handle(across);
    if (m.is_boundary(other)) continue;
    if (m.to_vertex_handle(m.next_halfedge_handle(other)).idx() != b) continue;
    const int e = m.edge_handle(across).idx();
    if (occ.arc_on_edge(e) >= 0) return false;
    return w.flip_edge(e);
  }
  return false;
}

// Moves the vertices of \p path at \p positions (indices into path, refinement vertices) towards
// the straight line between their path neighbours, inside their input face or along their input
// edge (WorkingMesh::move_vertex keeps the surface exact and every triangle valid): a route
// through edge midpoints zig-zags, and an arc maps to a straight iso-line.
void straighten(WorkingMesh& w, const std::vector<int>& path, const std::vector<size_t>& positions,
                int passes) {
  const TriMesh& in = w.input();
  for (int pass = 0; pass < passes; ++pass) {
    for (size_t k : positions) {
      const int m = path[k], a = path[k - 1], b = path[k + 1];
      const SurfacePoint o = w.origin(m);
      const Vec3 xm = w.mesh().point(VH(m)), xa = w.mesh().point(VH(a)), xb = w.mesh().point(VH(b));
      SurfacePoint target;
      target.face = o.face;
      if (w.carrier(m) == WorkingMesh::Carrier::kInputFace) {
        const auto ba = w.bary_in_input_face(a, o.face), bb = w.bary_in_input_face(b, o.face);
        if (!ba || !bb) continue;
        const Vec3 ab = xb - xa;
        const double l2 = ab.sqrnorm();
        if (!(l2 > 0)) continue;
        const double t = std::clamp(((xm - xa) | ab) / l2, 0.05, 0.95);
        for (int j = 0; j < 3; ++j) target.bary[j] = (1 - t) * (*ba)[j] + t * (*bb)[j];
      } else {
        // Along the input edge (p, q): where the straight line between the neighbours, unfolded
        // across the edge, crosses it.
        const auto edge = w.input_edge_of(m);
        if (!edge) continue;
        const Vec3 xp = in.point(VH((*edge)[0])), xq = in.point(VH((*edge)[1]));
        const Vec3 pq = xq - xp;
        const double len = pq.norm();
        if (!(len > 0)) continue;
        auto side = [&](const Vec3& x, double& along, double& dist) {
          along = ((x - xp) | pq) / (len * len);
          dist = ((x - xp) % pq).norm() / len;
        };
        double ta, da, tb, db;
        side(xa, ta, da);
        side(xb, tb, db);
        if (!(da + db > 0)) continue;
        // Only where the neighbours lie on both sides of the edge (different input faces).
        const auto in_a = w.bary_in_input_face(a, o.face), in_b = w.bary_in_input_face(b, o.face);
        if (in_a && in_b) continue;
        const double t = std::clamp(ta + (tb - ta) * da / (da + db), 0.02, 0.98);
        int zero = -1;
        for (int j = 0; j < 3; ++j)
          if (o.bary[j] == 0) zero = j;
        const auto& c = in.face_handle(o.face);
        int k0 = -1, k1 = -1, j = 0;
        for (auto v : in.fv_range(c)) {
          if (v.idx() == (*edge)[0]) k0 = j;
          if (v.idx() == (*edge)[1]) k1 = j;
          ++j;
        }
        if (k0 < 0 || k1 < 0 || zero < 0) continue;
        target.bary = {0, 0, 0};
        target.bary[k0] = 1 - t;
        target.bary[k1] = t;
      }
      // The full way, else half of it.
      SurfacePoint half = target;
      for (int j = 0; j < 3; ++j) half.bary[j] = 0.5 * (o.bary[j] + target.bary[j]);
      if (!w.move_vertex(m, target)) w.move_vertex(m, half);
    }
  }
}

}  // namespace

LayoutOccupancy::LayoutOccupancy(const WorkingMesh& mesh) : mesh_(mesh) {
  sync();
}

void LayoutOccupancy::sync() {
  node_.resize(mesh_.mesh().n_vertices(), -1);
  arc_.resize(mesh_.mesh().n_vertices(), -1);
  edge_.resize(mesh_.mesh().n_edges(), -1);
}

void LayoutOccupancy::clear() {
  node_.assign(mesh_.mesh().n_vertices(), -1);
  arc_.assign(mesh_.mesh().n_vertices(), -1);
  edge_.assign(mesh_.mesh().n_edges(), -1);
}

void LayoutOccupancy::set_node(int v, int node) {
  sync();
  node_[v] = node;
}

void LayoutOccupancy::set_path(const std::vector<int>& path, int arc) {
  sync();
  const TriMesh& m = mesh_.mesh();
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    if (k > 0) arc_[path[k]] = arc;
    const int e = edge_between(m, path[k], path[k + 1]);
    if (e >= 0) edge_[e] = arc;
  }
}

std::vector<int> route_arc(WorkingMesh& mesh, LayoutOccupancy& occupancy,
                           const RouteRequest& request, int* splits,
                           std::vector<std::array<int, 3>>* split_log) {
  occupancy.sync();
  std::vector<int> sites;
  int nv = 0;
  {
    RouteSearch search(mesh, occupancy, request);
    sites = search.run();
    nv = static_cast<int>(mesh.mesh().n_vertices());
  }
  if (sites.size() < 2) return {};
  // Realize: each midpoint site becomes a vertex. Edge indices stay valid through the splits
  // (a split keeps its edge's index on one half, and each edge is split at most once here).
  std::vector<int> path;
  path.reserve(sites.size());
  for (int s : sites) {
    if (s < nv) {
      path.push_back(s);
    } else {
      const HH h = mesh.mesh().halfedge_handle(EH(s - nv), 0);
      const int a = mesh.mesh().from_vertex_handle(h).idx();
      const int b = mesh.mesh().to_vertex_handle(h).idx();
      path.push_back(mesh.split_edge(s - nv, 0.5));
      if (splits) ++*splits;
      if (split_log) split_log->push_back({a, b, path.back()});
    }
  }
  occupancy.sync();
  // Consecutive vertices lie on one face of the mesh before the splits; splits of that face's
  // other edges (a face the path crosses twice) can leave them unjoined: one flip joins them.
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    if (edge_between(mesh.mesh(), path[k], path[k + 1]) >= 0) continue;
    if (!join_by_flip(mesh, occupancy, path[k], path[k + 1])) return {};
  }
  std::vector<size_t> created;
  for (size_t k = 1; k + 1 < path.size(); ++k)
    if (path[k] >= nv) created.push_back(k);
  if (request.straighten > 0) straighten(mesh, path, created, request.straighten);
  return path;
}

}  // namespace qs

namespace qs {

std::vector<int> route_straight(WorkingMesh& mesh, LayoutOccupancy& occupancy, int source,
                                int target, double snap, int* splits,
                                std::vector<std::array<int, 3>>* split_log) {
  occupancy.sync();
  const TriMesh& m = mesh.mesh();
  const Vec3 goal = m.point(VH(target));
  std::vector<int> path{source};
  std::vector<char> on_path;  // vertices already on this path (no loops)
  auto mark = [&](int v) {
    if (v >= static_cast<int>(on_path.size())) on_path.resize(m.n_vertices() + 64, 0);
    on_path[v] = 1;
  };
  auto visited = [&](int v) { return v < static_cast<int>(on_path.size()) && on_path[v]; };
  mark(source);
  auto free_vertex = [&](int v) { return v == target || (!occupancy.occupied(v) && !visited(v)); };
  const double start_distance = (goal - m.point(VH(source))).norm();
  for (int guard = 0; guard < 100000; ++guard) {
    const int c = path.back();
    if (c == target) return path;
    const Vec3 xc = m.point(VH(c));
    // Joined to the target by a free edge: the last step.
    const HH direct = m.find_halfedge(VH(c), VH(target));
    if (direct.is_valid()) {
      if (occupancy.arc_on_edge(m.edge_handle(direct).idx()) >= 0) return {};
      path.push_back(target);
      return path;
    }
    if ((goal - xc).norm() > 2 * start_distance + 1e-12) return {};  // wandered off
    // The face around c whose corner wedge holds the direction to the target, and where the
    // straight line leaves it through the opposite edge (a, b).
    const Vec3 d = goal - xc;
    HH leave;
    double t_leave = -1;
    for (auto h : m.voh_range(VH(c))) {
      if (m.is_boundary(h)) continue;
      const HH opposite = m.next_halfedge_handle(h);
      const int a = m.to_vertex_handle(h).idx(), b = m.to_vertex_handle(opposite).idx();
      const Vec3 xa = m.point(VH(a)), xb = m.point(VH(b));
      const Vec3 n = ((xa - xc) % (xb - xc));
      const double area2 = n.norm();
      if (!(area2 > 0)) continue;
      const Vec3 nn = n / area2;
      const Vec3 dp = d - (d | nn) * nn;  // direction in the face's plane
      const double sa = ((xa - xc) % dp) | nn, sb = (dp % (xb - xc)) | nn;
      if (sa < 0 || sb < 0) continue;  // outside this corner wedge
      // c + s·dp = a + t·(b − a): solve in the plane.
      const Vec3 ab = xb - xa, ac = xc - xa;
      const double den = (ab % dp) | nn;
      if (!(std::abs(den) > 0)) continue;
      const double t = ((ac % dp) | nn) / den;
      leave = opposite;
      t_leave = std::clamp(t, 0.0, 1.0);
      break;
    }
    if (!leave.is_valid()) return {};
    const int a = m.from_vertex_handle(leave).idx(), b = m.to_vertex_handle(leave).idx();
    const int e = m.edge_handle(leave).idx();
    // Through a vertex when the crossing is within `snap` of it, else through the edge.
    int next = -1;
    if (t_leave < snap) {
      if (!free_vertex(a)) return {};  // the line runs into an occupied vertex
      next = a;
    } else if (t_leave > 1 - snap) {
      if (!free_vertex(b)) return {};
      next = b;
    }
    if (next >= 0) {
      const HH step = m.find_halfedge(VH(c), VH(next));
      if (!step.is_valid() || occupancy.arc_on_edge(m.edge_handle(step).idx()) >= 0) return {};
    } else {
      if (occupancy.arc_on_edge(e) >= 0 || m.is_boundary(m.edge_handle(leave))) return {};
      const double t = t_leave;
      const HH h0 = m.halfedge_handle(m.edge_handle(leave), 0);
      const bool forward = m.from_vertex_handle(h0).idx() == a;
      try {
        next = mesh.split_edge(e, forward ? t : 1 - t);
      } catch (const InvalidInputError&) {
        return {};
      }
      if (splits) ++*splits;
      if (split_log) split_log->push_back({a, b, next});
      occupancy.sync();
    }
    mark(next);
    path.push_back(next);
  }
  return {};
}

}  // namespace qs
