// Poly-chord collapse on a quad layout whose arcs are quad-mesh vertex walks: the machinery of
// coarsen_complex (core/import/coarsen.h). Internal to core/import (coarsen.cpp,
// chord_collapse.cpp).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/import/coarsen.h"

namespace qs {

//! Darts: 2a runs arc a from `from` to `to`, 2a+1 back; a dart is also the half-arc leaving its
//! start node. Each patch lists its 4 darts counter-clockwise (the patch left of each).
class ChordCollapser {
 public:
  ChordCollapser(const PolyMesh& quads, const QuadComplex& complex, const CoarsenOptions& options)
      : quads_(quads), complex_(complex), options_(options) {}

  //! Builds the patch structure; false (with the reason in \p why) when a patch is not 4-sided
  //! or the arcs do not end at the nodes.
  bool build(std::string& why);
  //! Collapses clean chords of width <= options.max_width, thinnest first, in rounds until
  //! none is left; returns how many were collapsed.
  int run();
  //! The coarsened complex (surviving nodes and arcs in their old order; simple_paths false).
  QuadComplex result() const;

 private:
  using HH = OpenMesh::HalfedgeHandle;
  using VH = OpenMesh::VertexHandle;

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
  std::vector<Chord> enumerate_chords() const;

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
  bool collapse(const Chord& chord, std::vector<char>& touched);

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

}  // namespace qs
