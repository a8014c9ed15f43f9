#include "core/layout/arc_router.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

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
    best_[r_.source] = {0.0, -1};
    open.push({heuristic(r_.source), 0.0, r_.source});
    while (!open.empty()) {
      const Item it = open.top();
      open.pop();
      auto found = best_.find(it.site);
      if (found == best_.end() || it.g > found->second.g) continue;
      if (it.g > cap) break;
      if (is_goal(it.site)) return trace(it.site);
      neighbours(it.site, [&](int next, bool along_edge) {
        if (!enterable(next, along_edge)) return;
        const double step =
            (position(next) - position(it.site)).norm() * 0.5 * (weight(it.site) + weight(next));
        const double g = it.g + step;
        auto b = best_.find(next);
        if (b != best_.end() && b->second.g <= g) return;
        best_[next] = {g, it.site};
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

}  // namespace

LayoutOccupancy::LayoutOccupancy(const WorkingMesh& mesh) : mesh_(mesh) {
  sync();
}

void LayoutOccupancy::sync() {
  node_.resize(mesh_.mesh().n_vertices(), -1);
  arc_.resize(mesh_.mesh().n_vertices(), -1);
  edge_.resize(mesh_.mesh().n_edges(), -1);
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
                           const RouteRequest& request, int* splits) {
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
      path.push_back(mesh.split_edge(s - nv, 0.5));
      if (splits) ++*splits;
    }
  }
  occupancy.sync();
  // Consecutive vertices lie on one face of the mesh before the splits; splits of that face's
  // other edges (a face the path crosses twice) can leave them unjoined: one flip joins them.
  for (size_t k = 0; k + 1 < path.size(); ++k) {
    if (edge_between(mesh.mesh(), path[k], path[k + 1]) >= 0) continue;
    if (!join_by_flip(mesh, occupancy, path[k], path[k + 1])) return {};
  }
  return path;
}

}  // namespace qs
