// Quad layouts for triangle meshes without any quad structure: a voxel cage (the boundary
// surface of the mesh's voxelization, made manifold and checked to have the mesh's genus) is
// fitted onto the surface and imported through the quad-import machinery (quad_import.h).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/import/base_complex.h"
#include "core/import/quad_import.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! Occupancy grid of a voxelization. Cell (i, j, k), 0 <= i < dims[0] etc., is the box
//! origin + h·[i, i+1] × [j, j+1] × [k, k+1] (mesh length units). The outermost layer of
//! cells is always empty.
struct VoxelGrid {
  std::array<int, 3> dims{{0, 0, 0}};  //!< cells per axis
  Vec3 origin{0, 0, 0};                //!< corner of cell (0, 0, 0)
  double h = 0;                        //!< cell edge length
  std::vector<uint8_t> occupied;       //!< per cell, index i + dims[0]·(j + dims[1]·k)

  int cell(int i, int j, int k) const { return i + dims[0] * (j + dims[1] * k); }
  bool at(int i, int j, int k) const { return occupied[cell(i, j, k)] != 0; }
};

//! What voxel_cage did.
struct VoxelCageInfo {
  VoxelGrid grid;         //!< final occupancy (after repairs)
  int inside_cells = 0;   //!< cells classified inside (ray parity, 2 of 3 axes)
  int filled_voids = 0;   //!< empty cells not reachable from outside, filled
  int flipped_cells = 0;  //!< cells filled or carved to make the surface manifold
  int genus = 0;          //!< of the cage surface
  int components = 0;     //!< of the cage surface
  //! Per cage vertex: its grid point (x, y, z), 0 <= x <= dims[0] etc.
  std::vector<std::array<int, 3>> grid_vertex;
};

//! The boundary surface of the voxelization of a closed triangle mesh as a pure quad mesh,
//! one quad per boundary face of the occupied cells, oriented outward, at the voxel
//! positions. A sample point is inside when it is inside for the ray parity along at least
//! two of the three axes (rays slightly offset from the sample points against exact hits); a
//! cell is occupied when at least half of its subsamples³ sample points (the centres of a
//! subsamples × subsamples × subsamples split of the cell; 1: the cell centre) are inside.
//! Empty cells enclosed by occupied ones are filled; then, until the surface is manifold at
//! every grid vertex (the occupied and the empty cells of its 2×2×2 block are each
//! face-connected in the block), the cell of a bad block whose centre lies closest to the
//! mesh surface is flipped (preferring flips that repair the block; each cell flips at most
//! once).
//! \param resolution cells along the longest bounding-box axis (2..200; memory grows with its
//! cube). \throw InvalidInputError for a mesh with boundary or without faces, a resolution or
//!        subsamples out of range, or a configuration that cannot be repaired.
//! \param shift offset of the grid along every axis, in cells (another sampling of the shape).
//! \param subsamples sample points per cell and axis (1..8), see above.
PolyMesh voxel_cage(const TriMesh& mesh, int resolution, VoxelCageInfo* info = nullptr,
                    double shift = 0.0, int subsamples = 1);

struct CageFitOptions {
  //! Uniform Laplacian smoothing rounds of the voxel cage in 3D before the first projection
  //! (removes the staircase; the projection undoes the shrinking).
  int presmoothing = 3;
  //! Rounds of tangential spring relaxation (cage edges towards their mean length, quad
  //! diagonals towards √2 times it, moved within the surface's tangent plane), each followed
  //! by a closest-point re-projection onto faces facing the same way.
  int iterations = 30;
  double step = 0.5;  //!< fraction of the move towards the neighbours' mean per round
};

//! Moves the cage's vertices onto \p mesh: presmoothing, closest-point projection, then
//! tangential smoothing + re-projection. Returns the number of folded quads afterwards (the
//! normal of the projected quad points against the mesh normal at its corners).
int fit_cage(PolyMesh& cage, const TriMesh& mesh, const CageFitOptions& options = {});

//! Splits every quad of a fitted cage into 4 (split_to_quads: edge midpoints and face
//! centroids, original vertices kept with their indices) and moves the new vertices onto
//! \p mesh (closest point on a face facing the same way as the split cage at the vertex).
//! Straight cage edges cut across concave corners and narrow gaps between their end vertices;
//! the split ones follow the surface, so the transfer's closest-point samples of an arc stay
//! on the arc's own side. The base complex keeps its nodes (the new vertices are regular).
//! \pre is_pure_quad(cage).
void refine_fitted_cage(PolyMesh& cage, const TriMesh& mesh);

//! What cancel_irregular_vertices did.
struct CageSimplifyStats {
  int quads_before = 0, quads_after = 0;
  int irregular_before = 0, irregular_after = 0;  //!< vertices of valence != 4
  int collapses = 0, rotations = 0;               //!< operations applied
};

struct QuadSimplifyOptions {
  //! Rounds of look-ahead after the greedy pass (0: greedy only), see
  //! cancel_irregular_vertices.
  int rounds = 0;
  //! Neutral operations in a row before the improving one in a look-ahead (>= 1).
  int depth = 1;
  //! With surface normals: the smallest sin(corner angle) of a face an operation makes or
  //! changes (0.5: corners between 30° and 150°).
  double min_corner_sine = 0.5;
};

//! Cancels nearby irregular vertices of a closed pure quad mesh (e.g. the valence-3/5 pairs a
//! voxel staircase leaves about one cell apart) by local operations that keep it a closed
//! manifold quad mesh of the same genus:
//! - diagonal collapse of a quad (a, b, c, d): a and c merge at their midpoint (valence
//!   val(a) + val(c) − 2), b and d lose one edge;
//! - edge rotation: the edge between two quads turns to another diagonal of their hexagon (its
//!   ends lose one edge, two opposite hexagon corners gain one).
//! Every operation keeps all valences >= 3 (at most 8). Greedy pass: operations that lower
//! Σ (valence − 4)² are applied until there is none. Then, for options.rounds rounds, at each
//! irregular vertex: an operation that leaves the sum unchanged is kept when, after at most
//! options.depth − 1 further such operations at the irregular vertices it touched, an
//! improving one becomes possible nearby (moves a defect towards its partner).
//! \param normals if given, unit surface normal per vertex: every face an operation makes or
//!        changes must then turn the normals' way at each corner, with sin(angle) >=
//!        options.min_corner_sine (a merged vertex takes the mean normal); keeps a coarse mesh
//!        on a surface unfolded.
//! \param kept_vertex if given, receives the old index of each vertex of the result (vertices
//!        are renumbered compactly in their old order; of a merged pair, the one that
//!        survives).
//! \pre is_pure_quad(quads), closed and manifold.
CageSimplifyStats cancel_irregular_vertices(PolyMesh& quads,
                                            const QuadSimplifyOptions& options = {},
                                            const std::vector<Vec3>* normals = nullptr,
                                            std::vector<int>* kept_vertex = nullptr);

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
