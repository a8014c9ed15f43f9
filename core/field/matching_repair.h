// Keeps a cross field's principal matching equal to its prescribed period jumps: where the
// smoothest field turns by more than 45° across an edge (against the transport and the period
// jump), the principal matching between the two faces picks the other quarter turn, and an
// index check measured on the field alone moves the singularity to a neighbouring vertex (next
// to a node on a vertex with a large angle defect, e.g. a sharp cone of a coarse input). The
// repair spreads that turn over the faces around such edges, so the field's singularities are
// exactly those of the period jumps (the layout's irregular nodes).
#pragma once

#include <vector>

#include "core/mesh/geometry.h"

namespace qs {

struct MatchingRepairOptions {
  //! Edges whose turn against transport and period jump exceeds this (radians) are repaired.
  //! Just below 45°, so that an edge at 45° up to round-off is repaired too.
  double trigger = 0.785;
  //! After the repair every edge of a repaired region turns by at most this (radians): a
  //! margin below 45° that survives a re-measurement on written, rounded directions.
  double target = 0.70;
  //! Face rings (dual-graph steps) around the repaired edges whose θ may change; tried in turn
  //! (larger regions when a smaller one cannot hold the target).
  std::vector<int> rings = {2, 4, 8};
  int max_rounds = 16;         //!< reweighting rounds per region size
  double weight_growth = 4.0;  //!< factor on an edge's weight while it turns too far
};

struct MatchingRepairResult {
  int mismatched_before = 0;  //!< edges beyond `trigger` on entry
  int mismatched_after = 0;   //!< edges beyond 45° on return (0 unless no region held)
  int changed_faces = 0;      //!< faces whose θ was changed
};

//! Repairs \p theta (per face, radians from the frames of \p geometry, size #F) against the
//! period jumps \p period_jump (per edge, canonical dual orientation, size #E, see CrossField):
//! when some interior edge turns by more than options.trigger, the θ of the non-\p fixed faces
//! (per face, size #F; e.g. the direction constraints in force) within a few rings of those
//! edges minimize the field's edge energy Σ w_e (θ_j − θ_i − κ_e − (π/2)p_e)² with the faces
//! outside held, the weights w_e (1 at first: the smoothest field's own energy) growing on the
//! edges that still turn too far, until every edge of the region turns by at most
//! options.target. Without such edges θ is returned unchanged. When no region size holds the
//! target (a vertex whose angle defect exceeds what its edges can carry: no field with these
//! period jumps avoids the turn), θ is the attempt with the fewest edges beyond 45°, if fewer
//! than before, else unchanged; mismatched_after counts them.
//! \throw InvalidInputError when the sizes do not match \p geometry.
MatchingRepairResult repair_principal_matching(const GeometryCache& geometry,
                                               const std::vector<int>& period_jump,
                                               const std::vector<char>& fixed,
                                               std::vector<double>& theta,
                                               const MatchingRepairOptions& options = {});

}  // namespace qs
