// The sketch tools' edits on the layout editor (GL-free): each plain, or mirrored about a
// mirror plane (symmetric sketching: what is drawn on one side appears mirrored on the other,
// edits, deletes and pins are mirrored, nodes on the plane stay on it), and the edge-loop edits
// (core/layout/edge_loops.h). A mirrored edit and its mirror image are one undo step; when the
// mirror image cannot be made (its place is taken, no free route) the edit is refused with the
// reason and nothing changes.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "app/gui/layout_editor.h"
#include "core/layout/symmetry.h"
#include "core/mesh/closest_point.h"

namespace qs::app {

//! A mirror plane for sketching on a mesh.
struct Mirror {
  MirrorPlane plane;
  std::shared_ptr<const ClosestPointTree> tree;  //!< of the mesh being edited
  //! A vertex this close to the plane (mesh length units) is on it: its node is its own mirror.
  double on_plane = 0;
  //! A node placed this close to the plane is moved onto it (plane_vertex).
  double snap = 0;
  //! Two nodes are mirror images when the reflection of one lies this close to the other.
  double pair_distance = 0;
};

//! The mirror \p plane of \p mesh with tolerances from its mean edge length h: on the plane
//! within h/2, snapped onto it within h, paired within 1.5 h (mirror vertices of a mesh whose
//! tessellation is not symmetric are up to about an edge off).
Mirror make_mirror(const TriMesh& mesh, const MirrorPlane& plane,
                   std::shared_ptr<const ClosestPointTree> tree);

//! The id of node \p id's mirror node in \p layout: itself for a node on the plane, else the
//! node nearest to its reflection within the pair distance; -1 when there is none.
int mirror_node_id(const TriMesh& mesh, const Layout& layout, const Mirror& mirror, int id);
//! The id of arc \p id's mirror arc: among the arcs joining the mirror nodes of its ends, the
//! one nearest to its reflection (within twice the pair distance); itself for an arc that is
//! its own mirror image; -1 when there is none.
int mirror_arc_id(const TriMesh& mesh, const Layout& layout, const Mirror& mirror, int id);

// The edits. With \p mirror null they are the plain LayoutEditor edits.
EditResult sketch_add_node(LayoutEditor& editor, const Mirror* mirror, int vertex);
EditResult sketch_add_arc(LayoutEditor& editor, const Mirror* mirror, int from_id, int to_id);
EditResult sketch_add_stroke_arc(LayoutEditor& editor, const Mirror* mirror, int from_id, int to_id,
                                 const std::vector<SurfacePoint>& stroke);
EditResult sketch_add_dangling_arc(LayoutEditor& editor, const Mirror* mirror, int from_id,
                                   int boundary_vertex);
EditResult sketch_delete_node(LayoutEditor& editor, const Mirror* mirror, int id);
EditResult sketch_delete_arc(LayoutEditor& editor, const Mirror* mirror, int id);
//! A node on the plane moves to the plane vertex nearest to \p vertex.
EditResult sketch_move_node(LayoutEditor& editor, const Mirror* mirror, int id, int vertex);
EditResult sketch_split_arc(LayoutEditor& editor, const Mirror* mirror, int arc_id, int vertex);
EditResult sketch_toggle_node_pin(LayoutEditor& editor, const Mirror* mirror, int id);
EditResult sketch_toggle_arc_pin(LayoutEditor& editor, const Mirror* mirror, int id);

//! LayoutEditor::drag_follow for a mirror: the dragged node's mirror node moves to the mirror
//! vertex of its new vertex (a node on the plane stays on it), and the mirror arcs follow as
//! mirror images of the dragged node's arcs. Also used by sketch_move_node.
std::string follow_mirror(const TriMesh& mesh, const Mirror& mirror, const Layout& before,
                          Layout& moved, int node_id);

//! Inserts an edge loop through the poly-chord crossing arc \p arc_id (insert_edge_loop, routed
//! on the mesh with route_layout; the new nodes keep only their vertex) and, with a mirror, the
//! mirror loop when the mirror arc lies on another chord. EditResult::id: the first new node.
//! \p mirror_loop (optional) is set to whether a second, mirror loop was inserted (false when
//! the loop is its own mirror image). Refused with the reason (no chord, a patch that is not
//! 4-sided, an arc of one edge, a route that fails, a result that is not valid).
EditResult sketch_insert_edge_loop(LayoutEditor& editor, const Mirror* mirror, int arc_id,
                                   bool* mirror_loop = nullptr);
//! Removes the edge loop through arc \p arc_id (remove_edge_loop) and, with a mirror, the
//! mirror loop when it is another one; \p mirror_loop (optional) tells whether it was.
EditResult sketch_remove_edge_loop(LayoutEditor& editor, const Mirror* mirror, int arc_id,
                                   bool* mirror_loop = nullptr);

}  // namespace qs::app
