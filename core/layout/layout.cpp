#include "core/layout/layout.h"

#include <algorithm>

namespace qs {

// Ids are usually the positions (files written by us, imports, the editor before deletions), so
// that is tried first; otherwise a linear search. Both lookups run once per arc end in
// build_topology and validation, which made them quadratic on layouts with thousands of arcs.
int Layout::node_index(int id) const {
  if (id >= 0 && static_cast<size_t>(id) < nodes.size() && nodes[id].id == id) return id;
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].id == id) return static_cast<int>(i);
  return -1;
}

bool same_cycle(const std::vector<int>& a, const std::vector<int>& b) {
  if (a.size() != b.size()) return false;
  if (a.empty()) return true;
  for (size_t shift = 0; shift < b.size(); ++shift) {
    if (b[shift] != a[0]) continue;
    bool equal = true;
    for (size_t i = 0; i < a.size() && equal; ++i) equal = a[i] == b[(i + shift) % b.size()];
    if (equal) return true;
  }
  return false;
}

int Layout::arc_index(int id) const {
  if (id >= 0 && static_cast<size_t>(id) < arcs.size() && arcs[id].id == id) return id;
  for (size_t i = 0; i < arcs.size(); ++i)
    if (arcs[i].id == id) return static_cast<int>(i);
  return -1;
}

namespace {

using HH = OpenMesh::HalfedgeHandle;

// Next outgoing halfedge counter-clockwise around its from-vertex. The face left of h spans
// the wedge from h to the returned halfedge.
HH ccw_next(const TriMesh& mesh, HH h) {
  return mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(h));
}

// Outgoing halfedges of v in ccw order. For a boundary vertex the list starts right after the
// exterior wedge and ends with the boundary halfedge (whose ccw wedge is the exterior).
std::vector<HH> outgoing_ccw(const TriMesh& mesh, OpenMesh::VertexHandle v) {
  std::vector<HH> out;
  HH start = mesh.halfedge_handle(v);
  if (!start.is_valid()) return out;
  // Find the boundary outgoing halfedge, if any (do not rely on OpenMesh's choice).
  HH h = start;
  HH boundary;
  do {
    if (mesh.is_boundary(h)) boundary = h;
    h = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(h));  // clockwise step
  } while (h != start);
  if (boundary.is_valid()) {
    h = ccw_next(mesh, boundary);
    while (h != boundary) {
      out.push_back(h);
      h = ccw_next(mesh, h);
    }
    out.push_back(boundary);
  } else {
    h = start;
    do {
      out.push_back(h);
      h = ccw_next(mesh, h);
    } while (h != start);
  }
  return out;
}

}  // namespace

std::vector<int> nodes_near_faces(const TriMesh& mesh, const Layout& layout,
                                  const std::vector<int>& faces, int max_rings) {
  std::vector<int> node_at(mesh.n_vertices(), -1);
  for (size_t n = 0; n < layout.nodes.size(); ++n) {
    const int v = layout.nodes[n].vertex;
    if (v >= 0 && v < static_cast<int>(node_at.size())) node_at[v] = static_cast<int>(n);
  }
  std::vector<int> out, dist(mesh.n_vertices(), -1), queue;
  for (int f : faces) {
    if (f < 0 || f >= static_cast<int>(mesh.n_faces())) continue;
    for (int v : queue) dist[v] = -1;
    queue.clear();
    for (auto v : mesh.fv_range(mesh.face_handle(f))) dist[v.idx()] = 0, queue.push_back(v.idx());
    int found = -1;
    for (size_t head = 0; head < queue.size() && found < 0; ++head) {
      const int v = queue[head];
      if (node_at[v] >= 0) {
        found = node_at[v];
      } else if (dist[v] < max_rings) {
        for (auto w : mesh.vv_range(mesh.vertex_handle(v)))
          if (dist[w.idx()] < 0) dist[w.idx()] = dist[v] + 1, queue.push_back(w.idx());
      }
    }
    if (found >= 0 && std::find(out.begin(), out.end(), found) == out.end()) out.push_back(found);
  }
  return out;
}

std::string describe_nodes(const Layout& layout, const std::vector<int>& nodes) {
  std::string out;
  for (int n : nodes) {
    const LayoutNode& node = layout.nodes[n];
    out += (out.empty() ? "node " : ", node ") + std::to_string(node.id) + " (vertex " +
           std::to_string(node.vertex) + ")";
  }
  return out;
}

std::vector<char> arc_edge_mask(const TriMesh& mesh, const Layout& layout) {
  std::vector<char> mask(mesh.n_edges(), 0);
  for (const LayoutArc& arc : layout.arcs)
    for (size_t k = 0; k + 1 < arc.path.size(); ++k) {
      const auto h =
          mesh.find_halfedge(mesh.vertex_handle(arc.path[k]), mesh.vertex_handle(arc.path[k + 1]));
      if (h.is_valid()) mask[mesh.edge_handle(h).idx()] = 1;
    }
  return mask;
}

LayoutTopology build_topology(const TriMesh& mesh, const Layout& layout) {
  LayoutTopology topo;
  const int n_nodes = static_cast<int>(layout.nodes.size());
  const int n_arcs = static_cast<int>(layout.arcs.size());
  topo.num_nodes = n_nodes;
  topo.num_arcs = n_arcs;
  topo.half_node.assign(2 * n_arcs, -1);
  topo.half_first.assign(2 * n_arcs, HH());
  topo.theta.assign(2 * n_arcs, -1);
  topo.node_half_arcs.assign(n_nodes, {});
  topo.valence.assign(n_nodes, 0);

  std::vector<int> node_at_vertex(mesh.n_vertices(), -1);
  for (int i = 0; i < n_nodes; ++i) node_at_vertex[layout.nodes[i].vertex] = i;

  std::vector<int> edge_arc(mesh.n_edges(), -1);
  std::vector<int> half_of_halfedge(mesh.n_halfedges(), -1);
  for (int a = 0; a < n_arcs; ++a) {
    const LayoutArc& arc = layout.arcs[a];
    const auto& p = arc.path;
    for (size_t k = 0; k + 1 < p.size(); ++k) {
      const HH h = mesh.find_halfedge(mesh.vertex_handle(p[k]), mesh.vertex_handle(p[k + 1]));
      edge_arc[mesh.edge_handle(h).idx()] = a;
    }
    const size_t k = p.size() - 1;
    topo.half_first[2 * a] = mesh.find_halfedge(mesh.vertex_handle(p[0]), mesh.vertex_handle(p[1]));
    topo.half_first[2 * a + 1] =
        mesh.find_halfedge(mesh.vertex_handle(p[k]), mesh.vertex_handle(p[k - 1]));
    topo.half_node[2 * a] = layout.node_index(arc.from);
    topo.half_node[2 * a + 1] = arc.dangling() ? -1 : layout.node_index(arc.to);
    half_of_halfedge[topo.half_first[2 * a].idx()] = 2 * a;
    half_of_halfedge[topo.half_first[2 * a + 1].idx()] = 2 * a + 1;
  }

  // Rotation system: half-arcs ccw around each node; θ = next clockwise.
  for (int n = 0; n < n_nodes; ++n) {
    const auto v = mesh.vertex_handle(layout.nodes[n].vertex);
    for (HH h : outgoing_ccw(mesh, v)) {
      const int ha = half_of_halfedge[h.idx()];
      if (ha >= 0 && topo.half_node[ha] == n) topo.node_half_arcs[n].push_back(ha);
    }
    const auto& list = topo.node_half_arcs[n];
    const int m = static_cast<int>(list.size());
    topo.valence[n] = m;
    const bool open = mesh.is_boundary(v);
    for (int i = 0; i < m; ++i) {
      if (i == 0 && open) continue;  // clockwise from the first one is the exterior
      topo.theta[list[i]] = list[(i + m - 1) % m];
    }
  }

  // Patches: face components separated by arc edges and the mesh boundary.
  auto is_wall = [&](OpenMesh::EdgeHandle e) {
    return edge_arc[e.idx()] >= 0 || mesh.is_boundary(e);
  };
  topo.face_patch.assign(mesh.n_faces(), -1);
  int n_patches = 0;
  std::vector<int> stack;
  for (auto f0 : mesh.faces()) {
    if (topo.face_patch[f0.idx()] >= 0) continue;
    const int pid = n_patches++;
    topo.face_patch[f0.idx()] = pid;
    stack.assign(1, f0.idx());
    while (!stack.empty()) {
      const auto f = mesh.face_handle(stack.back());
      stack.pop_back();
      for (auto h : mesh.fh_range(f)) {
        if (is_wall(mesh.edge_handle(h))) continue;
        const auto g = mesh.opposite_face_handle(h);
        if (topo.face_patch[g.idx()] < 0) {
          topo.face_patch[g.idx()] = pid;
          stack.push_back(g.idx());
        }
      }
    }
  }
  topo.patches.assign(n_patches, {});

  // Euler characteristic of each patch cut open along its border: every border vertex copy
  // pairs with one border halfedge, so χ = F − E_inner + V_inner, where inner edges are
  // non-wall edges and inner vertices touch no wall. This is right for slits too (an arc with
  // the patch on both sides, e.g. a dangling arc into a hole).
  {
    for (auto f : mesh.faces()) ++topo.patches[topo.face_patch[f.idx()]].euler;
    for (auto e : mesh.edges())
      if (!is_wall(e))
        --topo.patches[topo.face_patch[mesh.face_handle(mesh.halfedge_handle(e, 0)).idx()]].euler;
    for (auto v : mesh.vertices()) {
      bool inner = !mesh.is_boundary(v);
      for (auto h : mesh.voh_range(v)) inner = inner && !is_wall(mesh.edge_handle(h));
      if (inner)
        ++topo.patches[topo.face_patch[mesh.face_handle(mesh.halfedge_handle(v)).idx()]].euler;
    }
    for (auto f : mesh.faces()) ++topo.patches[topo.face_patch[f.idx()]].faces;
  }
  // Border cycles (patch on the left), corners and darts.
  std::vector<char> visited(mesh.n_halfedges(), 0);
  auto next_border = [&](HH h) {
    HH n = mesh.next_halfedge_handle(h);
    while (!is_wall(mesh.edge_handle(n)))
      n = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(n));
    return n;
  };
  // Start cycles at dart halfedges first so that each patch lists its darts from a corner.
  std::vector<HH> starts;
  for (int ha = 0; ha < 2 * n_arcs; ++ha) starts.push_back(topo.half_first[ha]);
  for (auto h : mesh.halfedges()) starts.push_back(h);
  for (HH s : starts) {
    if (visited[s.idx()] || mesh.is_boundary(s) || !is_wall(mesh.edge_handle(s))) continue;
    auto& patch = topo.patches[topo.face_patch[mesh.face_handle(s).idx()]];
    ++patch.border_cycles;
    HH h = s;
    int guard = 0;
    do {
      visited[h.idx()] = 1;
      const int ha = half_of_halfedge[h.idx()];
      if (ha >= 0) patch.darts.push_back(ha);
      if (edge_arc[mesh.edge_handle(h).idx()] < 0) patch.trimmed = true;  // bare boundary
      const int from_node = node_at_vertex[mesh.from_vertex_handle(h).idx()];
      if (from_node >= 0) patch.corners.push_back(from_node);
      h = next_border(h);
    } while (h != s && ++guard < static_cast<int>(mesh.n_halfedges()));
  }
  return topo;
}

}  // namespace qs
