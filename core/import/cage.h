// Quad layouts for triangle meshes without any quad structure: a voxel cage (the boundary
// surface of the mesh's voxelization, made manifold and checked to have the mesh's genus,
// voxel_cage.h) is fitted onto the surface (cage_fit.h) and imported through the quad-import
// machinery (quad_import.h), optionally with its irregular nodes simplified (quad_simplify.h).
#pragma once

#include <string>
#include <vector>

#include "core/import/base_complex.h"
#include "core/import/cage_fit.h"
#include "core/import/coarsen.h"
#include "core/import/quad_import.h"
#include "core/import/quad_simplify.h"
#include "core/import/voxel_cage.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

struct CageOptions {
  //! Cells along the longest bounding-box axis for the first attempt.
  int resolution = 12;
  //! Attempts in all: the grid at resolution (shifted by `shift` cells), then shifted by half a
  //! cell more, then resolution + 1, ... until a cage has the mesh's genus and one component
  //! and its layout can be transferred onto the mesh.
  int attempts = 8;
  //! Grid shift (cells) of the first attempt.
  double shift = 0.0;
  //! Sample points per cell and axis of the inside test (voxel_cage): 1 classifies a cell by
  //! its centre; more classify it by its inside fraction (smoother on shapes whose thin parts
  //! are about one cell thick).
  int subsamples = 1;
  //! When no complex of an attempt's fitted cage transfers, the cage is split up to this many
  //! times (refine_fitted_cage, each 4 quads per quad) and the (coarsened, then full) complex
  //! of each split cage is tried again. Ignored with all_edges.
  int max_refine = 2;
  //! Use every cage edge as an arc (one patch per cage quad) instead of the cage's base
  //! complex (separatrices of its irregular vertices).
  bool all_edges = false;
  //! > 0 (base complex only): collapse the cage complex's thin chords (coarsen_complex) whose
  //! crossed arcs are at most this many voxel cells long, e.g. the one-cell steps of
  //! staircases (fewer, larger patches). When the coarsened layout cannot be transferred, the
  //! full complex is tried next.
  double coarsen = 1.5;
  //! Base complex only. Before the transfers of each attempt's unsplit cage: its (coarsened)
  //! complex becomes a coarse quad mesh (a vertex per node, a face per patch; skipped when that
  //! is not a manifold mesh, e.g. two arcs join the same nodes); its nearby irregular vertices
  //! are cancelled (cancel_irregular_vertices, greedy, corners kept within 30°–150°); it is
  //! projected onto the surface, split simplify_splits times (refine_fitted_cage), smoothed
  //! simplify_relaxation times (every vertex to its neighbours' mean, projected back onto
  //! faces facing the same way), and its edges, as straight chains of the split mesh, are
  //! transferred as the arcs. When no irregular node could be cancelled or that transfer
  //! fails, the complexes are tried as without simplify. Fewer irregular nodes (fertility at
  //! resolution 34: 257 -> 139).
  bool simplify = false;
  int simplify_splits = 2;      //!< see simplify
  int simplify_relaxation = 5;  //!< see simplify
  CageFitOptions fit;
  //! Options of the transfer onto the mesh (all_edges and refine are ignored).
  QuadImportOptions transfer;
};

struct CageResult {
  Layout layout;  //!< valid layout on the input mesh (validate_layout passed)
  //! The fitted cage (vertices on the mesh surface) after `refined` splits; its first
  //! voxels.grid_vertex.size() vertices are the voxel cage's. When the simplified layout was
  //! used (simplified), the split coarse mesh instead (its first vertices are the nodes).
  PolyMesh cage;
  QuadComplex complex;      //!< the layout on the cage (after coarsening)
  CoarsenStats coarsen;     //!< before/after counts (equal without coarsening)
  bool simplified = false;  //!< the layout is the simplified one (CageOptions::simplify)
  //! With simplified: the coarse mesh's quads and irregular vertices before/after
  //! cancel_irregular_vertices.
  CageSimplifyStats simplify;
  VoxelCageInfo voxels;
  int resolution = 0;                 //!< resolution of the attempt that succeeded
  double shift = 0;                   //!< grid shift (cells) of the attempt that succeeded
  int refined = 0;                    //!< refine_fitted_cage splits of the cage that succeeded
  int folded_quads = 0;               //!< after fit_cage
  std::vector<std::string> warnings;  //!< attempts that failed, folded quads
};

//! Builds a quad layout on a closed manifold triangle mesh from its voxel cage
//! (voxel_cage + fit_cage + base_complex + transfer_complex). The layout is validated and
//! keeps the cage's cyclic orders (transfer_complex's checks).
//! \throw InvalidInputError when no attempt succeeds; the message lists every attempt's
//!        failure (genus/components, or the transfer's error naming nodes/arcs).
CageResult cage_layout(const TriMesh& mesh, const CageOptions& options = {});

}  // namespace qs
