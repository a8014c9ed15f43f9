// Continuous node positioning by vertex relocation and re-routing of a moved node's arcs
// (paper §6.1.1; docs/design.md, "Node relocation").
#pragma once

#include <functional>
#include <vector>

#include "core/layout/layout.h"
#include "core/layout/routing.h"
#include "core/mesh/mesh.h"

namespace qs {

struct RelocationOptions {
  //! A relocation is allowed only if every face normal of the moved (and restored) vertices'
  //! 1-rings keeps a cosine of at least this with its normal on the original mesh.
  double min_normal_cos = 0.2;
  //! Faces of those 1-rings must keep at least this fraction of their original area.
  double min_area_ratio = 0.05;
  //! Arc re-routing splices the new first part into the old path this many edges (2..max)
  //! down from the old node vertex; the attempts go from 2 upwards until one validates.
  int max_splice_edges = 5;
  //! Hysteresis: keep the node on its current vertex whenever that vertex is a corner of the
  //! target face and may be relocated there (the paper's rule, false, always takes the nearest).
  bool prefer_node_vertex = false;
  //! Re-routing checks the result with the full validate_layout + build_topology (O(#F) work
  //! several times per node switch) instead of the equivalent local test (rotation at the
  //! affected nodes + patch count). For tests that compare both.
  bool full_validation = false;
};

//! Data that stays valid while a layout's nodes move (re-routing keeps the structure): lets
//! move_node_and_reroute skip recomputing it per call.
struct RerouteContext {
  int patches = -1;  //!< patch count of the layout (every accepted move keeps it)
  //! The mesh is a closed, connected genus-0 surface: a connected layout graph then has
  //! one (disk) patch per face cycle of its rotation system, so an unchanged rotation system
  //! implies an unchanged patch count and the flood fill is skipped.
  bool sphere = false;
};

//! Fills a RerouteContext for a valid layout on \p mesh.
RerouteContext make_reroute_context(const TriMesh& mesh, const Layout& layout);

//! The curves on which nodes slide (paper §6.1.1: "if h lies on a feature curve, we first
//! project d(h) onto it and restrict the tracing to this curve"): the layout's feature edges,
//! sharp edges and the mesh boundary.
struct CurveNetwork {
  //! Per vertex (size #V): the vertices joined to it by a curve edge.
  std::vector<std::vector<int>> neighbours;
  //! Per vertex (size #V): a node here slides along the curve. True when the vertex has exactly
  //! two curve neighbours and the curve turns there by at most the corner angle (a node on a
  //! curve's end, a junction or a corner stays).
  std::vector<char> slides;
  bool empty() const { return neighbours.empty(); }
};

//! The curve network of \p layout on \p mesh (original positions); \p corner_deg: the largest
//! turn of a curve at a vertex on which a node still slides (degrees). \p sharp, when given
//! (per edge, size #E), marks further feature edges (the sharp edges the cross field aligns to).
CurveNetwork make_curve_network(const TriMesh& mesh, const Layout& layout, double corner_deg,
                                const std::vector<char>* sharp = nullptr);

//! Routing state of a layout whose nodes move one at a time (a node optimization trial), kept up
//! to date by move_node_and_reroute: saves rebuilding the obstacles (O(#F), with an edge look-up
//! per arc edge) for every moved node and every splice attempt.
struct LayoutObstacles {
  RoutingObstacles routing;  //!< obstacles_of_layout of the current layout
  //! Vertices never relocated for a node (size #V): boundary vertices, vertices of feature
  //! edges, and every vertex of the curve network given to make_layout_obstacles.
  std::vector<char> fixed;
};

//! The obstacles of \p layout on \p mesh (routing: as obstacles_of_layout); \p curves, when
//! given, adds its vertices to `fixed`.
LayoutObstacles make_layout_obstacles(const TriMesh& mesh, const Layout& layout,
                                      const CurveNetwork* curves = nullptr);

//! Number of patches (face components separated by arc edges and the mesh boundary).
//! \pre every arc path is an edge chain of \p mesh.
int count_patches(const TriMesh& mesh, const Layout& layout);

//! True when moving \p vertex of \p mesh to \p target (after first restoring \p restored to
//! its position in \p original, when restored ≥ 0) keeps every incident face normal within
//! RelocationOptions::min_normal_cos of its normal in \p original and every such face's area
//! above min_area_ratio of the original area.
//! \pre mesh and original have the same connectivity.
bool relocation_keeps_orientation(const TriMesh& mesh, const TriMesh& original, int restored,
                                  int vertex, const Vec3& target,
                                  const RelocationOptions& options = {});

//! Chooses the vertex of face \p target_point.face (a face of \p original) to carry a node
//! moved to \p target (3D): among its corners that are \p node_vertex or not \p forbidden, the
//! one nearest to \p target (original positions) whose relocation keeps the orientation (the
//! node's old vertex \p node_vertex restored first when a different vertex is chosen).
//! Returns -1 when no corner qualifies.
//! \pre forbidden has size #V.
int choose_relocation_vertex(const TriMesh& mesh, const TriMesh& original,
                             const SurfacePoint& target_point, const Vec3& target, int node_vertex,
                             const std::vector<char>& forbidden,
                             const RelocationOptions& options = {});
//! The same with \p forbidden asked only for the face's corners (relocation_forbidden).
int choose_relocation_vertex(const TriMesh& mesh, const TriMesh& original,
                             const SurfacePoint& target_point, const Vec3& target, int node_vertex,
                             const std::function<bool(int)>& forbidden,
                             const RelocationOptions& options = {});

//! Vertices a moving node may not be relocated onto (size #V): other nodes' vertices, boundary
//! vertices, vertices of feature edges, and vertices of arcs not incident to node \p node_index
//! (an index into layout.nodes); with \p keep_apart also the 1-rings of the other nodes
//! (next_to_other_nodes, NodeOptOptions::Moves::keep_nodes_apart).
std::vector<char> forbidden_relocation_vertices(const TriMesh& mesh, const Layout& layout,
                                                int node_index, bool keep_apart = false);
//! Vertex \p v holds another node than \p node_index, or lies on an arc not incident to it
//! (\p obstacles: make_layout_obstacles of \p layout).
bool occupied_by_layout(const Layout& layout, int node_index, const LayoutObstacles& obstacles,
                        int v);
//! Vertices next to another node than \p node_index (size #V): the other nodes' vertices and
//! their 1-rings. A node carried to such a vertex would share a triangle (or an edge) with the
//! other node: the two patches or the arc between them would be narrower than one triangle,
//! where the parameterization cannot keep the layout's sides apart, and the orientation
//! constraints become infeasible. A node already there may stay.
std::vector<char> next_to_other_nodes(const TriMesh& mesh, const Layout& layout, int node_index);
//! One entry of forbidden_relocation_vertices for node \p node_index, vertex \p v, from
//! \p obstacles (make_layout_obstacles of \p layout) without building the #V array (a descent
//! step asks for three vertices per node): occupied, or fixed.
bool relocation_forbidden(const Layout& layout, int node_index, const LayoutObstacles& obstacles,
                          int v);

//! A node sliding along a curve to another vertex (move_node_and_reroute).
struct CurveWalk {
  std::vector<int> vertices;  //!< the curve vertices from the node's vertex to the new one
  //! The old vertex's other curve neighbour (the one the walk turns its back on), or -1.
  int behind = -1;
};

//! The walk along \p curves through \p vertices (at least two), with its `behind` vertex.
CurveWalk make_curve_walk(const CurveNetwork& curves, std::vector<int> vertices);

//! A vertex that may carry a node sliding along a curve segment, and where to.
struct CurveCarrier {
  int vertex = -1;        //!< the carrying vertex (an end of the segment)
  double fraction = 0.0;  //!< its new position: this fraction of the segment from its end a
};

//! The vertices that may carry a node which slid to fraction \p s ∈ [0, 1] of the curve segment
//! (\p a, \p b), in the order to try them: the nearer end first, carrying the node to the point
//! itself, then the farther end, carrying it at most to the segment's middle (relocated further
//! along the curve, it would squeeze its faces on the other side). An end other than
//! \p node_vertex is left out when \p may_take is false for it; an end that does not slide
//! (\p slides, size #V: a curve end, junction or corner) only carries the node at its own place
//! (s = 0 for a, s = 1 for b). Whether a relocation keeps the orientation is left to the caller.
std::vector<CurveCarrier> curve_carriers(int a, int b, double s, int node_vertex,
                                         const std::vector<char>& slides,
                                         const std::function<bool(int)>& may_take);

//! Moves node \p node_index of \p layout to \p new_vertex and re-routes its incident arcs: each
//! arc keeps its old path from k edges after the node on (k = 2, 3, … max_splice_edges; the
//! whole arc when it is shorter) and gets a new shortest first part from the new vertex that
//! avoids every other arc and node. The move is kept only if the layout validates and has the
//! same structure (same patch count, same cyclic order of half-arcs around every node) as
//! before; otherwise \p layout is left unchanged and false is returned. The new vertex must not
//! hold another node or lie on an arc not incident to the node. Since the old layout is valid,
//! the same rotation system and patch count imply a valid layout (every patch stays a disk with
//! the same corners), so only the nodes whose first arc edges changed and the patch count are
//! checked (RelocationOptions::full_validation re-validates everything). \p context, when
//! given, supplies the patch count. \p obstacles, when given, must hold
//! make_layout_obstacles(mesh, layout); it is updated when the move is kept.
//! \p curve_walk, when given, is a node sliding along a curve (its vertices run from the node's
//! vertex to \p new_vertex). An arc that follows the walk keeps its path from \p new_vertex on, an
//! arc that leaves the node towards `behind` gets the walk prepended (both stay on the curve); the
//! node's other arcs are re-routed as above.
//! \pre layout is valid on \p mesh (connectivity only; positions give the routing metric).
bool move_node_and_reroute(const TriMesh& mesh, Layout& layout, int node_index, int new_vertex,
                           const RelocationOptions& options = {},
                           const RerouteContext* context = nullptr,
                           LayoutObstacles* obstacles = nullptr,
                           const CurveWalk* curve_walk = nullptr);

//! Same patch count and the same cyclic order of half-arcs around every node.
bool same_layout_structure(const LayoutTopology& a, const LayoutTopology& b);

}  // namespace qs
