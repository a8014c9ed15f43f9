// Block-structured quad mesh of a traced quad layout (paper §8; docs/design.md, "Quad mesh"):
// an m×n grid per patch, with counts that agree along every poly-chord, arcs sampled once and
// shared (watertight), interior points located in the patch charts. Plus the exports:
// quads.obj, patches.json and layout_curves.obj.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/extract/patches.h"
#include "core/extract/tracing.h"
#include "core/extract/uv_atlas.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"

namespace qs {

struct QuadMeshOptions {
  //! Target quad edge length q in parameter units (≈ surface length units for an isometric
  //! parameterization). Used when > 0.
  double quad_size = 0;
  //! Otherwise: choose q so that the mesh has about this many quads (> 0).
  int quad_count = 0;
  PatchChartOptions chart;
};

//! One gridded patch.
struct QuadPatch {
  int patch = -1;                     //!< index in LayoutTopology::patches (= output patch id)
  bool ok = false;                    //!< gridded; false: skipped (see failure)
  std::string failure;                //!< why it was skipped
  std::array<int, 4> nodes{};         //!< corner node indices (LayoutTopology::Patch::corners)
  std::array<int, 4> darts{};         //!< border half-arcs; side k is arc darts[k] >> 1
  std::array<double, 2> size{};       //!< (w, h), parameter units
  std::array<int, 2> grid{};          //!< (m, n): quads along sides 0/2 and 1/3
  int first_quad = 0, num_quads = 0;  //!< range in QuadMesh::quads
  //! Grid vertex (i, j), 0 ≤ i ≤ m, 0 ≤ j ≤ n, at grid_vertices[j·(m+1) + i]: index into
  //! QuadMesh::vertices. (0,0) is corner 0, (m,0) corner 1, (m,n) corner 2, (0,n) corner 3.
  std::vector<int> grid_vertices;
};

struct QuadMesh {
  double quad_size = 0;                         //!< q actually used
  std::vector<std::array<double, 3>> vertices;  //!< 3D positions, on the surface
  //! Quads, counter-clockwise seen from the side the surface normal points to. Indices into
  //! `vertices`. Quads of one patch are contiguous (QuadPatch::first_quad, num_quads).
  std::vector<std::array<int, 4>> quads;
  std::vector<int> quad_patch;     //!< per quad: index into `patches`
  std::vector<QuadPatch> patches;  //!< one per LayoutTopology patch (skipped ones with ok=false)
  //! Per arc: number of grid segments along it (its poly-chord's count), 0 when the arc is not
  //! on the border of any gridded patch.
  std::vector<int> arc_segments;
  //! Per arc: its shared vertices (from node to to node, arc_segments + 1 of them; empty when
  //! arc_segments is 0). Indices into `vertices`.
  std::vector<std::vector<int>> arc_vertices;
  std::vector<int> node_vertex;       //!< per node: index into `vertices`, or -1
  std::vector<std::string> warnings;  //!< skipped patches, poor point location, ...
  int gridded_patches() const;
};

//! q for about \p quad_count quads (Σ m·n closest to it, ties to the larger q).
//! \pre quad_count > 0. \throw InvalidInputError when no patch can be gridded.
double quad_size_for_count(const LayoutTopology& topology, const Extraction& extraction,
                           int quad_count);

//! Number of quads Σ m·n for quad size \p quad_size over the gridded (quad) patches whose
//! border arcs traced.
long count_quads(const LayoutTopology& topology, const Extraction& extraction, double quad_size);

//! Builds the quad mesh. Patches that are not 4-sided disks, are trimmed, touch a failed arc
//! or whose chart fails are skipped (with a warning); the mesh is then open there.
//! \p period_jump: per edge (CrossField::period_jump); \p corner_uv: Parameterization::corner_uv.
//! \throw InvalidInputError when neither quad_size > 0 nor quad_count > 0.
QuadMesh build_quad_mesh(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                         const LayoutTopology& topology, const Extraction& extraction,
                         const std::vector<int>& period_jump,
                         const std::vector<std::array<double, 2>>& corner_uv,
                         const QuadMeshOptions& options);

//! quads.obj: "v" per vertex, per-corner "vt" with the patch coordinates (s, t) ∈ [0,w]×[0,h]
//! mapped to the patch's rectangle of uv_atlas over the gridded patches' sizes (kPerPatch:
//! (s/w, t/h), every patch on [0,1]²; kPacked: non-overlapping rectangles), one
//! "g patch_<id>" group per gridded patch, "f v/vt" quads. Atomic.
//! \throw InvalidInputError for invalid \p atlas options.
void write_quads_obj(const QuadMesh& quads, const std::string& path,
                     const UvAtlasOptions& atlas = {});

//! patches.json: per gridded patch its id, corner node ids, arc ids (sides 0..3), (w, h),
//! (m, n), quad range and the 4 boundary curves as 3D polylines (side k from corner k to corner
//! k+1, the traced arcs); skipped patches with their reason. Atomic.
void write_patches_json(const QuadMesh& quads, const Layout& layout, const Extraction& extraction,
                        const std::string& path);

//! layout_curves.obj: one object "layout_curves"; first one "v" per node (in layout order, at
//! the start of an arc from it or the end of a traced arc to it; nodes on no arc are left out),
//! then the inner points of every arc's traced polyline. Per arc with at least 2 points a group
//! "g arc_<id>" of 2-vertex line records "l a b", one per polyline segment from its `from` node
//! to its `to` node, the end vertices being the node vertices (shared by all arcs at that node;
//! a failed or dangling arc ends on a vertex of its own). Last, the node vertices as one
//! "p" record in group "nodes". Atomic.
void write_layout_curves_obj(const Layout& layout, const Extraction& extraction,
                             const std::string& path);

//! Writes quads.obj (with \p atlas), patches.json and layout_curves.obj into folder \p dir.
void write_quad_exports(const QuadMesh& quads, const Layout& layout, const Extraction& extraction,
                        const std::string& dir, const UvAtlasOptions& atlas = {});

}  // namespace qs
