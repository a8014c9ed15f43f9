#include "core/import/base_complex.h"

#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <numeric>
#include <string>

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

namespace {

// Poly-chord collapse on a quad layout whose arcs are quad-mesh vertex walks (coarsen_complex).
// Darts: 2a runs arc a from `from` to `to`, 2a+1 back; a dart is also the half-arc leaving its
// start node. Each patch lists its 4 darts counter-clockwise (the patch left of each).
class ChordCollapser {
 public:
  ChordCollapser(const PolyMesh& quads, const QuadComplex& complex, const CoarsenOptions& options)
      : quads_(quads), complex_(complex), options_(options) {}

  // Builds the patch structure; false (with the reason) when a patch is not 4-sided.
  bool build(std::string& why) {
    const int n_nodes = static_cast<int>(complex_.node_vertex.size());
    const int n_arcs = static_cast<int>(complex_.arcs.size());
    s_.node_vertex = complex_.node_vertex;
    s_.node_alive.assign(n_nodes, 1);
    s_.node_boundary.resize(n_nodes);
    for (int n = 0; n < n_nodes; ++n)
      s_.node_boundary[n] = quads_.is_boundary(VH(s_.node_vertex[n]));
    s_.arcs.resize(n_arcs);
    paths_.resize(n_arcs);
    std::vector<char> marked(quads_.n_edges(), 0);
    std::vector<int> dart_of_first(quads_.n_halfedges(), -1);
    for (int a = 0; a < n_arcs; ++a) {
      const auto& arc = complex_.arcs[a];
      if (arc.path.size() < 2) {
        why = "arc " + std::to_string(a) + " has no edge";
        return false;
      }
      s_.arcs[a] = {arc.from, arc.to, 1};
      paths_[a] = arc.path;
      const auto& p = arc.path;
      for (size_t k = 0; k + 1 < p.size(); ++k)
        marked[quads_.edge_handle(quads_.find_halfedge(VH(p[k]), VH(p[k + 1]))).idx()] = 1;
      dart_of_first[quads_.find_halfedge(VH(p[0]), VH(p[1])).idx()] = 2 * a;
      dart_of_first[quads_.find_halfedge(VH(p[p.size() - 1]), VH(p[p.size() - 2])).idx()] =
          2 * a + 1;
    }
    s_.patch_of_dart.assign(2 * n_arcs, -2);  // -2: not yet visited, -1: exterior
    for (int d0 = 0; d0 < 2 * n_arcs; ++d0) {
      if (s_.patch_of_dart[d0] != -2) continue;
      if (!quads_.face_handle(first_halfedge(d0)).is_valid()) {
        s_.patch_of_dart[d0] = -1;
        continue;
      }
      std::vector<int> cycle;
      int d = d0;
      do {
        if (cycle.size() > 4 || s_.patch_of_dart[d] != -2) {
          why = "a patch of the base complex is not 4-sided";
          return false;
        }
        s_.patch_of_dart[d] = static_cast<int>(s_.patches.size());
        cycle.push_back(d);
        // Turn clockwise around the end node from the face left of the last halfedge until
        // the next arc edge.
        HH g = quads_.next_halfedge_handle(last_halfedge(d));
        while (!marked[quads_.edge_handle(g).idx()])
          g = quads_.next_halfedge_handle(quads_.opposite_halfedge_handle(g));
        d = dart_of_first[g.idx()];
        if (d < 0) {
          why = "the arcs of the complex do not end at its nodes";
          return false;
        }
      } while (d != d0);
      if (cycle.size() != 4) {
        why = "a patch of the base complex has " + std::to_string(cycle.size()) + " sides";
        return false;
      }
      s_.patches.push_back({cycle[0], cycle[1], cycle[2], cycle[3]});
      s_.patch_alive.push_back(1);
    }
    length_.resize(n_arcs);
    for (int a = 0; a < n_arcs; ++a) length_[a] = path_length(paths_[a]);
    return true;
  }

  int run() {
    int collapsed = 0;
    while (true) {
      std::vector<Chord> chords = enumerate_chords();
      std::stable_sort(chords.begin(), chords.end(),
                       [](const Chord& a, const Chord& b) { return a.width < b.width; });
      std::vector<char> touched(s_.patches.size(), 0);
      int round = 0;
      for (const Chord& chord : chords) {
        if (chord.width > options_.max_width) break;
        bool stale = false;
        for (int p : chord.patches) stale = stale || touched[p];
        if (stale) continue;
        if (collapse(chord, touched)) ++round;
      }
      collapsed += round;
      if (round == 0) break;
    }
    return collapsed;
  }

  QuadComplex result() const {
    QuadComplex qc;
    qc.irregular_vertices = complex_.irregular_vertices;
    qc.simple_paths = false;
    std::vector<int> node_index(s_.node_vertex.size(), -1), arc_index(s_.arcs.size(), -1);
    for (size_t n = 0; n < s_.node_vertex.size(); ++n) {
      if (!s_.node_alive[n]) continue;
      node_index[n] = static_cast<int>(qc.node_vertex.size());
      qc.node_vertex.push_back(s_.node_vertex[n]);
    }
    for (size_t a = 0; a < s_.arcs.size(); ++a) {
      if (!s_.arcs[a].alive) continue;
      arc_index[a] = static_cast<int>(qc.arcs.size());
      QuadComplex::Arc arc;
      arc.from = node_index[s_.arcs[a].from];
      arc.to = node_index[s_.arcs[a].to];
      arc.path = paths_[a];
      qc.arcs.push_back(std::move(arc));
    }
    auto half = [&](int d) { return 2 * arc_index[d >> 1] + (d & 1); };
    qc.node_half_arcs.assign(qc.node_vertex.size(), {});
    std::vector<int> any_dart(s_.node_vertex.size(), -1), exterior(s_.node_vertex.size(), -1);
    for (size_t d = 0; d < 2 * s_.arcs.size(); ++d) {
      if (!s_.arcs[d >> 1].alive) continue;
      const int n = start(static_cast<int>(d));
      any_dart[n] = static_cast<int>(d);
      if (s_.patch_of_dart[d] < 0) exterior[n] = static_cast<int>(d);
    }
    for (size_t n = 0; n < s_.node_vertex.size(); ++n) {
      if (!s_.node_alive[n] || any_dart[n] < 0) continue;
      auto& out = qc.node_half_arcs[node_index[n]];
      if (exterior[n] >= 0) {
        // Clockwise from the outgoing boundary dart, then reversed: starts after the
        // exterior sector and ends with the outgoing boundary dart.
        std::vector<int> cw{exterior[n]};
        int e = exterior[n];
        while (s_.patch_of_dart[e ^ 1] >= 0 && cw.size() <= 2 * s_.arcs.size()) {
          e = patch_next(e ^ 1);
          if (e == exterior[n]) break;
          cw.push_back(e);
        }
        for (auto it = cw.rbegin(); it != cw.rend(); ++it) out.push_back(half(*it));
      } else {
        int d = any_dart[n];
        do {
          out.push_back(half(d));
          d = patch_prev(d) ^ 1;
        } while (d != any_dart[n] && out.size() <= 2 * s_.arcs.size());
      }
    }
    for (const auto& list : qc.node_half_arcs) qc.valence.push_back(static_cast<int>(list.size()));
    for (size_t p = 0; p < s_.patches.size(); ++p) qc.num_patches += s_.patch_alive[p];
    return qc;
  }

 private:
  struct ArcRec {
    int from = -1, to = -1;
    char alive = 0;
  };
  // The combinatorial state (copied for a trial collapse; paths are kept apart).
  struct State {
    std::vector<int> node_vertex;
    std::vector<char> node_alive, node_boundary;
    std::vector<ArcRec> arcs;
    std::vector<std::array<int, 4>> patches;
    std::vector<char> patch_alive;
    std::vector<int> patch_of_dart;  // -1: exterior (boundary side)
  };
  struct Chord {
    std::vector<int> patches;  // in order along the strip
    std::vector<int> entry;    // position of the entering side in each patch
    bool closed = false;
    double width = 0;
  };

  HH first_halfedge(int d) const {
    const auto& p = paths_[d >> 1];
    return (d & 1) ? quads_.find_halfedge(VH(p[p.size() - 1]), VH(p[p.size() - 2]))
                   : quads_.find_halfedge(VH(p[0]), VH(p[1]));
  }
  HH last_halfedge(int d) const { return quads_.opposite_halfedge_handle(first_halfedge(d ^ 1)); }
  int start(int d) const { return (d & 1) ? s_.arcs[d >> 1].to : s_.arcs[d >> 1].from; }
  static int start_in(const State& s, int d) {
    return (d & 1) ? s.arcs[d >> 1].to : s.arcs[d >> 1].from;
  }
  static int position(const State& s, int p, int d) {
    for (int i = 0; i < 4; ++i)
      if (s.patches[p][i] == d) return i;
    return -1;
  }
  int patch_next(int d) const {
    const int p = s_.patch_of_dart[d];
    return s_.patches[p][(position(s_, p, d) + 1) % 4];
  }
  int patch_prev(int d) const {
    const int p = s_.patch_of_dart[d];
    return s_.patches[p][(position(s_, p, d) + 3) % 4];
  }
  double path_length(const std::vector<int>& p) const {
    double l = 0;
    for (size_t k = 0; k + 1 < p.size(); ++k)
      l += (quads_.point(VH(p[k + 1])) - quads_.point(VH(p[k]))).norm();
    return l;
  }

  // Every poly-chord once. A chord may cross itself (pass a patch in both directions); it
  // cannot run through a patch twice in the same direction on an orientable surface, such a
  // walk is dropped.
  std::vector<Chord> enumerate_chords() const {
    std::vector<Chord> chords;
    std::vector<std::array<char, 2>> seen(s_.patches.size(), {0, 0});
    std::vector<std::array<char, 2>> in_chord(s_.patches.size(), {0, 0});
    for (size_t p0 = 0; p0 < s_.patches.size(); ++p0) {
      if (!s_.patch_alive[p0]) continue;
      for (int t0 = 0; t0 < 2; ++t0) {
        if (seen[p0][t0]) continue;
        Chord chord;
        bool bad = false;
        std::vector<int> fwd_p{static_cast<int>(p0)}, fwd_t{t0};
        std::vector<int> back_p, back_t;
        in_chord[p0][t0] = 1;
        // Forward through the exit sides.
        int p = static_cast<int>(p0), t = t0;
        while (true) {
          const int e = s_.patches[p][(t + 2) % 4];
          const int q = s_.patch_of_dart[e ^ 1];
          if (q < 0) break;
          const int tq = position(s_, q, e ^ 1);
          if (q == static_cast<int>(p0) && tq == t0) {
            chord.closed = true;
            break;
          }
          if (in_chord[q][tq % 2]) {
            bad = true;
            break;
          }
          in_chord[q][tq % 2] = 1;
          fwd_p.push_back(q);
          fwd_t.push_back(tq);
          p = q, t = tq;
        }
        if (!chord.closed && !bad) {
          p = static_cast<int>(p0), t = t0;
          while (true) {
            const int e = s_.patches[p][t];
            const int q = s_.patch_of_dart[e ^ 1];
            if (q < 0) break;
            const int tq = (position(s_, q, e ^ 1) + 2) % 4;
            if (in_chord[q][tq % 2]) {
              bad = true;
              break;
            }
            in_chord[q][tq % 2] = 1;
            back_p.push_back(q);
            back_t.push_back(tq);
            p = q, t = tq;
          }
        }
        for (size_t i = 0; i < fwd_p.size(); ++i) {
          seen[fwd_p[i]][fwd_t[i] % 2] = 1;
          in_chord[fwd_p[i]][fwd_t[i] % 2] = 0;
        }
        for (size_t i = 0; i < back_p.size(); ++i) {
          seen[back_p[i]][back_t[i] % 2] = 1;
          in_chord[back_p[i]][back_t[i] % 2] = 0;
        }
        if (bad) continue;
        chord.patches.assign(back_p.rbegin(), back_p.rend());
        chord.entry.assign(back_t.rbegin(), back_t.rend());
        chord.patches.insert(chord.patches.end(), fwd_p.begin(), fwd_p.end());
        chord.entry.insert(chord.entry.end(), fwd_t.begin(), fwd_t.end());
        for (size_t i = 0; i < chord.patches.size(); ++i) {
          const auto& P = s_.patches[chord.patches[i]];
          chord.width = std::max(chord.width, length_[P[chord.entry[i]] >> 1]);
          chord.width = std::max(chord.width, length_[P[(chord.entry[i] + 2) % 4] >> 1]);
        }
        chords.push_back(std::move(chord));
      }
    }
    return chords;
  }

  // Removes immediate back-and-forth steps (u v u -> u) from a walk.
  static void reduce_walk(std::vector<int>& p) {
    std::vector<int> out;
    for (int v : p) {
      if (!out.empty() && out.back() == v) continue;
      if (out.size() >= 2 && out[out.size() - 2] == v) {
        out.pop_back();
        continue;
      }
      out.push_back(v);
    }
    p.swap(out);
  }

  int find(std::vector<int>& parent, int x) const {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }

  bool in_range(int valence, bool boundary) const {
    return boundary ? valence >= options_.min_boundary_valence &&
                          valence <= options_.max_boundary_valence
                    : valence >= options_.min_interior_valence &&
                          valence <= options_.max_interior_valence;
  }

  // Collapses \p chord if that is clean (see coarsen_complex); the state is unchanged otherwise.
  bool collapse(const Chord& chord, std::vector<char>& touched) {
    State s = s_;
    const size_t k = chord.patches.size();
    // Crossed arcs (as darts) and the patches the chord passes twice (it crosses itself there).
    std::vector<int> crossing;
    for (size_t i = 0; i < k; ++i) crossing.push_back(s.patches[chord.patches[i]][chord.entry[i]]);
    if (!chord.closed) {
      const auto& last = s.patches[chord.patches[k - 1]];
      crossing.push_back(last[(chord.entry[k - 1] + 2) % 4] ^ 1);
    }
    std::vector<int> sorted_patches = chord.patches;
    std::sort(sorted_patches.begin(), sorted_patches.end());
    std::vector<char> twice(k, 0);
    int self_crossings = 0;
    for (size_t i = 0; i < k; ++i) {
      twice[i] = std::count(sorted_patches.begin(), sorted_patches.end(), chord.patches[i]) > 1;
      self_crossings += twice[i];
    }
    self_crossings /= 2;
    std::vector<int> seen_arcs;
    for (int d : crossing) {
      if (s.arcs[d >> 1].from == s.arcs[d >> 1].to) return false;
      seen_arcs.push_back(d >> 1);
    }
    // Rails: the two uncrossed sides of each patch passed once. A chord running along itself
    // shares rails between its patches; the identified rails then form chains of arcs.
    std::vector<std::array<int, 2>> rails;
    for (size_t i = 0; i < k; ++i) {
      if (twice[i]) continue;  // all four sides are crossed
      const auto& P = s.patches[chord.patches[i]];
      rails.push_back({P[(chord.entry[i] + 1) % 4], P[(chord.entry[i] + 3) % 4]});
    }
    {
      std::vector<int> v = seen_arcs;
      std::sort(v.begin(), v.end());
      if (std::adjacent_find(v.begin(), v.end()) != v.end()) return false;
      for (const auto& r : rails)
        for (int d : r)
          if (std::binary_search(v.begin(), v.end(), d >> 1)) return false;
    }
    // rail_links[a]: the rails identified with arc a (one or two).
    std::map<int, std::vector<int>> rail_links;
    for (const auto& r : rails) {
      rail_links[r[0] >> 1].push_back(r[1] >> 1);
      rail_links[r[1] >> 1].push_back(r[0] >> 1);
    }
    struct Chain {
      int first_outer, last_outer;  // outer darts of the end arcs (not in a chord patch)
      std::vector<int> arcs;
    };
    std::vector<Chain> chains;
    {
      std::vector<char> in_chord_patch(2 * s.arcs.size(), 0);
      for (const auto& r : rails) in_chord_patch[r[0]] = in_chord_patch[r[1]] = 1;
      std::map<int, char> done;
      for (const auto& [a, links] : rail_links) {
        if (links.size() != 1 || done[a]) continue;
        Chain chain;
        int prev = -1, cur = a;
        while (true) {
          chain.arcs.push_back(cur);
          done[cur] = 1;
          const auto& l = rail_links[cur];
          int next = -1;
          for (int b : l)
            if (b != prev) next = b;
          if (l.size() == 1 && prev >= 0) break;
          if (next < 0 || done[next]) return false;
          prev = cur, cur = next;
        }
        auto outer = [&](int arc) { return in_chord_patch[2 * arc] ? 2 * arc + 1 : 2 * arc; };
        chain.first_outer = outer(chain.arcs.front());
        chain.last_outer = outer(chain.arcs.back());
        if (s.patch_of_dart[chain.first_outer] < 0 && s.patch_of_dart[chain.last_outer] < 0)
          return false;  // would pinch two boundary pieces together
        chains.push_back(std::move(chain));
      }
      for (const auto& [a, links] : rail_links)
        if (!done[a]) return false;  // rails closing a cycle
    }
    // Groups of merged nodes: the crossed arcs' ends. Only the cycles closed around the
    // patches where the chord crosses itself may repeat a union; any other would pinch.
    const int n_nodes = static_cast<int>(s.node_vertex.size());
    std::vector<int> parent(n_nodes);
    std::iota(parent.begin(), parent.end(), 0);
    int unions = 0;
    for (int d : crossing) {
      const int x = find(parent, s.arcs[d >> 1].from), y = find(parent, s.arcs[d >> 1].to);
      if (x == y) continue;
      parent[std::max(x, y)] = std::min(x, y);
      ++unions;
    }
    if (unions != static_cast<int>(crossing.size()) - self_crossings) return false;
    std::vector<int> members;
    for (int d : crossing) {
      members.push_back(s.arcs[d >> 1].from);
      members.push_back(s.arcs[d >> 1].to);
    }
    std::sort(members.begin(), members.end());
    members.erase(std::unique(members.begin(), members.end()), members.end());
    std::vector<int> node_at_vertex(quads_.n_vertices(), -1);
    for (int n = 0; n < n_nodes; ++n)
      if (s.node_alive[n]) node_at_vertex[s.node_vertex[n]] = n;
    std::vector<std::vector<int>> ext(n_nodes);
    std::vector<int> reps, new_vertices;
    std::vector<char> has_ext(n_nodes, 0);
    for (int root : members) {
      if (find(parent, root) != root) continue;
      reps.push_back(root);
      std::vector<int> group, group_arcs;
      for (int n : members)
        if (find(parent, n) == root) group.push_back(n);
      for (int d : crossing)
        if (find(parent, s.arcs[d >> 1].from) == root) group_arcs.push_back(d >> 1);
      std::vector<int> boundary_nodes;
      for (int n : group)
        if (s.node_boundary[n]) boundary_nodes.push_back(n);
      // The merge point: an arc of the group and a vertex index on its path.
      int m_arc = -1;
      size_t m_index = 0;
      if (boundary_nodes.size() >= 2) {
        // Only two boundary nodes joined along the boundary may merge (at the middle).
        const int a = group_arcs[0];
        const bool boundary_arc = s.patch_of_dart[2 * a] < 0 || s.patch_of_dart[2 * a + 1] < 0;
        if (group.size() != 2 || !boundary_arc) return false;
        m_arc = a;
        m_index = paths_[a].size() / 2;
      } else if (boundary_nodes.size() == 1) {
        for (int a : group_arcs) {
          if (s.arcs[a].from == boundary_nodes[0]) m_arc = a, m_index = 0;
          if (s.arcs[a].to == boundary_nodes[0]) m_arc = a, m_index = paths_[a].size() - 1;
        }
      } else {
        // The interior path vertex nearest to the group's centroid.
        Vec3 c(0, 0, 0);
        for (int n : group) c += quads_.point(VH(s.node_vertex[n]));
        c /= static_cast<double>(group.size());
        double best = std::numeric_limits<double>::infinity();
        for (int a : group_arcs) {
          const auto& p = paths_[a];
          for (size_t i = 1; i + 1 < p.size(); ++i) {
            if (quads_.is_boundary(VH(p[i])) || node_at_vertex[p[i]] >= 0) continue;
            const double d = (quads_.point(VH(p[i])) - c).sqrnorm();
            if (d < best) best = d, m_arc = a, m_index = i;
          }
        }
        if (m_arc < 0) {
          // No inner vertex: a node of the group itself.
          m_arc = group_arcs[0];
          m_index = 0;
        }
      }
      if (m_arc < 0) return false;
      const auto& mp = paths_[m_arc];
      const int mv = mp[m_index];
      if (node_at_vertex[mv] >= 0 && find(parent, node_at_vertex[mv]) != root) return false;
      new_vertices.push_back(mv);
      // Walks from every group node to the merge point, over a spanning tree of the group's
      // crossed arcs.
      const int x = s.arcs[m_arc].from, y = s.arcs[m_arc].to;
      ext[x].assign(mp.begin(), mp.begin() + m_index + 1);              // x ... m
      ext[y].assign(mp.rbegin(), mp.rbegin() + (mp.size() - m_index));  // y ... m
      has_ext[x] = has_ext[y] = 1;
      for (bool grew = true; grew;) {
        grew = false;
        for (int a : group_arcs) {
          const int u = s.arcs[a].from, w = s.arcs[a].to;
          if (has_ext[u] == has_ext[w]) continue;
          const auto& p = paths_[a];
          if (has_ext[u]) {  // w ... u ... m
            ext[w].assign(p.rbegin(), p.rend());
            ext[w].insert(ext[w].end(), ext[u].begin() + 1, ext[u].end());
            has_ext[w] = 1;
          } else {  // u ... w ... m
            ext[u] = p;
            ext[u].insert(ext[u].end(), ext[w].begin() + 1, ext[w].end());
            has_ext[u] = 1;
          }
          grew = true;
        }
      }
      bool boundary = false;
      for (int n : group) {
        if (!has_ext[n]) return false;
        reduce_walk(ext[n]);
        boundary = boundary || s.node_boundary[n];
        if (n != root) s.node_alive[n] = 0;
      }
      s.node_vertex[root] = mv;
      s.node_boundary[root] = boundary;
    }
    {
      std::vector<int> v = new_vertices;
      std::sort(v.begin(), v.end());
      if (std::adjacent_find(v.begin(), v.end()) != v.end()) return false;
    }
    for (int d : crossing) s.arcs[d >> 1].alive = 0;
    for (auto& arc : s.arcs) {
      if (!arc.alive) continue;
      arc.from = find(parent, arc.from);
      arc.to = find(parent, arc.to);
    }
    // Extended length of an arc (its old ends, walked on to the merge points).
    auto extended_length = [&](int a) {
      return length_[a] + path_length(ext[s_.arcs[a].from]) + path_length(ext[s_.arcs[a].to]);
    };
    std::vector<int> removed_arcs;
    for (const Chain& chain : chains) {
      int keep = chain.arcs.front(), drop = chain.arcs.back();
      int keep_outer = chain.first_outer, drop_outer = chain.last_outer;
      const bool b0 = s.patch_of_dart[keep_outer] < 0, b1 = s.patch_of_dart[drop_outer] < 0;
      if (b1 || (!b0 && extended_length(drop) < extended_length(keep))) {
        std::swap(keep, drop);
        std::swap(keep_outer, drop_outer);
      }
      // The kept arc's other dart takes the place of the dropped end's outer dart.
      const int q = s.patch_of_dart[drop_outer];
      s.patches[q][position(s, q, drop_outer)] = keep_outer ^ 1;
      s.patch_of_dart[keep_outer ^ 1] = q;
      for (int a : chain.arcs) {
        if (a == keep) continue;
        s.patch_of_dart[2 * a] = s.patch_of_dart[2 * a + 1] = -1;
        s.arcs[a].alive = 0;
        removed_arcs.push_back(a);
      }
    }
    for (int p : chord.patches) s.patch_alive[p] = 0;
    // Checks on the result.
    std::vector<char> affected(n_nodes, 0);
    for (int x : reps) affected[x] = 1;
    for (const auto& arc : s.arcs)
      if (arc.alive && arc.from == arc.to && affected[arc.from]) return false;
    std::vector<int> affected_patches;
    for (size_t p = 0; p < s.patches.size(); ++p) {
      if (!s.patch_alive[p]) continue;
      bool hit = false;
      std::array<int, 4> corner{}, side{};
      for (int i = 0; i < 4; ++i) {
        corner[i] = start_in(s, s.patches[p][i]);
        side[i] = s.patches[p][i] >> 1;
        hit = hit || affected[corner[i]];
      }
      if (!hit) continue;
      for (int i = 0; i < 4; ++i) {
        if (!s.arcs[side[i]].alive || s.patch_of_dart[s.patches[p][i]] != static_cast<int>(p))
          return false;
        if (start_in(s, s.patches[p][i] ^ 1) != corner[(i + 1) % 4]) return false;
      }
      affected_patches.push_back(static_cast<int>(p));
      std::sort(corner.begin(), corner.end());
      std::sort(side.begin(), side.end());
      if (std::adjacent_find(corner.begin(), corner.end()) != corner.end() ||
          std::adjacent_find(side.begin(), side.end()) != side.end())
        return false;
    }
    for (int x : reps)
      if (!in_range(valence_of(s, x), s.node_boundary[x])) return false;

    // Commit: the arcs at merged nodes run on to the merge points.
    for (size_t a = 0; a < s.arcs.size(); ++a) {
      if (!s.arcs[a].alive) continue;
      const int from = s_.arcs[a].from, to = s_.arcs[a].to;
      if (ext[from].size() < 2 && ext[to].size() < 2) continue;
      std::vector<int> p;
      if (s.patch_of_dart[2 * a] < 0 || s.patch_of_dart[2 * a + 1] < 0) {
        // Boundary arcs walk along the boundary to the merge points.
        p.assign(ext[from].rbegin(), ext[from].rend());  // m ... from
        if (!p.empty()) p.pop_back();
        p.insert(p.end(), paths_[a].begin(), paths_[a].end());
        if (!ext[to].empty()) p.insert(p.end(), ext[to].begin() + 1, ext[to].end());  // ... m
      } else {
        // Inner arcs jump straight from the merge points to where they are farther from the
        // old node than the merge point is (so arcs that left the old node in different
        // directions also leave the merge point in different directions, and share no walk).
        const auto& q = paths_[a];
        size_t first = 0, last = q.size() - 1;
        auto reach = [&](int node) {
          return ext[node].empty()
                     ? 0.0
                     : (quads_.point(VH(ext[node].back())) - quads_.point(VH(ext[node].front())))
                           .norm();
        };
        const double r_from = reach(from), r_to = reach(to);
        while (first + 1 < last &&
               (quads_.point(VH(q[first])) - quads_.point(VH(q.front()))).norm() < r_from)
          ++first;
        while (last > first + 1 &&
               (quads_.point(VH(q[last])) - quads_.point(VH(q.back()))).norm() < r_to)
          --last;
        if (!ext[from].empty()) p.push_back(ext[from].back());
        p.insert(p.end(), q.begin() + first, q.begin() + last + 1);
        if (!ext[to].empty()) p.push_back(ext[to].back());
      }
      reduce_walk(p);
      paths_[a] = std::move(p);
      length_[a] = path_length(paths_[a]);
    }
    for (int p : chord.patches) touched[p] = 1;
    for (int p : affected_patches) touched[p] = 1;
    for (int a : removed_arcs) paths_[a].clear();
    for (int d : crossing) paths_[d >> 1].clear();
    s_ = std::move(s);
    return true;
  }

  static int valence_of(const State& s, int n) {
    int v = 0;
    for (const auto& arc : s.arcs) {
      if (!arc.alive) continue;
      v += (arc.from == n) + (arc.to == n);
    }
    return v;
  }

  const PolyMesh& quads_;
  const QuadComplex& complex_;
  const CoarsenOptions& options_;
  State s_;
  std::vector<std::vector<int>> paths_;
  std::vector<double> length_;
};

}  // namespace

QuadComplex coarsen_complex(const PolyMesh& quads, const QuadComplex& complex,
                            const CoarsenOptions& options, CoarsenStats* stats) {
  CoarsenStats local;
  CoarsenStats& st = stats ? *stats : local;
  st = CoarsenStats{};
  st.nodes_before = static_cast<int>(complex.node_vertex.size());
  st.arcs_before = static_cast<int>(complex.arcs.size());
  st.patches_before = complex.num_patches;
  ChordCollapser collapser(quads, complex, options);
  QuadComplex out;
  if (!collapser.build(st.skipped)) {
    out = complex;
  } else {
    if (options.max_width > 0) st.chords_collapsed = collapser.run();
    out = st.chords_collapsed > 0 ? collapser.result() : complex;
  }
  st.nodes_after = static_cast<int>(out.node_vertex.size());
  st.arcs_after = static_cast<int>(out.arcs.size());
  st.patches_after = out.num_patches;
  return out;
}

}  // namespace qs
