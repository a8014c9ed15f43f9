// A quad layout from a polygonal patch partition of a triangle mesh (e.g. QuadWild's own
// patches: the .patch and .corners files it writes beside its quadrangulation). Every n-sided
// patch is split Catmull–Clark-style into n quads (its centre joined to the midpoints of its
// sides), so 4-sided patches become 2 × 2 and 5-sided ones 5 quads; the result lives on the
// same triangle mesh (no projection, no transfer).
#pragma once

#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! A partition of a triangle mesh into polygonal patches.
struct PatchPartition {
  //! Patch id of every face (size #F, ids 0 .. #patches − 1).
  std::vector<int> face_patch;
  //! Per patch: its corner vertices (mesh vertex ids; any order, they are sorted along the
  //! patch boundary). Vertices where three or more patches meet are corners even if missing.
  std::vector<std::vector<int>> corners;
};

//! Reads QuadWild's per-face patch ids (\p patch_file: the face count, then one id per face)
//! and patch corners (\p corners_file: the patch count, then per patch its corner count
//! followed by that many vertex ids), all whitespace-separated integers.
//! \throw InvalidInputError if a file cannot be read, is malformed, or does not match \p mesh
//!        (face count, vertex ids, patch ids out of range).
PatchPartition load_quadwild_partition(const TriMesh& mesh, const std::string& patch_file,
                                       const std::string& corners_file);

struct PatchLayoutStats {
  int partition_patches = 0;  //!< patches of the partition
  int partition_nodes = 0;    //!< its corners (nodes before the split)
  int partition_arcs = 0;     //!< its sides shared between corners (arcs before the split)
  int expected_patches = 0;   //!< quads of the result (sum of quads)
  std::vector<int> sides;     //!< per partition patch: number of sides (k)
  std::vector<int> quads;     //!< per partition patch: quads it was split into (k, or k + 1)
  //! Per partition patch: its centre node id(s): one, or two when no single centre fits.
  std::vector<std::vector<int>> centres;
};

//! The quad layout of a patch partition on \p mesh (Catmull–Clark-style split of every patch):
//! - nodes: the corners; one midpoint vertex inside every side (an interior vertex of the side
//!   within 30% of its length from the middle, chosen by the first patch routed to it); one
//!   centre per patch (an interior vertex far from the patch boundary, in edge hops);
//! - arcs: the two halves of every side; an edge path inside the patch from its centre to each
//!   side midpoint. The k paths of a patch are vertex-disjoint and of least total length (a
//!   min-cost flow that also picks the free midpoints), so they leave the centre in the sides'
//!   order: k quads. Patches with the most sides and least room are routed first.
//! - When no single centre fits (it needs k neighbours and room for k disjoint paths; e.g. a
//!   neck of the patch hides several sides), two centres split the sides into two ranges that
//!   share their end midpoints x and y, adding the quad (centre 0, x, centre 1, y): k + 1 quads.
//! Node order: corners (ascending vertex), midpoints (side order), centres (patch order). The
//! layout is validated.
//! \throw InvalidInputError when a patch is not a disk with one boundary loop, has fewer than 2
//!        sides, a side has a single edge (no midpoint vertex: the mesh is too coarse there), a
//!        patch has no interior vertex or its centre paths cannot be routed, or the result does
//!        not validate; the message names the patch, and *bad_patch (when given) is set to it
//!        (-1 when no single patch is to blame).
Layout layout_from_partition(const TriMesh& mesh, const PatchPartition& partition,
                             PatchLayoutStats* stats = nullptr, int* bad_patch = nullptr);

}  // namespace qs
