// Discretizing a layout onto a working mesh (docs/design.md, "Discretizing a layout"): nodes at
// any surface point become vertices, arcs become edge paths routed through vertices and edge
// midpoints, and the mesh is split where arcs need room. The input surface never changes.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/working_mesh.h"

namespace qs {

struct EmbedOptions {
  WorkingMeshOptions mesh;
  //! Corridor half-width of arcs given by `points`, in mean edge lengths of the input mesh.
  double corridor = 2.0;
  //! Arcs between two nodes pass through every one of their `points`: each point gets a vertex
  //! (insert_point; a free vertex within the snap distance is reused) and consecutive vertices
  //! (the nodes first and last) are joined by the straight path between them (route_straight),
  //! else by a route guided along their segment (route_arc); a point that cannot be joined is
  //! skipped. For dense polylines that must be followed closely (transfers). False: each arc is
  //! one route guided by its points.
  bool through_points = false;
};

//! \throw InvalidInputError naming the option when a value is out of range or not finite.
void validate_embed_options(const EmbedOptions& options);

//! Counters of one discretization.
struct EmbedStats {
  int inserted_nodes = 0;     //!< nodes placed at surface points by a new vertex
  int snapped_nodes = 0;      //!< nodes placed on an existing vertex within the snap distance
  int route_splits = 0;       //!< edges split to route arcs through their midpoints
  int separation_splits = 0;  //!< edges split to make room between arcs and nodes
  int flips = 0;              //!< edge flips inside input faces (angle repair)
  int point_vertices = 0;     //!< arc points given a vertex (boundary arcs, through_points)
  int skipped_points = 0;     //!< arc points that could not be placed or joined, skipped
  int guided_arcs = 0;        //!< through_points arcs routed as one guided route instead
  int attempts = 1;           //!< attempts (arcs without a route go first in the next one)
};

//! A layout on a working mesh: node vertices and arc paths are working-mesh indices; every
//! node also carries its exact `point` on the input surface.
struct EmbeddedLayout {
  std::shared_ptr<WorkingMesh> mesh;
  Layout layout;
  EmbedStats stats;
};

//! Discretizes \p layout, given on \p input (nodes by input `vertex` or by `point`; arcs by an
//! input edge `path`, by surface `points`, or by neither), onto a new working mesh of \p input:
//! 1. each node with a `point` gets a vertex there (WorkingMesh::insert_point; never another
//!    node's vertex; a point on the mesh boundary gets a boundary vertex, any other point an
//!    interior vertex), a node with a `vertex` keeps that input vertex;
//! 2. arcs with a `path` follow it exactly (an input edge split by a node insertion is
//!    followed through its pieces);
//! 3. arcs whose ends and `points` (at least one) all lie on the mesh boundary run along it
//!    through their points (boundary edges only), first;
//! 4. the other arcs are routed (route_arc, or through their points with
//!    EmbedOptions::through_points), guided by their `points` when given, in breadth-first
//!    order over the layout graph, each avoiding the arcs before it; when arcs find no route,
//!    the whole discretization is repeated with them first (up to 3 times);
//! 5. edges are flipped inside input faces to raise small angles (never arc edges), and the
//!    mesh is split where arcs need room (separate_layout).
//! Arc `points` are dropped from the result (the path supersedes them).
//! \throw InvalidInputError listing every problem with its node and arc ids: a node point
//! outside its face, two nodes on one vertex, a node on another arc's path, arcs that cannot be
//! routed (no route avoiding the others: a layout that is invalid as curves on the surface).
//! The result is not validated as a layout (validate_layout on mesh->mesh() does that).
EmbeddedLayout embed_layout(std::shared_ptr<const TriMesh> input, const Layout& layout,
                            const EmbedOptions& options = {});

//! The working-mesh edge path along the input edge path \p input_path (input vertex indices),
//! through the vertices that splits put on those input edges; empty when two consecutive input
//! vertices are not joined by an input edge.
std::vector<int> working_path_of_input_path(const WorkingMesh& mesh,
                                            const std::vector<int>& input_path);

}  // namespace qs
