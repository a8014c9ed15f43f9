// Integer patch sizes (paper §8, `optimize --integer`): after a relaxed solve every arc's
// parametric length is rounded to a non-zero multiple of the quad size Q, consistently for arcs
// of one poly-chord (their relaxed lengths are equal), and the rounded lengths become linear
// constraints (ParamOptions::arc_lengths) of every later solve.
#pragma once

#include <vector>

#include "core/param/parameterization.h"

namespace qs {

struct IntegerSizes {
  double quad_size = 0;            //!< Q, parameter units
  std::vector<ArcLength> lengths;  //!< one per arc with two end nodes: k·Q, k ≠ 0 integer
  double max_change = 0;           //!< max |rounded − relaxed| over the arcs, parameter units
  int min_multiple = 0;            //!< smallest |k| (1 when a short arc was rounded up)
};

//! Rounds \p relaxed (ParamSolver::arc_lengths of a solved layout) to multiples of
//! \p quad_size: k = max(1, round(|ℓ|/Q)) with the sign of ℓ. Lengths that agree to 1e-7
//! relative (opposite sides of a patch, arcs of one poly-chord) are rounded together, by their
//! mean, so they get the same k. \throw InvalidInputError when quad_size ≤ 0 or a length is not
//! finite.
IntegerSizes round_arc_lengths(const std::vector<ArcLength>& relaxed, double quad_size);

}  // namespace qs
