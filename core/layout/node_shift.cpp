#include "core/layout/node_shift.h"

#include <algorithm>
#include <limits>

#include "core/base/errors.h"
#include "core/layout/path_finder.h"
#include "core/layout/routing.h"

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;
using VH = OpenMesh::VertexHandle;

}  // namespace

class NodeShifter::Impl {
 public:
  Impl(const TriMesh& mesh, const Layout& layout) : mesh_(mesh), finder_(mesh) {
    layout_ = layout;
    const LayoutTopology topo = build_topology(mesh, layout);
    const int nv = static_cast<int>(mesh.n_vertices());
    vertex_node_.assign(nv, -1);
    vertex_arc_.assign(nv, -1);
    edge_arc_.assign(mesh.n_edges(), -1);
    obstacles_.vertex_blocked.assign(nv, 0);
    obstacles_.edge_blocked.assign(mesh.n_edges(), 0);
    region_.assign(nv, 0);
    stamp_.assign(nv, 0);
    edge_stamp_.assign(mesh.n_edges(), 0);
    face_stamp_.assign(mesh.n_faces(), 0);
    reference_order_ = topo.node_half_arcs;
    node_arcs_.assign(layout.nodes.size(), {});
    for (size_t n = 0; n < layout.nodes.size(); ++n) {
      input_vertex_.push_back(layout.nodes[n].vertex);
      vertex_node_[layout.nodes[n].vertex] = static_cast<int>(n);
      obstacles_.vertex_blocked[layout.nodes[n].vertex] = 1;
    }
    for (size_t a = 0; a < layout.arcs.size(); ++a) {
      mark_arc(static_cast<int>(a));
      node_arcs_[topo.half_node[2 * a]].push_back(static_cast<int>(a));
      if (topo.half_node[2 * a + 1] >= 0 && topo.half_node[2 * a + 1] != topo.half_node[2 * a])
        node_arcs_[topo.half_node[2 * a + 1]].push_back(static_cast<int>(a));
    }
    face_patch_ = topo.face_patch;
    patch_faces_.assign(topo.patches.size(), {});
    for (size_t f = 0; f < face_patch_.size(); ++f)
      patch_faces_[face_patch_[f]].push_back(static_cast<int>(f));
  }

  const Layout& layout() const { return layout_; }
  const std::vector<int>& node_arcs(int n) const { return node_arcs_[n]; }

  Layout take_layout() {
    clear_moved_node_outputs();
    return std::move(layout_);
  }

  // Moves every crowded node (another node within options.min_distance − 1 edge rings) that
  // \p movable allows to the nearest vertex where it is not crowded, fewest rings first.
  SeparateNodesResult separate(const std::vector<char>& movable,
                               const SeparateNodesOptions& options) {
    SeparateNodesResult out;
    Layout& layout = layout_;
    const int nn = static_cast<int>(layout.nodes.size());
    for (int n = 0; n < nn; ++n)
      if (crowded(n, layout.nodes[n].vertex, options.min_distance))
        out.crowded_nodes.push_back(layout.nodes[n].id);
    std::vector<char> moved(nn, 0);
    for (int round = 0; round < options.rounds; ++round) {
      bool any = false;
      for (int n = 0; n < nn; ++n) {
        if (!movable.empty() && !movable[n]) continue;
        if (!crowded(n, layout.nodes[n].vertex, options.min_distance)) continue;
        if (!may_move(n)) continue;
        if (separate_node(n, options)) moved[n] = 1, any = true;
      }
      if (!any) break;
    }
    for (int n = 0; n < nn; ++n) {
      if (moved[n]) out.moved_nodes.push_back(layout.nodes[n].id);
      if (crowded(n, layout.nodes[n].vertex, options.min_distance))
        out.still_crowded.push_back(layout.nodes[n].id);
    }
    clear_moved_node_outputs();
    out.layout = std::move(layout);
    return out;
  }

  // A moved node's output fields (point, position, valence) describe its old vertex; a stale
  // `point` would contradict `vertex` (load_layout refuses such a node).
  void clear_moved_node_outputs() {
    for (size_t n = 0; n < input_vertex_.size(); ++n) {
      LayoutNode& node = layout_.nodes[n];
      if (node.vertex == input_vertex_[n]) continue;
      node.point.reset();
      node.position.reset();
      node.valence = -1;
    }
  }

  // Not pinned, no pinned arc, no loop arc, at least one arc.
  bool may_move(int n) const {
    const Layout& layout = layout_;
    if (layout.nodes[n].pinned || node_arcs_[n].empty()) return false;
    for (int a : node_arcs_[n]) {
      const LayoutArc& arc = layout.arcs[a];
      if (arc.pinned || (!arc.dangling() && arc.from == arc.to)) return false;
    }
    return true;
  }

  // Another node than n within min_distance − 1 edge rings of vertex v.
  bool crowded(int n, int v, int min_distance) {
    std::vector<int> ball = ball_vertices(v, min_distance - 1);
    for (int w : ball)
      if (vertex_node_[w] >= 0 && vertex_node_[w] != n) return true;
    return vertex_node_[v] >= 0 && vertex_node_[v] != n;
  }

  // Vertices at 1 … rings edge rings from v0 (breadth-first order: nearer rings first).
  std::vector<int> ball_vertices(int v0, int rings) {
    ++current_stamp_;
    std::vector<int> out;
    stamp_[v0] = current_stamp_;
    size_t begin = 0;
    out.push_back(v0);
    for (int r = 0; r < rings; ++r) {
      const size_t end = out.size();
      for (size_t i = begin; i < end; ++i) {
        for (const auto w : mesh_.vv_range(VH(out[i]))) {
          if (stamp_[w.idx()] == current_stamp_) continue;
          stamp_[w.idx()] = current_stamp_;
          out.push_back(w.idx());
        }
      }
      begin = end;
    }
    out.erase(out.begin());
    return out;
  }

  bool separate_node(int n, const SeparateNodesOptions& options) {
    const Layout& layout = layout_;
    const int v0 = layout.nodes[n].vertex;
    auto point = [&](int v) { return mesh_.point(VH(v)); };
    // The nodes crowding n: the candidates farthest from them are tried first within a ring.
    std::vector<Vec3> crowders;
    for (int w : ball_vertices(v0, options.min_distance - 1))
      if (vertex_node_[w] >= 0 && vertex_node_[w] != n) crowders.push_back(point(w));
    struct Candidate {
      int vertex, ring;
      double clearance;
    };
    std::vector<Candidate> candidates;
    for (int r = 1; r <= options.search_rings; ++r) {
      for (int v : ring_candidates(n, r)) {
        if (vertex_node_[v] >= 0 || crowded(n, v, options.min_distance)) continue;
        double clearance = std::numeric_limits<double>::infinity();
        for (const Vec3& c : crowders) clearance = std::min(clearance, (point(v) - c).norm());
        candidates.push_back({v, r, clearance});
      }
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [](const Candidate& a, const Candidate& b) {
                       if (a.ring != b.ring) return a.ring < b.ring;
                       return a.clearance > b.clearance;
                     });
    const int attempts = std::min<int>(options.max_attempts, static_cast<int>(candidates.size()));
    for (int k = 0; k < attempts; ++k)
      if (try_move(n, candidates[k].vertex)) return true;
    return false;
  }

  // Vertices at exactly r edge rings from v0 (breadth-first distance on the whole mesh), sorted.
  std::vector<int> ring_vertices_at(int v0, int r) {
    ++current_stamp_;
    std::vector<int> frontier{v0}, next;
    stamp_[v0] = current_stamp_;
    for (int k = 0; k < r && !frontier.empty(); ++k) {
      next.clear();
      for (int v : frontier) {
        for (const auto w : mesh_.vv_range(VH(v))) {
          if (stamp_[w.idx()] == current_stamp_) continue;
          stamp_[w.idx()] = current_stamp_;
          next.push_back(w.idx());
        }
      }
      frontier.swap(next);
    }
    std::sort(frontier.begin(), frontier.end());
    return frontier;
  }

  // ---- ownership bookkeeping ----
  int edge_of(int u, int w) const {
    return mesh_.edge_handle(mesh_.find_halfedge(VH(u), VH(w))).idx();
  }

  void mark_arc(int a) {
    const auto& p = layout_.arcs[a].path;
    for (size_t k = 0; k < p.size(); ++k) {
      if (vertex_node_[p[k]] < 0) {
        vertex_arc_[p[k]] = a;
        obstacles_.vertex_blocked[p[k]] = 1;
      }
      if (k == 0) continue;
      const int e = edge_of(p[k - 1], p[k]);
      edge_arc_[e] = a;
      obstacles_.edge_blocked[e] = 1;
    }
  }

  void unmark_arc(int a) {
    const auto& p = layout_.arcs[a].path;
    for (size_t k = 0; k < p.size(); ++k) {
      if (vertex_node_[p[k]] < 0) {
        vertex_arc_[p[k]] = -1;
        obstacles_.vertex_blocked[p[k]] = 0;
      }
      if (k == 0) continue;
      const int e = edge_of(p[k - 1], p[k]);
      edge_arc_[e] = -1;
      obstacles_.edge_blocked[e] = 0;
    }
  }

  void set_node_vertex(int n, int v) {
    const int old = layout_.nodes[n].vertex;
    vertex_node_[old] = -1;
    obstacles_.vertex_blocked[old] = 0;
    layout_.nodes[n].vertex = v;
    vertex_node_[v] = n;
    obstacles_.vertex_blocked[v] = 1;
  }

  // Stamps the vertices reachable from v0 within `depth` steps without entering another node
  // or another arc (the node's own arcs, about to be re-routed, do not count).
  void mark_reachable(int n, int v0, int depth) {
    ++current_stamp_;
    std::vector<int> frontier{v0}, next;
    stamp_[v0] = current_stamp_;
    auto own = [&](int v) {
      const int a = vertex_arc_[v];
      return a >= 0 &&
             std::find(node_arcs_[n].begin(), node_arcs_[n].end(), a) != node_arcs_[n].end();
    };
    for (int r = 0; r < depth && !frontier.empty(); ++r) {
      next.clear();
      for (int v : frontier) {
        for (const auto w : mesh_.vv_range(VH(v))) {
          const int wi = w.idx();
          if (stamp_[wi] == current_stamp_) continue;
          if (obstacles_.vertex_blocked[wi] && !own(wi)) continue;
          stamp_[wi] = current_stamp_;
          next.push_back(wi);
        }
      }
      frontier.swap(next);
    }
  }

  std::vector<int> ring_candidates(int n, int rings) {
    const int v0 = layout_.nodes[n].vertex;
    const bool boundary = mesh_.is_boundary(VH(v0));
    const std::vector<int> ring = ring_vertices_at(v0, rings);
    // A ring vertex beyond another arc would put the node into a foreign patch.
    mark_reachable(n, v0, 2 * rings + 2);
    std::vector<int> candidates;
    for (int v : ring) {
      if (stamp_[v] != current_stamp_) continue;
      if (mesh_.is_boundary(VH(v)) != boundary) continue;
      candidates.push_back(v);
    }
    return candidates;
  }

  // ---- one move ----
  bool try_move(int n, int target_vertex) {
    Layout& layout = layout_;
    const int v0 = layout.nodes[n].vertex;
    // The node's patches: every face around it, and their patches.
    std::vector<int> patches;
    for (const auto f : mesh_.vf_range(VH(v0))) patches.push_back(face_patch_[f.idx()]);
    std::sort(patches.begin(), patches.end());
    patches.erase(std::unique(patches.begin(), patches.end()), patches.end());
    std::vector<int> region_vertices;
    for (int p : patches) {
      for (int f : patch_faces_[p]) {
        for (const auto v : mesh_.fv_range(OpenMesh::FaceHandle(f))) {
          if (!region_[v.idx()]) {
            region_[v.idx()] = 1;
            region_vertices.push_back(v.idx());
          }
        }
      }
    }
    auto clear_region = [&] {
      for (int v : region_vertices) region_[v] = 0;
    };
    if (!region_[target_vertex]) {
      clear_region();
      return false;
    }

    const std::vector<int> arcs = node_arcs_[n];
    std::vector<std::vector<int>> old_paths;
    for (int a : arcs) {
      old_paths.push_back(layout.arcs[a].path);
      unmark_arc(a);
    }
    set_node_vertex(n, target_vertex);
    bool ok = true;
    std::vector<int> routed;
    for (size_t i = 0; i < arcs.size(); ++i) {
      const int a = arcs[i];
      LayoutArc& arc = layout.arcs[a];
      const bool from_here = layout.node_index(arc.from) == n;
      const std::vector<int>& old = old_paths[i];
      const int other = from_here ? old.back() : old.front();
      std::vector<int> path = finder_.find(target_vertex, other, obstacles_, &region_);
      if (path.size() < 2) {
        ok = false;
        break;
      }
      if (!from_here) std::reverse(path.begin(), path.end());
      arc.path = std::move(path);
      mark_arc(a);
      routed.push_back(a);
    }
    ok = ok && orders_kept(n, arcs) && patches_kept(patches);
    clear_region();
    if (ok) {
      commit_patches(patches);
      return true;
    }
    for (int a : routed) unmark_arc(a);
    set_node_vertex(n, v0);
    for (size_t i = 0; i < arcs.size(); ++i) {
      layout.arcs[arcs[i]].path = old_paths[i];
      mark_arc(arcs[i]);
    }
    return false;
  }

  // Half-arcs around node n's vertex, counter-clockwise.
  std::vector<int> order_at(int n) const {
    const Layout& layout = layout_;
    const VH v(layout.nodes[n].vertex);
    std::vector<int> order;
    // Start anywhere: orders are compared up to rotation.
    for (const HH h : mesh_.voh_ccw_range(v)) {
      const int a = edge_arc_[mesh_.edge_handle(h).idx()];
      if (a < 0) continue;
      const auto& p = layout.arcs[a].path;
      const int w = mesh_.to_vertex_handle(h).idx();
      if (p[0] == v.idx() && p[1] == w) order.push_back(2 * a);
      if (p.back() == v.idx() && p[p.size() - 2] == w) order.push_back(2 * a + 1);
    }
    return order;
  }

  bool orders_kept(int n, const std::vector<int>& arcs) const {
    const Layout& layout = layout_;
    if (!same_cycle(reference_order_[n], order_at(n))) return false;
    for (int a : arcs) {
      for (int id : {layout.arcs[a].from, layout.arcs[a].to}) {
        if (id < 0) continue;
        const int m = layout.node_index(id);
        if (m != n && !same_cycle(reference_order_[m], order_at(m))) return false;
      }
    }
    return true;
  }

  // The faces of \p patches split by the current arcs into exactly as many disks.
  bool patches_kept(const std::vector<int>& patches) {
    components_.clear();
    ++current_face_stamp_;
    for (int p : patches)
      for (int f : patch_faces_[p]) face_stamp_[f] = current_face_stamp_;
    const int inside = current_face_stamp_;
    ++current_face_stamp_;  // visited mark
    std::vector<int> stack;
    for (int p : patches) {
      for (int f0 : patch_faces_[p]) {
        if (face_stamp_[f0] != inside) continue;
        components_.emplace_back();
        auto& comp = components_.back();
        face_stamp_[f0] = current_face_stamp_;
        stack.assign(1, f0);
        while (!stack.empty()) {
          const int f = stack.back();
          stack.pop_back();
          comp.push_back(f);
          for (const HH h : mesh_.fh_range(OpenMesh::FaceHandle(f))) {
            const auto e = mesh_.edge_handle(h);
            if (edge_arc_[e.idx()] >= 0 || mesh_.is_boundary(e)) continue;
            const int g = mesh_.opposite_face_handle(h).idx();
            if (face_stamp_[g] != inside) continue;  // outside the region (cannot happen)
            face_stamp_[g] = current_face_stamp_;
            stack.push_back(g);
          }
        }
        if (components_.size() > patches.size()) return false;
      }
    }
    if (components_.size() != patches.size()) return false;
    for (const auto& comp : components_) {
      ++current_stamp_;
      int nv = 0, ne = 0;
      for (int f : comp) {
        for (const HH h : mesh_.fh_range(OpenMesh::FaceHandle(f))) {
          const int v = mesh_.to_vertex_handle(h).idx();
          const int e = mesh_.edge_handle(h).idx();
          if (stamp_[v] != current_stamp_) stamp_[v] = current_stamp_, ++nv;
          if (edge_stamp_[e] != current_stamp_) edge_stamp_[e] = current_stamp_, ++ne;
        }
      }
      if (nv - ne + static_cast<int>(comp.size()) != 1) return false;
    }
    return true;
  }

  // Relabels the region's faces with the components found by patches_kept.
  void commit_patches(const std::vector<int>& patches) {
    for (size_t i = 0; i < patches.size(); ++i) {
      patch_faces_[patches[i]] = components_[i];
      for (int f : components_[i]) face_patch_[f] = patches[i];
    }
  }

 private:
  const TriMesh& mesh_;
  PathFinder finder_;
  Layout layout_;
  std::vector<int> input_vertex_;  // per node, its vertex in the input layout
  std::vector<int> vertex_node_, vertex_arc_, edge_arc_;
  RoutingObstacles obstacles_;
  std::vector<char> region_;
  std::vector<int> stamp_, edge_stamp_, face_stamp_;
  int current_stamp_ = 0, current_face_stamp_ = 0;
  std::vector<std::vector<int>> reference_order_;
  std::vector<std::vector<int>> node_arcs_;
  std::vector<int> face_patch_;
  std::vector<std::vector<int>> patch_faces_;
  std::vector<std::vector<int>> components_;
};

NodeShifter::NodeShifter(const TriMesh& mesh, const Layout& layout)
    : impl_(std::make_unique<Impl>(mesh, layout)) {}

NodeShifter::~NodeShifter() = default;

const Layout& NodeShifter::layout() const {
  return impl_->layout();
}

const std::vector<int>& NodeShifter::node_arcs(int n) const {
  return impl_->node_arcs(n);
}

bool NodeShifter::may_move(int n) const {
  return impl_->may_move(n);
}

std::vector<int> NodeShifter::ring_candidates(int n, int rings) {
  return impl_->ring_candidates(n, rings);
}

bool NodeShifter::try_move(int n, int vertex) {
  return impl_->try_move(n, vertex);
}

SeparateNodesResult NodeShifter::separate(const std::vector<char>& movable,
                                          const SeparateNodesOptions& options) {
  return impl_->separate(movable, options);
}

Layout NodeShifter::take_layout() {
  return impl_->take_layout();
}

SeparateNodesResult separate_nodes(const TriMesh& mesh, const Layout& layout,
                                   const std::vector<char>& movable,
                                   const SeparateNodesOptions& options) {
  if (options.min_distance < 1 || options.search_rings < 1)
    throw InvalidInputError("separate_nodes: min_distance and search_rings must be at least 1");
  if (!movable.empty() && movable.size() != layout.nodes.size())
    throw InvalidInputError("separate_nodes: one movable flag per layout node expected");
  return NodeShifter(mesh, layout).separate(movable, options);
}

}  // namespace qs
