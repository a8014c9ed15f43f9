// Cross-field topology fixed by the layout (paper §4.1; docs/design.md, "Field topology"): integer
// period jumps on dual edges such that every irregular node's vertex has index (4 − valence)/4,
// every other interior vertex index 0, and every layout cycle (hence every homology generator and
// boundary loop) the turning number the layout implies. Exact integer construction by
// tree–cotree elimination; no rounding of geometric angles.
#pragma once

#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

struct PeriodJumpReport {
  int free_unknowns = 0;   //!< generator (and extra boundary-loop) jumps fixed by layout cycles
  int cycles = 0;          //!< layout cycles used
  int cycles_skipped = 0;  //!< cycles through the boundary that cannot carry a left strip
  int rank = 0;            //!< rank of the cycle system in the free unknowns
  //! undetermined (free) boundary loops whose turning FreeLoopTurning fixed, shortest first
  int boundary_loop_equations = 0;
  int max_abs_jump = 0;
};

//! Target index of each vertex in quarter turns (size #V): 4 − valence at node vertices, 0
//! elsewhere, and 0 (unused) on boundary vertices.
std::vector<int> target_quarter_indices(const TriMesh& mesh, const Layout& layout,
                                        const LayoutTopology& topology);

//! How the field turns along a boundary loop that the layout leaves free (no node on it, no
//! closed arc cycle around it: a hole that only dangling arcs run into).
enum class FreeLoopTurning {
  //! As around a regular point, as if the hole were capped by a disk without singularity: the
  //! iso-lines run on across the hole (one or a few arcs into a hole; the default).
  kCap,
  //! Like the loop's tangent, as along an aligned boundary: the iso-lines wrap around the hole,
  //! an O-grid around it (many arcs radiating into a hub).
  kWrap,
};

//! Period jumps p_e per edge (size #E; 0 on boundary edges) for the canonical dual orientation
//! of GeometryCache. Never reduced mod 4.
//! \pre the layout is valid (validate_layout) and \p topology was built from it.
//! \throw TopologyError naming the offending layout cycle (its arc ids) when the layout's
//!        turning numbers are inconsistent or not integral, or naming the boundary loop /
//!        generator when the layout does not determine it.
std::vector<int> compute_period_jumps(const TriMesh& mesh, const GeometryCache& geometry,
                                      const Layout& layout, const LayoutTopology& topology,
                                      PeriodJumpReport* report = nullptr,
                                      FreeLoopTurning free_loops = FreeLoopTurning::kCap);

//! Index of every interior vertex in quarter turns from the period jumps and κ alone:
//! 4·I(v) = 4·I_0(v) − Σ_ccw p. Boundary vertices get 0. Size #V.
std::vector<int> quarter_indices_from_jumps(const GeometryCache& geometry,
                                            const std::vector<int>& p);

//! The closed layout cycles used to fix generators: each is a list of (arc index, forward).
std::vector<std::vector<std::pair<int, bool>>> layout_fundamental_cycles(
    const Layout& layout, const LayoutTopology& topology);

}  // namespace qs
