// Sketching edits on a layout with undo/redo. GL-free so that tests can drive it directly.
//
// Every edit either succeeds completely (one undo step) or leaves the layout untouched and
// returns an error message for the status line. Undo steps store whole layouts: layouts are
// small next to the mesh, and whole copies make "undo restores exactly" trivially true.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/layout/routing.h"
#include "core/mesh/mesh.h"

namespace qs::app {

struct EditResult {
  bool ok = true;
  std::string error;  //!< why the edit was refused (ok == false)
  int id = -1;        //!< id of a created node/arc, when the edit creates one
  int node_id = -1;   //!< id of a node created along with an arc (stroke to a new end node)
  static EditResult fail(std::string message) { return {false, std::move(message), -1, -1}; }
  explicit operator bool() const { return ok; }
};

//! How a free-hand stroke becomes an edge path (route_stroke).
struct StrokeOptions {
  //! Vertices farther than this many local edge lengths from the stroke are used only when no
  //! path exists inside that corridor (e.g. other arcs block it).
  double corridor_edges = 4.0;
  //! Cost factor of a vertex at distance d from the stroke: 1 + weight · (d / h)², h the mean
  //! edge length of the faces the stroke crosses. Larger: the route hugs the stroke tighter.
  double deviation_weight = 8.0;
};

//! Routes a free-hand stroke onto mesh edges: the edge path from vertex \p source to vertex
//! \p target that minimizes length weighted by the distance to the stroke (StrokeOptions),
//! avoiding \p obstacles (RoutingObstacles' rules; source and target may be blocked).
//! \p stroke: surface points in drawing order (mouse samples projected onto the surface), at
//! least 2. \p target = -1 ends the path on the unblocked boundary vertex nearest to the last
//! stroke point (a dangling arc). Returns the vertex path (source first), or an empty path and
//! a reason in \p error (bad samples, no boundary, no free path, source == target).
std::vector<int> route_stroke(const TriMesh& mesh, int source, int target,
                              const std::vector<SurfacePoint>& stroke,
                              const RoutingObstacles& obstacles, std::string* error,
                              const StrokeOptions& options = {});

//! Unblocked boundary vertex nearest (Euclidean) to \p point, or -1 (closed mesh, all blocked).
int nearest_boundary_vertex(const TriMesh& mesh, const Vec3& point,
                            const RoutingObstacles* obstacles = nullptr);

//! 3D position of a surface point (\pre valid face index and barycentrics).
Vec3 surface_position(const TriMesh& mesh, const SurfacePoint& p);

//! Drops what the optimizer wrote for an arc (label, polyline, samples) and its input `points`:
//! an edited arc no longer matches them.
void clear_arc_outputs(LayoutArc& arc);
//! Drops a moved node's `point`, position and valence (a stale point would snap the node back
//! when the file is reloaded).
void clear_node_outputs(LayoutNode& node);

class LayoutEditor {
 public:
  //! Starts editing \p layout on \p mesh (which must outlive the editor's use); clears the
  //! history. \p mesh may be null (then every edit fails).
  void reset(const TriMesh* mesh, Layout layout);

  const Layout& layout() const { return layout_; }
  const TriMesh* mesh() const { return mesh_; }
  //! Increments on every change of layout() (edits, drag previews, undo, redo, reset).
  std::uint64_t version() const { return version_; }

  //! New node on a mesh vertex. Refused on a vertex that already holds a node or lies on an
  //! arc (use split_arc there).
  EditResult add_node(int vertex);
  //! New arc between two nodes, routed along the shortest free edge path (avoiding other
  //! arcs and nodes).
  EditResult add_arc(int from_id, int to_id);
  //! New arc from node \p from_id following a free-hand \p stroke (route_stroke) to node
  //! \p to_id. With \p to_id = -1 the arc ends at the vertex nearest to the stroke's last
  //! point: at the node there if there is one, else at a new node created in the same undo
  //! step (EditResult::node_id). EditResult::id is the new arc. Refused (nothing changes) for
  //! strokes with fewer than 2 samples or invalid samples, ends on another arc, or no free route.
  EditResult add_stroke_arc(int from_id, int to_id, const std::vector<SurfacePoint>& stroke,
                            const StrokeOptions& options = {});
  //! New dangling arc (LayoutArc::to = -1) from node \p from_id to the mesh boundary vertex
  //! \p boundary_vertex, or with -1 to the nearest reachable free boundary vertex; routed along
  //! the shortest free edge path. Refused on closed meshes, for vertices not on the boundary or
  //! already used by an arc or node, and when no free path exists.
  EditResult add_dangling_arc(int from_id, int boundary_vertex = -1);
  //! Deletes a node and every arc that ends at it.
  EditResult delete_node(int id);
  EditResult delete_arc(int id);
  //! Moves a node to another vertex and re-routes its arcs.
  EditResult move_node(int id, int vertex);
  //! Splits an arc with a new node at \p vertex, an interior vertex of its path. The first
  //! part keeps the arc's id; the second part gets a new id (returned in EditResult::id is
  //! the new node).
  EditResult split_arc(int arc_id, int vertex);
  EditResult toggle_node_pin(int id);
  EditResult toggle_arc_pin(int id);
  //! Applies \p change to a copy of the layout as one edit labelled \p label (edits composed
  //! elsewhere: mirror images, edge loops). \p change returns "" to commit the copy, or why it
  //! refuses (nothing changes). Patches are dropped.
  EditResult edit(const std::string& label, const std::function<std::string(Layout&)>& change);
  //! Runs \p edits (calls of this editor's edits) as one undo step labelled \p label: the steps
  //! they record are merged, and on_change runs once. When \p edits returns a failed result or
  //! throws, the layout and the history are restored and nothing is recorded. A group inside a
  //! group is part of the outer one.
  EditResult group(const std::string& label, const std::function<EditResult()>& edits);
  //! Replaces the whole layout (e.g. by the optimized one) as one undoable edit. Traced output
  //! fields (polylines, samples, labels, patches) are dropped: they describe the old solve.
  EditResult replace_layout(Layout layout, const std::string& label);

  //! Interactive drag: previews are applied to layout() without history entries; end_drag
  //! records a single undo step (or nothing if the node did not move).
  bool begin_drag(int node_id);
  EditResult drag_to(int vertex);
  void end_drag();
  void cancel_drag();
  bool dragging() const { return drag_node_ >= 0; }
  //! Called by drag_to after the dragged node moved in \p moved (the layout before the drag,
  //! \p before, with the node on its new vertex and its arcs re-routed): may change \p moved
  //! further (e.g. move the mirror node along); a message refuses the position.
  std::function<std::string(const Layout& before, Layout& moved, int node_id)> drag_follow;

  bool can_undo() const { return cursor_ > 0; }
  bool can_redo() const { return cursor_ < history_.size(); }
  bool undo();
  bool redo();
  std::string undo_label() const;
  std::string redo_label() const;
  std::size_t history_size() const { return history_.size(); }
  //! Steps that undo can take back (the position in the history).
  std::size_t undo_position() const { return cursor_; }

  //! Called after every committed change (edit, end of drag, undo, redo), e.g. for autosave.
  std::function<void(const Layout&)> on_change;

  //! Limit of the undo history (oldest steps are dropped).
  std::size_t max_history = 500;

 private:
  struct Step {
    std::string label;
    Layout before;
    Layout after;
  };
  void commit(std::string label, Layout before);
  void set_layout(Layout layout);
  EditResult check_mesh() const;
  //! Re-routes every arc of \p node_id in \p layout. Returns false (layout partly changed)
  //! when an arc cannot be routed; \p error names it.
  bool reroute_arcs_of(Layout& layout, int node_id, std::string* error) const;

  const TriMesh* mesh_ = nullptr;
  Layout layout_;
  std::uint64_t version_ = 0;
  std::vector<Step> history_;
  std::size_t cursor_ = 0;  // steps [0, cursor_) are done, [cursor_, size) can be redone
  int drag_node_ = -1;
  Layout drag_before_;
  int group_depth_ = 0;  //!< inside group(): steps are merged, on_change waits
};

//! Next free id (max + 1) among nodes or arcs.
int next_node_id(const Layout& layout);
int next_arc_id(const Layout& layout);
//! Id of the node on \p vertex, or -1.
int node_at_vertex(const Layout& layout, int vertex);
//! Id of an arc whose path passes through \p vertex as an interior vertex, or -1.
int arc_through_vertex(const Layout& layout, int vertex);
//! Arc valence per node id (dangling arcs count once at their `from` node).
int node_valence(const Layout& layout, int node_id);

}  // namespace qs::app
