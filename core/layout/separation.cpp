#include "core/layout/separation.h"

#include <algorithm>

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using HH = OpenMesh::HalfedgeHandle;
using EH = OpenMesh::EdgeHandle;

bool shares(const std::vector<int>& a, const std::vector<int>& b) {
  for (int x : a)
    if (std::find(b.begin(), b.end(), x) != b.end()) return true;
  return false;
}

bool shares3(const std::vector<int>& a, const std::vector<int>& b, const std::vector<int>& c) {
  for (int x : a)
    if (std::find(b.begin(), b.end(), x) != b.end() && std::find(c.begin(), c.end(), x) != c.end())
      return true;
  return false;
}

}  // namespace

std::vector<std::vector<int>> arcs_per_vertex(const TriMesh& mesh, const Layout& layout) {
  std::vector<std::vector<int>> labels(mesh.n_vertices());
  auto add = [&](int v, int arc) {
    if (v < 0 || v >= static_cast<int>(labels.size())) return;
    auto& l = labels[v];
    if (std::find(l.begin(), l.end(), arc) == l.end()) l.push_back(arc);
  };
  for (int a = 0; a < static_cast<int>(layout.arcs.size()); ++a)
    for (int v : layout.arcs[a].path) add(v, a);
  return labels;
}

int separate_layout(WorkingMesh& mesh, const Layout& layout) {
  const TriMesh& m = mesh.mesh();
  std::vector<std::vector<int>> labels = arcs_per_vertex(m, layout);
  std::vector<char> node(m.n_vertices(), 0);
  for (const auto& n : layout.nodes)
    if (n.vertex >= 0 && n.vertex < static_cast<int>(node.size())) node[n.vertex] = 1;
  std::vector<char> arc_edge(m.n_edges(), 0);
  for (const auto& arc : layout.arcs) {
    for (size_t k = 0; k + 1 < arc.path.size(); ++k) {
      const HH h = m.find_halfedge(VH(arc.path[k]), VH(arc.path[k + 1]));
      if (h.is_valid()) arc_edge[m.edge_handle(h).idx()] = 1;
    }
  }
  auto on_layout = [&](int v) { return v < static_cast<int>(labels.size()) && !labels[v].empty(); };
  auto label = [&](int v) -> const std::vector<int>& {
    static const std::vector<int> none;
    return v < static_cast<int>(labels.size()) ? labels[v] : none;
  };
  // Whether edge e must be split (see the header).
  auto conflict = [&](int e) {
    if (e < static_cast<int>(arc_edge.size()) && arc_edge[e]) return false;
    const HH h0 = m.halfedge_handle(EH(e), 0);
    const int u = m.from_vertex_handle(h0).idx(), w = m.to_vertex_handle(h0).idx();
    if (!on_layout(u) || !on_layout(w)) return false;
    const bool both_nodes = u < static_cast<int>(node.size()) && node[u] &&
                            w < static_cast<int>(node.size()) && node[w];
    const bool joined = shares(label(u), label(w));
    if (both_nodes && !joined) return true;
    bool all_on_layout = true, degenerate = false;
    for (int k = 0; k < 2; ++k) {
      const HH h = m.halfedge_handle(EH(e), k);
      if (m.is_boundary(h)) continue;
      const int x = m.to_vertex_handle(m.next_halfedge_handle(h)).idx();
      all_on_layout = all_on_layout && on_layout(x);
      degenerate = degenerate || shares3(label(u), label(w), label(x));
    }
    return joined ? degenerate : all_on_layout;
  };
  int splits = 0;
  const int n_edges = static_cast<int>(m.n_edges());
  for (int e = 0; e < n_edges; ++e) {
    if (m.status(EH(e)).deleted() || !conflict(e)) continue;
    // The split keeps index e on one half; both halves touch the new, free vertex.
    mesh.split_edge(e, 0.5);
    ++splits;
  }
  return splits;
}

}  // namespace qs
