// Patch charts (paper Appendix D; docs/design.md, "Patch charts"): every full quad patch of the
// traced base complex gets one common 2D chart in which it is the rectangle [0,w]×[0,h], with point
// location (patch coordinates → surface point). Built without splitting the mesh: a BFS over face
// *instances* composes the transitions of the seamless parameterization, restricted to faces
// whose mapped triangle overlaps the open patch rectangle.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/extract/tracing.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"

namespace qs {

//! One mesh face placed into a patch chart. The same face may appear more than once, with
//! different placements (e.g. a patch whose border runs twice along the same arc).
struct PatchChartTriangle {
  int face = -1;
  //! Patch coordinates (s, t) of the face's corners, in GeometryCache::face_vertices order.
  std::array<std::array<double, 2>, 3> st{};
};

struct PatchChartOptions {
  //! The rectangle is shrunk by this fraction of max(w, h) when deciding whether a mapped
  //! triangle overlaps its interior (keeps faces that only touch a side out of the chart).
  double overlap_margin = 1e-7;
  //! Corner nodes must land within this fraction of max(w, h) of their rectangle corners.
  double corner_tolerance = 1e-4;
  //! Barycentric tolerance of point location.
  double locate_tolerance = 1e-7;
};

//! The chart of one patch. Patch coordinates are in parameter units: corner k of the patch
//! (LayoutTopology::Patch::corners[k]) is at (0,0), (w,0), (w,h), (0,h) for k = 0..3; side 0
//! (dart 0) runs along +s, and the patch interior is at t > 0 (counter-clockwise, as the
//! surface is oriented).
class PatchChart {
 public:
  int patch = -1;           //!< patch index in LayoutTopology::patches
  bool ok = false;          //!< the chart was built and its corners check out
  std::string failure;      //!< why not, when !ok
  double w = 0, h = 0;      //!< rectangle size, parameter units
  double corner_error = 0;  //!< max distance of a corner node from its rectangle corner
  std::vector<PatchChartTriangle> triangles;

  //! Locates patch coordinates \p st on the surface. Returns false when no placed triangle
  //! contains \p st (within the tolerance). \p out gets the face and barycentric coordinates
  //! (face_vertices order).
  bool locate(const std::array<double, 2>& st, SurfacePoint& out) const;

  //! Builds the uniform bin grid used by locate() (called by build_patch_chart; call it again
  //! after changing `triangles`, w or h).
  void build_bins();

  double locate_tolerance = 1e-7;  //!< barycentric tolerance of locate()

 private:
  int bins_x_ = 0, bins_y_ = 0;
  std::vector<int> bin_start_;  //!< CSR over bins, size bins_x_·bins_y_ + 1
  std::vector<int> bin_items_;  //!< triangle indices
};

//! True for a patch that can be gridded: 4 darts, 4 corners, not trimmed, a disk.
bool is_quad_patch(const LayoutTopology::Patch& patch);

//! Builds the chart of patch \p patch (index into topology.patches).
//! \p period_jump: per edge (CrossField::period_jump); \p corner_uv: per face corner
//! (Parameterization::corner_uv, size 3·#F). Never throws for a bad patch: returns ok == false
//! with a reason (not a quad patch, an arc of its border failed to trace, the corners do not
//! land on the rectangle, ...).
PatchChart build_patch_chart(const TriMesh& mesh, const GeometryCache& geometry,
                             const Layout& layout, const LayoutTopology& topology,
                             const Extraction& extraction, const std::vector<int>& period_jump,
                             const std::vector<std::array<double, 2>>& corner_uv, int patch,
                             const PatchChartOptions& options = {});

//! 3D position of a surface point.
Vec3 surface_position(const TriMesh& mesh, const GeometryCache& geometry,
                      const SurfacePoint& point);

}  // namespace qs
