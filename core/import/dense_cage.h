// A quad structure (a quad mesh or a subdivision cage) subdivided by Catmull–Clark until its
// edges are about as long as a target mesh's, with every arc of its layout traced through the
// subdivided mesh (docs/design.md, "Transfer").
#pragma once

#include <cstddef>
#include <vector>

#include "core/import/base_complex.h"
#include "core/mesh/mesh.h"

namespace qs {

struct DenseCageOptions {
  //! Subdivide while the mean edge length of the subdivided mesh exceeds this (model units;
  //! <= 0: no subdivision beyond the first step that n-gon cages need) ...
  double max_mean_edge = 0;
  //! ... and while the next level has at most this many faces.
  std::size_t max_faces = 4'000'000;
};

//! The subdivided quad structure.
struct DenseCage {
  //! The cage after `levels` Catmull–Clark steps (OpenMesh's CatmullClarkT on the cage as given,
  //! n-gons included). Its first #V(quads) vertices are the quad structure's vertices, same
  //! indices (moved by the subdivision's smoothing).
  PolyMesh mesh;
  //! Per vertex of `mesh` (size #V): its position under the same steps of linear subdivision
  //! (edge points at edge midpoints, face points at face centroids, old vertices unmoved): the
  //! cage's own surface, where `mesh` has the smoothed one.
  std::vector<Vec3> linear;
  int levels = 0;
  //! Levels between the quad structure and `mesh`: levels, or levels − 1 when the quad
  //! structure is the cage's first step (a cage with n-gons).
  int levels_below_quads = 0;
  //! Vertices of the quad structure (they are the first ones of `mesh`).
  int quad_vertices = 0;
  //! Per face of `mesh` (size #F): the face of the quad structure it lies in.
  std::vector<int> quad_of_face;
  //! Per arc of the complex: its vertex chain in `mesh` (node to node), each edge of the arc's
  //! quad-structure path replaced by the 2^levels_below_quads edges of `mesh` along it; steps
  //! of the path that are not edges (a coarsened complex's jumps) stay single steps.
  std::vector<std::vector<int>> arc_chains;
};

//! Subdivides \p cage and traces \p complex (a layout on \p quads) through it. \p quads is the
//! quad structure the complex lives on: \p cage itself when every face of \p cage is a quad,
//! else split_to_quads(\p cage) (whose vertices and edges are those of the cage's first
//! Catmull–Clark step, which is then always taken: the n-gons are subdivided as n-gons, never
//! as their quadrangulation). Further steps are taken while options allow.
//! \throw InvalidInputError when \p quads is neither \p cage nor its split into quads (vertex
//!        counts or edges differ), or when an arc path has fewer than 2 vertices, a vertex out of
//!        range or a vertex repeated in a row.
DenseCage subdivide_cage(const PolyMesh& cage, const PolyMesh& quads, const QuadComplex& complex,
                         const DenseCageOptions& options = {});

}  // namespace qs
