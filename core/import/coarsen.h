// Coarsening a quad layout on a quad mesh by poly-chord collapse (import-quads --coarsen and
// cage layouts): removes the thin strips of patches that spiralling separatrices and staircase
// boundaries make.
#pragma once

#include <string>

#include "core/import/base_complex.h"
#include "core/mesh/mesh.h"

namespace qs {

struct CoarsenOptions {
  //! Collapse every poly-chord of the complex whose crossing arcs are all at most this long
  //! (model units, measured along the arcs' quad-mesh paths). <= 0: nothing is collapsed.
  double max_width = 0;
  //! Valence range allowed for a merged interior node / a merged boundary node (a boundary
  //! node's valence counts its two boundary arcs).
  int min_interior_valence = 3, max_interior_valence = 5;
  int min_boundary_valence = 2, max_boundary_valence = 4;
};

struct CoarsenStats {
  int nodes_before = 0, arcs_before = 0, patches_before = 0;
  int nodes_after = 0, arcs_after = 0, patches_after = 0;
  int chords_collapsed = 0;
  //! Why nothing could be collapsed at all (e.g. a patch that is not 4-sided), or "".
  std::string skipped;
};

//! Coarsens a quad layout on a quad mesh by poly-chord collapse (issue #6): a poly-chord is a
//! strip of patches entered and left through opposite sides; collapsing it merges the two end
//! nodes of every arc it crosses (into a quad-mesh vertex halfway along that arc, or into the
//! boundary end of an arc that reaches the boundary) and merges the two side arcs of each of its
//! patches into one (the boundary one, else the shorter). Every remaining patch stays a 4-sided
//! disk and genus and boundary loops are kept. Chords are collapsed thinnest first (width = the
//! longest arc they cross), as long as their width is at most options.max_width, and only when
//! the collapse is clean: the chord does not cross itself or run along itself, it crosses no
//! loop arc, no node lies on two of its crossed arcs, no two boundary nodes get merged through
//! the interior, every merged node keeps a valence in the allowed range, and afterwards no arc
//! is a loop, no patch has a repeated corner or side and no two nodes share a vertex. Removing
//! thin chords removes the dense grids made by spiralling separatrices and by staircase
//! boundaries. Arc paths extended to merged nodes make the result's paths walks
//! (simple_paths = false); transfer_complex routes them onto a triangle mesh.
//! Node order: surviving nodes in their old order; arcs likewise.
//! If a patch of \p complex is not 4-sided, returns it unchanged with stats->skipped set.
QuadComplex coarsen_complex(const PolyMesh& quads, const QuadComplex& complex,
                            const CoarsenOptions& options, CoarsenStats* stats = nullptr);

}  // namespace qs
