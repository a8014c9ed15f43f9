// Quad layout model: nodes on mesh vertices, arcs as mesh edge paths, the rotation system
// (σ, θ) on half-arcs, and patches (docs/design.md, "Layout model").
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/surface_point.h"

namespace qs {

struct LayoutNode {
  int id = -1;      //!< user id (unique, >= 0)
  int vertex = -1;  //!< mesh vertex holding the node (after snapping a point)
  bool pinned = false;
  // Optional data: an input `point` (snapped to `vertex`), and output fields of optimize.
  std::optional<SurfacePoint> point;
  std::optional<std::array<double, 3>> position;
  int valence = -1;  //!< output only; -1 when unknown
};

struct LayoutArc {
  int id = -1;
  int from = -1;  //!< node id
  int to = -1;    //!< node id, or -1 for a dangling arc that ends on the mesh boundary
  //! Vertex path along mesh edges from the `from` node's vertex to the `to` node's vertex
  //! (dangling: to a boundary vertex). Empty until routed when the input gave `points`.
  std::vector<int> path;
  bool pinned = false;
  std::vector<SurfacePoint> points;  //!< input polyline (routed onto `path` on load)
  // Output fields of optimize (section 1 of interfaces.md).
  std::string label;                            //!< "u" or "v" (empty when unknown)
  std::vector<std::array<double, 3>> polyline;  //!< traced iso-line, 3D
  std::vector<SurfacePoint> samples;            //!< traced iso-line, surface points
  bool dangling() const { return to < 0; }
};

struct LayoutPatch {
  int id = -1;
  std::vector<int> nodes;                  //!< corner node ids in order (4 for a full patch)
  std::vector<int> arcs;                   //!< arc ids along the border, in order
  std::array<double, 2> size{{0.0, 0.0}};  //!< (w, h) in parameter units; 0 when unknown
};

//! A layout as read from / written to JSON. Ids are the user's; indices below are positions
//! in `nodes` / `arcs`.
struct Layout {
  int mesh_vertices = -1;  //!< optional "mesh" block of the file (-1: absent)
  int mesh_faces = -1;
  std::vector<LayoutNode> nodes;
  std::vector<LayoutArc> arcs;
  std::vector<std::array<int, 2>> feature_edges;  //!< mesh edges as vertex pairs
  std::vector<LayoutPatch> patches;               //!< output only

  //! Position of the node / arc with this id in `nodes` / `arcs`, or -1.
  int node_index(int id) const;
  int arc_index(int id) const;
};

//! Combinatorial structure of a layout embedded in a mesh (docs/design.md, "Layout model").
//! Half-arc 2a sits at arc a's `from` node, 2a+1 at its `to` node (for a dangling arc, 2a+1
//! is the boundary end and has no node). Indices (not ids) throughout.
struct LayoutTopology {
  int num_nodes = 0;
  int num_arcs = 0;
  //! Per half-arc (size 2·#arcs): node index (-1 for a dangling end).
  std::vector<int> half_node;
  //! Per half-arc: the first mesh halfedge leaving the node (or the boundary end) along the arc.
  std::vector<OpenMesh::HalfedgeHandle> half_first;
  //! Per half-arc: the next half-arc clockwise around its node (θ). -1 when the rotation hits
  //! the exterior of a boundary node first, or for dangling ends.
  std::vector<int> theta;
  //! Per node: its half-arcs in counter-clockwise order (starting after the exterior sector for
  //! boundary nodes).
  std::vector<std::vector<int>> node_half_arcs;
  //! Per node: valence (number of half-arcs).
  std::vector<int> valence;

  struct Patch {
    //! Half-arcs along the border, patch on the left: each arc side is entered at the
    //! listed half-arc's node. Border pieces that are mesh boundary (not arcs) are omitted.
    std::vector<int> darts;
    std::vector<int> corners;  //!< node indices along the border (with multiplicity)
    bool trimmed = false;      //!< part of the border is mesh boundary not covered by arcs
    int faces = 0;             //!< number of mesh faces
    int euler = 0;             //!< Euler characteristic cut open along the border (1 for a disk)
    int border_cycles = 0;     //!< number of border cycles (1 for a disk)
  };
  std::vector<Patch> patches;
  //! Patch index per mesh face (size #F).
  std::vector<int> face_patch;

  static int sigma(int h) { return h ^ 1; }
  static int arc_of(int h) { return h >> 1; }
};

//! σ(h): the other half-arc of the same arc.
inline int sigma(int h) {
  return h ^ 1;
}

//! Per mesh edge (size #E): 1 when an arc's path runs along it. Path steps that are not mesh
//! edges are skipped.
std::vector<char> arc_edge_mask(const TriMesh& mesh, const Layout& layout);

//! Per face of \p faces (face indices of \p mesh), the layout node nearest to it in vertex rings
//! (edge hops), at most \p max_rings away; without repeats, in the order of the faces. Indices
//! into layout.nodes. Out-of-range faces are skipped. Used to name where a solve failed.
std::vector<int> nodes_near_faces(const TriMesh& mesh, const Layout& layout,
                                  const std::vector<int>& faces, int max_rings = 8);

//! "node 63 (vertex 5381), node 64 (vertex 5928)": the nodes (indices into layout.nodes) by
//! id and vertex, for messages. Empty for no nodes.
std::string describe_nodes(const Layout& layout, const std::vector<int>& nodes);

//! Builds the rotation system and patches of a layout whose paths are valid (see
//! validate_layout; call it on layouts with no errors only).
//! \pre every arc has a path of mesh edges between its end vertices; arcs are disjoint.
LayoutTopology build_topology(const TriMesh& mesh, const Layout& layout);

//! True when the two sequences are equal up to a cyclic rotation (cyclic orders of arcs).
bool same_cycle(const std::vector<int>& a, const std::vector<int>& b);

//! φ = θ∘σ. -1 when θ is undefined.
inline int phi(const LayoutTopology& topo, int h) {
  return topo.theta[sigma(h)];
}

}  // namespace qs
