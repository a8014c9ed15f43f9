#include "core/param/cut_graph.h"

#include <deque>
#include <numeric>

#include "core/mesh/mesh_checks.h"

namespace qs {

CutGraph build_cut_graph(const TriMesh& mesh, const GeometryCache& g, const std::vector<int>& p,
                         const std::vector<char>& singular) {
  CutGraph cg;
  const int nf = g.n_faces, ne = g.n_edges;
  cg.cut.assign(ne, 0);
  // Spanning tree of faces across identity-transition edges (BFS); every other interior edge
  // is cut. The period-jump tree of topology.cpp has p = 0, so every face is reached.
  const std::vector<char> tree = dual_spanning_tree(mesh, [&](int e) { return p[e] % 4 == 0; });
  // Per vertex: the number of cut edges at it and the XOR of their indices, which is the
  // index of the only one when there is one (no adjacency walk needed while retracting).
  std::vector<int> valence(g.n_vertices, 0), edge_xor(g.n_vertices, 0);
  for (int e = 0; e < ne; ++e) {
    if (g.edge_face_i[e] < 0 || g.edge_face_j[e] < 0 || tree[e]) continue;
    cg.cut[e] = 1;
    for (int v : g.edge_vertices[e]) ++valence[v], edge_xor[v] ^= e;
  }
  // Retract dangling branches (the result does not depend on the order).
  std::vector<int> stack;
  for (int v = 0; v < g.n_vertices; ++v)
    if (valence[v] == 1 && !singular[v]) stack.push_back(v);
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    if (valence[v] != 1 || singular[v]) continue;
    const int e = edge_xor[v];
    if (p[e] % 4 != 0) continue;  // a rotation seam stays
    cg.cut[e] = 0;
    for (int x : g.edge_vertices[e]) {
      edge_xor[x] ^= e;
      if (--valence[x] == 1 && x != v && !singular[x]) stack.push_back(x);
    }
  }
  for (int e = 0; e < ne; ++e) cg.cut_edges += cg.cut[e];

  // Wedges: union-find of corners across non-cut interior edges.
  std::vector<int> parent(3 * nf);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int e = 0; e < ne; ++e) {
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0 || cg.cut[e]) continue;
    for (int v : g.edge_vertices[e])
      parent[find(3 * i + corner_of(g, i, v))] = find(3 * j + corner_of(g, j, v));
  }
  cg.corner_wedge.assign(3 * nf, -1);
  std::vector<int> id(3 * nf, -1);
  for (int c = 0; c < 3 * nf; ++c) {
    const int r = find(c);
    if (id[r] < 0) id[r] = cg.wedges++;
    cg.corner_wedge[c] = id[r];
  }
  return cg;
}

}  // namespace qs
