#include "core/import/coarsen.h"

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "core/import/chord_collapser.h"

namespace qs {

bool ChordCollapser::build(std::string& why) {
  const int n_nodes = static_cast<int>(complex_.node_vertex.size());
  const int n_arcs = static_cast<int>(complex_.arcs.size());
  s_.node_vertex = complex_.node_vertex;
  s_.node_alive.assign(n_nodes, 1);
  s_.node_boundary.resize(n_nodes);
  for (int n = 0; n < n_nodes; ++n) s_.node_boundary[n] = quads_.is_boundary(VH(s_.node_vertex[n]));
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
    dart_of_first[quads_.find_halfedge(VH(p[p.size() - 1]), VH(p[p.size() - 2])).idx()] = 2 * a + 1;
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

int ChordCollapser::run() {
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

QuadComplex ChordCollapser::result() const {
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

std::vector<ChordCollapser::Chord> ChordCollapser::enumerate_chords() const {
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
