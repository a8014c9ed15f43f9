#include "core/import/base_complex.h"

#include <algorithm>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.h"

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;
using VH = OpenMesh::VertexHandle;

// Next outgoing halfedge counter-clockwise around its from-vertex (same rule as layout.cpp:
// the face left of h spans the wedge from h to the result).
HH ccw_next(const PolyMesh& mesh, HH h) {
  return mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(h));
}

// Outgoing halfedges of v counter-clockwise; for a boundary vertex starting right after the
// exterior wedge and ending with the outgoing boundary halfedge (LayoutTopology's order).
std::vector<HH> outgoing_ccw(const PolyMesh& mesh, VH v) {
  std::vector<HH> out;
  const HH start = mesh.halfedge_handle(v);
  if (!start.is_valid()) return out;
  HH boundary;
  HH h = start;
  do {
    if (mesh.is_boundary(h)) boundary = h;
    h = ccw_next(mesh, h);
  } while (h != start);
  const HH first = boundary.is_valid() ? ccw_next(mesh, boundary) : start;
  h = first;
  do {
    out.push_back(h);
    h = ccw_next(mesh, h);
  } while (h != first);
  return out;
}

bool is_irregular(const PolyMesh& mesh, VH v) {
  const int valence = static_cast<int>(mesh.valence(v));
  return mesh.is_boundary(v) ? valence != 3 : valence != 4;
}

// The halfedge that continues a separatrix arriving along \p in (pointing at v) "straight"
// through the regular vertex v, or an invalid handle when the separatrix stops at v.
HH straight_continuation(const PolyMesh& mesh, HH in) {
  const VH v = mesh.to_vertex_handle(in);
  if (is_irregular(mesh, v)) return HH();
  const HH back = mesh.opposite_halfedge_handle(in);
  if (!mesh.is_boundary(v)) return ccw_next(mesh, ccw_next(mesh, back));  // opposite edge
  // Boundary valence 3: only a separatrix running along the boundary goes on, along the other
  // boundary edge; one arriving from inside ends here.
  if (!mesh.is_boundary(mesh.edge_handle(in))) return HH();
  for (const HH h : mesh.voh_range(v)) {
    if (h != back && mesh.is_boundary(mesh.edge_handle(h))) return h;
  }
  return HH();
}

// Face components separated by marked edges.
int count_patches(const PolyMesh& mesh, const std::vector<char>& marked) {
  std::vector<int> comp(mesh.n_faces(), -1);
  std::vector<int> stack;
  int count = 0;
  for (const auto f0 : mesh.faces()) {
    if (comp[f0.idx()] >= 0) continue;
    comp[f0.idx()] = count;
    stack.assign(1, f0.idx());
    while (!stack.empty()) {
      const auto f = mesh.face_handle(stack.back());
      stack.pop_back();
      for (const HH h : mesh.fh_range(f)) {
        if (marked[mesh.edge_handle(h).idx()]) continue;
        const auto g = mesh.opposite_face_handle(h);
        if (g.is_valid() && comp[g.idx()] < 0) {
          comp[g.idx()] = count;
          stack.push_back(g.idx());
        }
      }
    }
    ++count;
  }
  return count;
}

// Turns marked edges and node flags into arcs (maximal chains between nodes) and fills the
// derived fields of \p qc.
void collect_arcs(const PolyMesh& mesh, const std::vector<char>& marked, std::vector<char>& is_node,
                  QuadComplex& qc) {
  // Marked cycles without a node get one at their smallest vertex: every vertex of such a
  // cycle has exactly two marked edges, so walking from the smallest unvisited vertex finds it.
  std::vector<int> marked_degree(mesh.n_vertices(), 0);
  for (const auto e : mesh.edges()) {
    if (!marked[e.idx()]) continue;
    ++marked_degree[mesh.to_vertex_handle(mesh.halfedge_handle(e, 0)).idx()];
    ++marked_degree[mesh.to_vertex_handle(mesh.halfedge_handle(e, 1)).idx()];
  }
  std::vector<char> edge_used(mesh.n_edges(), 0);
  auto walk = [&](HH h, std::vector<int>& path) {
    // Follows marked edges from h until a node; marks them used. Returns the end vertex.
    path.assign(1, mesh.from_vertex_handle(h).idx());
    while (true) {
      edge_used[mesh.edge_handle(h).idx()] = 1;
      const VH v = mesh.to_vertex_handle(h);
      path.push_back(v.idx());
      if (is_node[v.idx()]) return v.idx();
      HH next;
      for (const HH g : mesh.voh_range(v)) {
        if (marked[mesh.edge_handle(g).idx()] && !edge_used[mesh.edge_handle(g).idx()]) {
          next = g;
          break;
        }
      }
      if (!next.is_valid()) return v.idx();  // cannot happen: non-nodes have 2 marked edges
      h = next;
    }
  };

  std::vector<int> node_index(mesh.n_vertices(), -1);
  auto add_arcs_from = [&](int v) {
    for (const HH h : outgoing_ccw(mesh, VH(v))) {
      const int e = mesh.edge_handle(h).idx();
      if (!marked[e] || edge_used[e]) continue;
      QuadComplex::Arc arc;
      walk(h, arc.path);
      arc.from = node_index[arc.path.front()];
      arc.to = node_index[arc.path.back()];
      qc.arcs.push_back(std::move(arc));
    }
  };
  auto rebuild_nodes = [&] {
    qc.node_vertex.clear();
    for (const auto v : mesh.vertices()) {
      if (is_node[v.idx()]) {
        node_index[v.idx()] = static_cast<int>(qc.node_vertex.size());
        qc.node_vertex.push_back(v.idx());
      }
    }
  };
  rebuild_nodes();
  for (int v : qc.node_vertex) add_arcs_from(v);
  // Node-free cycles left over.
  bool added = false;
  for (const auto v : mesh.vertices()) {
    if (is_node[v.idx()] || marked_degree[v.idx()] == 0) continue;
    bool unused = false;
    for (const HH h : mesh.voh_range(v)) {
      const int e = mesh.edge_handle(h).idx();
      unused = unused || (marked[e] && !edge_used[e]);
    }
    if (!unused) continue;
    is_node[v.idx()] = 1;
    added = true;
    // Walk the cycle now so later vertices of it are not picked again.
    node_index[v.idx()] = -2;  // placeholder, fixed below
    std::vector<int> path;
    for (const HH h : mesh.voh_range(v)) {
      const int e = mesh.edge_handle(h).idx();
      if (marked[e] && !edge_used[e]) {
        walk(h, path);
        break;
      }
    }
  }
  if (added) {
    // Redo everything with the complete node set (keeps node order and arc order uniform).
    std::fill(edge_used.begin(), edge_used.end(), 0);
    qc.arcs.clear();
    rebuild_nodes();
    for (int v : qc.node_vertex) add_arcs_from(v);
  }

  // Valences and ccw half-arc lists.
  const int n_nodes = static_cast<int>(qc.node_vertex.size());
  qc.valence.assign(n_nodes, 0);
  qc.node_half_arcs.assign(n_nodes, {});
  std::vector<int> half_of_halfedge(mesh.n_halfedges(), -1);
  for (size_t a = 0; a < qc.arcs.size(); ++a) {
    const auto& p = qc.arcs[a].path;
    const size_t k = p.size() - 1;
    half_of_halfedge[mesh.find_halfedge(VH(p[0]), VH(p[1])).idx()] = static_cast<int>(2 * a);
    half_of_halfedge[mesh.find_halfedge(VH(p[k]), VH(p[k - 1])).idx()] =
        static_cast<int>(2 * a + 1);
  }
  for (int n = 0; n < n_nodes; ++n) {
    for (const HH h : outgoing_ccw(mesh, VH(qc.node_vertex[n]))) {
      const int ha = half_of_halfedge[h.idx()];
      if (ha >= 0) qc.node_half_arcs[n].push_back(ha);
    }
    qc.valence[n] = static_cast<int>(qc.node_half_arcs[n].size());
  }
  qc.num_patches = count_patches(mesh, marked);
}

}  // namespace

bool is_pure_quad(const PolyMesh& mesh) {
  for (const auto f : mesh.faces()) {
    if (mesh.valence(f) != 4) return false;
  }
  return true;
}

PolyMesh split_to_quads(const PolyMesh& mesh) {
  PolyMesh out;
  const int nv = static_cast<int>(mesh.n_vertices());
  const int ne = static_cast<int>(mesh.n_edges());
  for (const auto v : mesh.vertices()) out.add_vertex(mesh.point(v));
  for (const auto e : mesh.edges()) {
    const auto h = mesh.halfedge_handle(e, 0);
    out.add_vertex(0.5 *
                   (mesh.point(mesh.from_vertex_handle(h)) + mesh.point(mesh.to_vertex_handle(h))));
  }
  for (const auto f : mesh.faces()) {
    Vec3 c(0, 0, 0);
    int n = 0;
    for (const auto v : mesh.fv_range(f)) c += mesh.point(v), ++n;
    out.add_vertex(c / n);
  }
  for (const auto f : mesh.faces()) {
    const VH centre(nv + ne + f.idx());
    for (const HH h : mesh.fh_range(f)) {
      // Corner at the from-vertex of h: incoming edge = prev(h), outgoing edge = h.
      const VH corner(mesh.from_vertex_handle(h).idx());
      const VH out_mid(nv + mesh.edge_handle(h).idx());
      const VH in_mid(nv + mesh.edge_handle(mesh.prev_halfedge_handle(h)).idx());
      out.add_face(std::vector<VH>{corner, out_mid, centre, in_mid});
    }
  }
  return out;
}

QuadComplex base_complex(const PolyMesh& quads, const BaseComplexOptions& options) {
  QuadComplex qc;
  for (const auto f : quads.faces()) {
    if (quads.valence(f) != 4) {
      throw InvalidInputError("face " + std::to_string(f.idx()) + " has " +
                              std::to_string(quads.valence(f)) +
                              " vertices; the base complex needs a pure quad mesh");
    }
  }
  bool has_boundary = false;
  for (const auto v : quads.vertices()) {
    if (is_irregular(quads, v)) ++qc.irregular_vertices;
    has_boundary = has_boundary || quads.is_boundary(v);
  }

  std::vector<char> marked(quads.n_edges(), 0);
  std::vector<char> is_node(quads.n_vertices(), 0);
  if (options.all_edges) {
    std::fill(marked.begin(), marked.end(), 1);
    for (const auto v : quads.vertices()) is_node[v.idx()] = !quads.is_isolated(v);
  } else {
    if (qc.irregular_vertices == 0 && !has_boundary) {
      throw InvalidInputError(
          "the quad mesh has no irregular vertex, so it has no separatrices and its base complex "
          "is empty; use --all-edges to make every edge of a coarse quad mesh an arc");
    }
    for (const auto e : quads.edges()) marked[e.idx()] = quads.is_boundary(e);
    // Trace: each step marks a new edge, so the total work is O(#E). A separatrix that runs
    // into an already marked edge is on a line traced before (lines are unique per edge).
    for (const auto v : quads.vertices()) {
      if (!is_irregular(quads, v)) continue;
      is_node[v.idx()] = 1;
      for (const HH start : quads.voh_range(v)) {
        HH h = start;
        while (h.is_valid() && !marked[quads.edge_handle(h).idx()]) {
          marked[quads.edge_handle(h).idx()] = 1;
          h = straight_continuation(quads, h);
        }
      }
    }
    for (const auto v : quads.vertices()) {
      int degree = 0;
      for (const HH h : quads.voh_range(v)) degree += marked[quads.edge_handle(h).idx()];
      if (degree >= 3) is_node[v.idx()] = 1;
    }
  }
  collect_arcs(quads, marked, is_node, qc);
  return qc;
}

}  // namespace qs
