// Importing a quad mesh's patch layout (its base complex, or all its edges) as a Layout on a
// triangle mesh: the triangulated quad mesh itself (exact), or another triangle mesh onto
// which the layout is transferred (issue #6).
#pragma once

#include <string>
#include <vector>

#include "core/layout/base_complex.h"
#include "core/layout/layout.h"
#include "core/layout/patch_import.h"
#include "core/layout/quad_triangulation.h"
#include "core/mesh/mesh.h"

namespace qs {

struct QuadImportOptions {
  //! Every edge is an arc and every vertex a node (coarse cages) instead of the base complex.
  bool all_edges = false;
  //! Without a target mesh: split every quad refine × refine (bilinearly) before triangulating.
  //! Ignored with a target mesh.
  int refine = 1;
  //! With a target mesh: a node or arc sample farther than this fraction of the target's
  //! bounding-box diagonal from its surface is an error.
  double max_distance_fraction = 0.05;
  //! With a target mesh: initial corridor radius around each projected source arc, in mean edge
  //! lengths of the target.
  double corridor_radius = 2.5;
  //! With a target mesh: how often a failed arc is retried with the corridor radius doubled.
  int corridor_growths = 3;
  //! > 0: coarsen the base complex first (coarsen_complex): collapse its poly-chords whose
  //! crossed arcs are all at most coarsen × the mean edge length of the target mesh (without a
  //! target: of the quad mesh). The coarsened layout is then routed onto the target, or onto
  //! the triangulated quad mesh, like a transfer (without a target use refine >= 2 so the
  //! routes have room). Ignored with all_edges.
  double coarsen = 0;
  //! With a target mesh: a patch partition of the target that the quad mesh was made from
  //! (QuadWild writes its patches as <target>.patch and <target>.corners). When the transfer of
  //! the base complex fails (its separatrices spiral into a grid the target is too coarse for),
  //! the layout is made from this partition instead (layout_from_partition: every n-sided
  //! patch split into quads), with a warning. Not owned; nullptr: no fallback.
  const PatchPartition* target_partition = nullptr;
};

struct QuadImportResult {
  TriMesh mesh;          //!< the triangle mesh the layout lives on
  Layout layout;         //!< node i / arc a have id i / a (QuadComplex order)
  PolyMesh quads;        //!< the quad mesh used (after the split of non-quad faces, if any)
  QuadComplex complex;   //!< the layout on \p quads
  bool split = false;    //!< non-quad faces were split (split_to_quads)
  CoarsenStats coarsen;  //!< counts before/after coarsening (after == before without it)
  std::vector<std::string> warnings;
  //! True when the layout was made from options.target_partition (then \p complex is the base
  //! complex that could not be transferred, and partition_stats describes the layout).
  bool via_partition = false;
  PatchLayoutStats partition_stats;
};

//! Transfers the complex onto another triangle mesh \p target lying near the quad mesh:
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
//! all edges), coarsens it (options.coarsen > 0), then builds the layout on the triangulated
//! quad mesh (\p target == nullptr; exact, or routed like a transfer when coarsened) or on
//! \p target (transfer_complex; when that fails and options.target_partition is given,
//! layout_from_partition on it). The triangulated quad mesh must pass the checks of the mesh
//! reader (check_as_read: e.g. no triangle of zero area), so that it can be written and read
//! back.
//! \throw InvalidInputError as base_complex, triangulate_quads and transfer_complex; when the
//!        triangulation fails the reader's checks, naming its problems and, for degenerate
//!        triangles, the quads they lie in.
QuadImportResult import_quads(const PolyMesh& quads, const TriMesh* target,
                              const QuadImportOptions& options = {});

}  // namespace qs
