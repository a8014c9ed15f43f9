// Importing a quad mesh's patch layout (its base complex, or all its edges) as a Layout on a
// triangle mesh: the triangulated quad mesh itself (exact), or a working mesh of another
// triangle mesh (or of the triangulated quad mesh, for a coarsened complex) onto which the
// layout is transferred (issues #6, #43).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/import/base_complex.h"
#include "core/import/coarsen.h"
#include "core/import/quad_triangulation.h"
#include "core/import/transfer.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

struct QuadImportOptions {
  //! Every edge is an arc and every vertex a node (coarse cages) instead of the base complex.
  bool all_edges = false;
  //! Without a target mesh: split every quad refine × refine (bilinearly) before triangulating.
  //! Ignored with a target mesh (the working mesh refines where the layout needs room).
  int refine = 1;
  //! With a target mesh: a point of the (subdivided) quad mesh farther than this fraction of the
  //! target's bounding-box diagonal from its surface is an error (transfer_quads; for
  //! transfer_complex, a node or arc sample).
  double max_distance_fraction = 0.05;
  //! transfer_complex: initial corridor radius around each projected source arc, in mean edge
  //! lengths of the target.
  double corridor_radius = 2.5;
  //! transfer_complex: how often a failed arc is retried with the corridor radius doubled.
  int corridor_growths = 3;
  //! > 0: coarsen the base complex first (coarsen_complex): collapse its poly-chords whose
  //! crossed arcs are all at most coarsen × the mean edge length of the target mesh (without a
  //! target: of the quad mesh). The coarsened layout is then transferred onto the target, or
  //! onto the triangulated quad mesh (transfer_quads, on a working mesh of it). Optional: the
  //! whole base complex transfers too. Ignored with all_edges.
  double coarsen = 0;
};

struct QuadImportResult {
  //! The triangle mesh the layout lives on: the triangulated quad mesh, or when the layout was
  //! transferred the working mesh (of the target, or of the triangulated quad mesh).
  TriMesh mesh;
  Layout layout;         //!< node i / arc a have id i / a (QuadComplex order)
  PolyMesh quads;        //!< the quad mesh used (after the split of non-quad faces, if any)
  QuadComplex complex;   //!< the layout on \p quads
  bool split = false;    //!< non-quad faces were split (split_to_quads)
  CoarsenStats coarsen;  //!< counts before/after coarsening (after == before without it)
  std::vector<std::string> warnings;
  //! When transferred: the working mesh that \p mesh copies, and the transfer's counts (input =
  //! the target or the triangulated quad mesh, working = \p mesh, growth); else null.
  std::shared_ptr<WorkingMesh> working;
  TransferStats transfer;
};

//! Transfers the complex onto the vertices and edges of another triangle mesh \p target lying
//! near the quad mesh (the target is not refined: for cage_layout; import_quads uses
//! transfer_quads, which refines the target instead):
//! nodes go to the closest surface point of \p target, snapped to the nearest free vertex of
//! its face (or of that face's 1-ring, else up to 3 rings; boundary nodes only to boundary
//! vertices; a node whose neighbours cannot take its arcs in order moves to a free vertex up to
//! 2 rings away); arcs are
//! routed along \p target's edges by a shortest path restricted to a corridor around the
//! closest-point projection of the densely sampled source arc (cost grows with the distance
//! from the projected curve), avoiding the arcs routed before (boundary arcs first, then by
//! increasing length; arcs that fail go first in up to 3 more attempts) and other nodes;
//! boundary arcs use boundary edges only. The result must validate (validate_layout) and keep
//! every node's cyclic order of arcs.
//! \throw InvalidInputError naming the nodes/arcs farther than
//!        options.max_distance_fraction · bbox diagonal, nodes that find no free vertex, the
//!        arcs that could not be routed, validation issues, or nodes whose cyclic order changed.
Layout transfer_complex(const PolyMesh& quads, const QuadComplex& complex, const TriMesh& target,
                        const QuadImportOptions& options = {});

//! Whole import: splits non-quad faces once (with a warning), computes the base complex (or
//! all edges), coarsens it (options.coarsen > 0), then builds the layout exactly on the
//! triangulated quad mesh (\p target == nullptr, not coarsened), or else transfers it
//! (transfer_quads, the n-gons of \p quads subdivided as n-gons) onto a working mesh of
//! \p target, or of the triangulated quad mesh when there is no target (a coarsened complex).
//! QuadImportResult::working is set exactly when the layout was transferred.
//! The triangulated quad mesh must pass the checks of the mesh reader (check_as_read: e.g. no
//! triangle of zero area), so that it can be written and read back.
//! \throw InvalidInputError as base_complex, triangulate_quads, transfer_complex and
//!        transfer_quads; when the triangulation fails the reader's checks, naming its problems
//!        and, for degenerate triangles, the quads they lie in.
QuadImportResult import_quads(const PolyMesh& quads, const TriMesh* target,
                              const QuadImportOptions& options = {});

}  // namespace qs
