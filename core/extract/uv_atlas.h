// Texture atlas of the quad mesh's patches (quads.obj's `vt`): where each patch's rectangle of
// patch coordinates (s, t) ∈ [0,w]×[0,h] goes in texture space [0,1]².
#pragma once

#include <array>
#include <vector>

namespace qs {

enum class UvAtlasLayout {
  //! Every patch fills [0,1]² with (s/w, t/h): the patches overlap.
  kPerPatch,
  //! Patches side by side without overlap, each with its aspect ratio w/h and one scale for all
  //! (uniform texel density), separated by gutters, inside [0,1]².
  kPacked,
};

struct UvAtlasOptions {
  UvAtlasLayout layout = UvAtlasLayout::kPerPatch;
  //! kPacked: empty space between two patches' rectangles, in texture units (1 = the atlas
  //! width); half of it between a rectangle and the atlas border. Reduced when so many patches
  //! would not fit: at most 1/(2·⌈√N⌉) for N patches. ≥ 0.
  double gutter = 1.0 / 256;
};

//! One patch's rectangle in texture space: patch coordinate (s, t) maps to
//! (u0 + s/w·(u1 − u0), v0 + t/h·(v1 − v0)).
struct UvRect {
  double u0 = 0, v0 = 0, u1 = 1, v1 = 1;
};

//! Rectangles for patches of parameter sizes \p sizes ((w, h) each, parameter units), in the
//! same order. kPacked: shelf packing of the rectangles sorted by decreasing height, with the
//! largest common scale (found by bisection) at which the shelves fit into [0,1]².
//! \throw InvalidInputError when a w or h is not positive and finite, or the gutter is negative
//! or not finite.
std::vector<UvRect> uv_atlas(const std::vector<std::array<double, 2>>& sizes,
                             const UvAtlasOptions& options);

}  // namespace qs
