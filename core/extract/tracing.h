// Embedding extraction (paper §5.2; docs/design.md, "Tracing"): every arc is traced as an iso-line
// of the parameterization from its start node, across transitions, with exact vertex handling; then
// the traced base complex is compared with the input layout.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/param/cut_graph.h"
#include "core/param/labeling.h"

namespace qs {

struct TracedArc {
  bool ok = false;                              //!< reached its end node (or the boundary)
  std::string failure;                          //!< why not, when !ok
  std::vector<SurfacePoint> samples;            //!< start, every edge crossing, end
  std::vector<std::array<double, 3>> polyline;  //!< 3D positions of the samples
  std::vector<std::array<double, 2>> uv;        //!< sample (u, v) in the chart of its face
  double param_length = 0;                      //!< parametric length along the arc
  bool iso_u = false;                           //!< u constant along it
};

struct Extraction {
  std::vector<TracedArc> arcs;                    //!< per arc
  std::vector<std::array<double, 2>> patch_size;  //!< per patch of the topology: (w, h)
  int crossings = 0;  //!< pairs of traced arc segments crossing inside a face
  bool structurally_equivalent = false;
  std::vector<std::string> problems;  //!< why not equivalent
  //! Interior nodes whose parametric cone angle (sum of the corner angles of the faces around
  //! the node vertex, each in its own chart) differs from valence·90° by more than 45°: the
  //! parameterization folds or winds wrongly around the node (e.g. 90° instead of 450° at a
  //! valence-5 node, with every face positive), so arcs cannot leave it in their sectors.
  //! Listed in `problems` when the extraction is not equivalent.
  int bad_cones = 0;
};

struct TraceOptions {
  double vertex_snap = 1e-9;  //!< relative to the face's parametric size
  int max_steps_factor = 8;   //!< cap: factor · #F steps per arc
  //! Layouts with at least this many arcs trace the second half of their arcs on a second
  //! thread (the arcs are independent; same result). 0: always one thread.
  int second_thread_arcs = 256;
};

//! Traces all arcs. \p corner_uv: (u, v) per face corner (Parameterization::corner_uv).
Extraction extract_layout(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                          const LayoutTopology& topology, const Labeling& labeling,
                          const std::vector<int>& period_jump,
                          const std::vector<std::array<double, 2>>& corner_uv,
                          const TraceOptions& options = {});

//! (u, v) of a surface point lying on face \p f (inside or on its border), in f's chart.
std::array<double, 2> uv_in_face(const TriMesh& mesh, const GeometryCache& geometry,
                                 const std::vector<std::array<double, 2>>& corner_uv,
                                 const SurfacePoint& point, int f);

//! Copies the traced arcs (samples, polyline, label), node positions/points/valences and patches
//! (with sizes) into \p layout for output.
void annotate_layout(const TriMesh& mesh, const LayoutTopology& topology,
                     const Extraction& extraction, Layout& layout);

}  // namespace qs
