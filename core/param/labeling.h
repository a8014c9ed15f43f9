// Arc strips, transitions along arcs and the consistent u/v labelling of half-arcs by
// direction symbols (paper (4)(5); docs/design.md, "Layout model" and "Node connections and
// labels").
#pragma once

#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

//! The face strip of one arc, walked along `walk` (the arc's path, or its reverse when the
//! arc's left side is the exterior): starts in face(walk[0]→walk[1]); each step is a halfedge
//! s, crossing from face(s) to face(opposite(s)) with pivot vertex from(s).
struct ArcStrip {
  std::vector<int> walk;                        //!< vertex path in walk order
  std::vector<OpenMesh::HalfedgeHandle> steps;  //!< crossings, in order
  //! Number of steps done before arriving at walk[k] (size walk.size(); arrival[0] = 0): the
  //! face current on arrival at walk[k] is face(walk[k−1]→walk[k]).
  std::vector<int> arrival;
  bool reversed = false;  //!< walk runs from the `to` end
  int rotation = 0;       //!< quarter turns of the composed transition, walk start → walk end
};

struct Labeling {
  std::vector<ArcStrip> strips;  //!< per arc
  //! Per half-arc (2a at `from`, 2a+1 at `to`): the face whose chart measures its symbol and an
  //! outgoing halfedge o at the node vertex with face(o) = that face.
  std::vector<int> chart_face;
  std::vector<OpenMesh::HalfedgeHandle> chart_halfedge;
  //! Per half-arc: direction symbol d ∈ Z4: the half-arc leaves along R^d(1,0) in its chart.
  std::vector<int> symbol;
  //! Per arc: true when u is constant along it (d odd), false when v is constant.
  std::vector<char> iso_u;
  int geometric_mismatches = 0;  //!< half-arcs whose geometric symbol differs (alignment check)
};

//! Builds strips and labels. \p theta: field angles per face (CrossField::theta), \p p: period
//! jumps. \pre the layout is valid. \throw TopologyError if the propagation is inconsistent
//! (the rotation system contradicts the period jumps) or an arc has no strip inside the surface.
Labeling label_layout(const TriMesh& mesh, const GeometryCache& geometry, const Layout& layout,
                      const LayoutTopology& topology, const std::vector<int>& p,
                      const std::vector<double>& theta);

}  // namespace qs
