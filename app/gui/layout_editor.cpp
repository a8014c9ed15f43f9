#include "app/gui/layout_editor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "core/base/errors.h"
#include "core/layout/path_finder.h"
#include "core/layout/routing.h"

namespace qs::app {

void clear_arc_outputs(LayoutArc& arc) {
  arc.label.clear();
  arc.polyline.clear();
  arc.samples.clear();
  arc.points.clear();
}

void clear_node_outputs(LayoutNode& node) {
  node.point.reset();  // a stale `point` would snap the node back when the file is reloaded
  node.position.reset();
  node.valence = -1;
}

namespace {

bool valid_vertex(const TriMesh& mesh, int v) {
  return v >= 0 && v < int(mesh.n_vertices());
}

double distance_to_segment(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double len2 = ab.sqrnorm();
  const double t = len2 > 0.0 ? std::clamp(OpenMesh::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
  return (p - (a + t * ab)).norm();
}

// Appends an arc (next free id) and drops the now stale patches; returns the arc's id.
int append_arc(Layout& layout, int from_id, int to_id, std::vector<int> path) {
  LayoutArc arc;
  arc.id = next_arc_id(layout);
  arc.from = from_id;
  arc.to = to_id;
  arc.path = std::move(path);
  layout.arcs.push_back(std::move(arc));
  layout.patches.clear();
  return layout.arcs.back().id;
}

}  // namespace

Vec3 surface_position(const TriMesh& mesh, const SurfacePoint& p) {
  Vec3 x(0, 0, 0);
  int k = 0;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(p.face)))
    if (k < 3) x += p.bary[k++] * mesh.point(vh);
  return x;
}

int nearest_boundary_vertex(const TriMesh& mesh, const Vec3& point,
                            const RoutingObstacles* obstacles) {
  int best = -1;
  double best_d = std::numeric_limits<double>::infinity();
  for (const auto vh : mesh.vertices()) {
    if (!mesh.is_boundary(vh)) continue;
    const int v = vh.idx();
    if (obstacles && v < int(obstacles->vertex_blocked.size()) && obstacles->vertex_blocked[v])
      continue;
    const double d = (mesh.point(vh) - point).sqrnorm();
    if (d < best_d) {
      best_d = d;
      best = v;
    }
  }
  return best;
}

std::vector<int> route_stroke(const TriMesh& mesh, int source, int target,
                              const std::vector<SurfacePoint>& stroke,
                              const RoutingObstacles& obstacles, std::string* error,
                              const StrokeOptions& options) {
  auto fail = [&](std::string why) {
    if (error) *error = std::move(why);
    return std::vector<int>();
  };
  const int nv = int(mesh.n_vertices());
  if (source < 0 || source >= nv || target >= nv) return fail("vertex out of range");
  if (stroke.size() < 2) return fail("the stroke is too short (draw across the surface)");
  // Samples in 3D (snap_to_vertex validates face index and barycentrics), and the local edge
  // length h of the faces the stroke crosses.
  std::vector<Vec3> points;
  points.reserve(stroke.size());
  double edge_sum = 0.0;
  int edge_count = 0;
  for (std::size_t k = 0; k < stroke.size(); ++k) {
    try {
      snap_to_vertex(mesh, stroke[k]);
    } catch (const InvalidInputError& e) {
      return fail("stroke sample " + std::to_string(k) + ": " + e.what());
    }
    points.push_back(surface_position(mesh, stroke[k]));
    if (k == 0 || stroke[k].face != stroke[k - 1].face) {
      for (const auto eh : mesh.fe_range(OpenMesh::FaceHandle(stroke[k].face))) {
        edge_sum += mesh.calc_edge_length(eh);
        ++edge_count;
      }
    }
  }
  const double h = edge_count > 0 ? edge_sum / edge_count : 0.0;
  if (!(h > 0.0) || !std::isfinite(h)) return fail("the stroke crosses only degenerate faces");

  if (target < 0) {
    target = nearest_boundary_vertex(mesh, points.back(), &obstacles);
    if (target < 0) {
      const bool closed = nearest_boundary_vertex(mesh, points.back()) < 0;
      return fail(closed ? "the mesh has no boundary to end a dangling arc on"
                         : "every boundary vertex is already used by an arc or node");
    }
  }
  if (target == source) return fail("the stroke starts and ends at the same vertex");

  // Distance of every vertex to the stroke polyline; vertices outside the stroke's bounding
  // box inflated by the corridor width get the box distance (a lower bound, enough there).
  const double corridor = options.corridor_edges * h;
  Vec3 lo = points[0], hi = points[0];
  for (const Vec3& p : points) {
    lo.minimize(p);
    hi.maximize(p);
  }
  lo -= Vec3(corridor, corridor, corridor);
  hi += Vec3(corridor, corridor, corridor);
  std::vector<double> distance(nv, std::numeric_limits<double>::infinity());
  for (int v = 0; v < nv; ++v) {
    const Vec3& x = mesh.point(OpenMesh::VertexHandle(v));
    bool inside = true;
    for (int c = 0; c < 3; ++c) inside = inside && x[c] >= lo[c] && x[c] <= hi[c];
    if (!inside) continue;
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k + 1 < points.size(); ++k)
      d = std::min(d, distance_to_segment(x, points[k], points[k + 1]));
    distance[v] = d;
  }
  std::vector<double> cost(nv);
  std::vector<char> allowed(nv, 0);
  const double cap = 4.0 * options.corridor_edges;  // cost of vertices far from the stroke
  for (int v = 0; v < nv; ++v) {
    const double r = std::min(distance[v] / h, cap);
    cost[v] = 1.0 + options.deviation_weight * r * r;
    allowed[v] = distance[v] <= corridor;
  }
  allowed[source] = 1;
  PathFinder finder(mesh);
  std::vector<int> path = finder.find(source, target, obstacles, &allowed, &cost);
  // Other arcs may close the corridor: then any free route, still drawn towards the stroke.
  if (path.empty()) path = finder.find(source, target, obstacles, nullptr, &cost);
  if (path.size() < 2)
    return fail("no free path along the stroke from vertex " + std::to_string(source) +
                " to vertex " + std::to_string(target) + " (other arcs are in the way)");
  return path;
}

int next_node_id(const Layout& layout) {
  int id = 0;
  for (const auto& n : layout.nodes) id = std::max(id, n.id + 1);
  return id;
}

int next_arc_id(const Layout& layout) {
  int id = 0;
  for (const auto& a : layout.arcs) id = std::max(id, a.id + 1);
  return id;
}

int node_at_vertex(const Layout& layout, int vertex) {
  for (const auto& n : layout.nodes)
    if (n.vertex == vertex) return n.id;
  return -1;
}

int arc_through_vertex(const Layout& layout, int vertex) {
  for (const auto& a : layout.arcs)
    for (std::size_t i = 1; i + 1 < a.path.size(); ++i)
      if (a.path[i] == vertex) return a.id;
  // A dangling arc's boundary end is not a node either.
  for (const auto& a : layout.arcs)
    if (a.dangling() && !a.path.empty() && a.path.back() == vertex) return a.id;
  return -1;
}

int node_valence(const Layout& layout, int node_id) {
  int valence = 0;
  for (const auto& a : layout.arcs) valence += (a.from == node_id) + (a.to == node_id);
  return valence;
}

void LayoutEditor::reset(const TriMesh* mesh, Layout layout) {
  mesh_ = mesh;
  history_.clear();
  cursor_ = 0;
  drag_node_ = -1;
  set_layout(std::move(layout));
}

void LayoutEditor::set_layout(Layout layout) {
  layout_ = std::move(layout);
  ++version_;
}

void LayoutEditor::commit(std::string label, Layout before) {
  history_.resize(cursor_);  // a new edit drops the redo branch
  history_.push_back({std::move(label), std::move(before), layout_});
  // Inside a group the steps are merged at its end: no trimming (indices stay) and one call.
  if (group_depth_ == 0 && history_.size() > max_history) history_.erase(history_.begin());
  cursor_ = history_.size();
  ++version_;
  if (group_depth_ == 0 && on_change) on_change(layout_);
}

EditResult LayoutEditor::edit(const std::string& label,
                              const std::function<std::string(Layout&)>& change) {
  if (auto r = check_mesh(); !r) return r;
  Layout changed = layout_;
  std::string error;
  try {
    error = change(changed);
  } catch (const std::exception& e) {
    error = e.what();
  }
  if (!error.empty()) return EditResult::fail(error);
  changed.patches.clear();
  Layout before = std::move(layout_);
  layout_ = std::move(changed);
  commit(label, std::move(before));
  return {};
}

EditResult LayoutEditor::group(const std::string& label, const std::function<EditResult()>& edits) {
  if (group_depth_ > 0) return edits();
  if (auto r = check_mesh(); !r) return r;
  const std::size_t cursor = cursor_;
  Layout before = layout_;
  // The redo branch the first edit drops, for a group that fails.
  std::vector<Step> redo(history_.begin() + static_cast<long>(cursor_), history_.end());
  ++group_depth_;
  EditResult result;
  try {
    result = edits();
  } catch (const std::exception& e) {
    result = EditResult::fail(e.what());
  }
  --group_depth_;
  if (!result.ok) {
    if (cursor_ != cursor) {
      history_.resize(cursor);
      history_.insert(history_.end(), std::make_move_iterator(redo.begin()),
                      std::make_move_iterator(redo.end()));
      cursor_ = cursor;
      set_layout(std::move(before));
    }
    return result;
  }
  if (cursor_ == cursor) return result;  // nothing changed
  history_.resize(cursor);
  history_.push_back({label, std::move(before), layout_});
  if (history_.size() > max_history) history_.erase(history_.begin());
  cursor_ = history_.size();
  ++version_;
  if (on_change) on_change(layout_);
  return result;
}

EditResult LayoutEditor::check_mesh() const {
  if (!mesh_) return EditResult::fail("no mesh loaded");
  if (dragging()) return EditResult::fail("finish the drag first");
  return {};
}

bool LayoutEditor::reroute_arcs_of(Layout& layout, int node_id, std::string* error) const {
  // Remove the node's arcs, then route them back one by one so that each new path avoids
  // all other arcs and the ones already re-routed.
  std::vector<LayoutArc> moved;
  std::erase_if(layout.arcs, [&](const LayoutArc& a) {
    if (a.from != node_id && a.to != node_id) return false;
    moved.push_back(a);
    return true;
  });
  for (auto& arc : moved) {
    const int from = layout.node_index(arc.from);
    const int to = arc.dangling() ? -1 : layout.node_index(arc.to);
    if (from < 0 || (!arc.dangling() && to < 0)) {
      if (error) *error = "arc " + std::to_string(arc.id) + " has a missing end node";
      return false;
    }
    const RoutingObstacles obstacles = obstacles_of_layout(*mesh_, layout);
    const int source = layout.nodes[from].vertex;
    std::vector<int> path = arc.dangling()
                                ? shortest_path_to_boundary(*mesh_, source, obstacles)
                                : shortest_path(*mesh_, source, layout.nodes[to].vertex, obstacles);
    if (path.size() < 2) {
      if (error) *error = "arc " + std::to_string(arc.id) + " cannot be routed (no free path)";
      return false;
    }
    arc.path = std::move(path);
    clear_arc_outputs(arc);
    layout.arcs.push_back(std::move(arc));
  }
  // Keep the file order stable (sorted by id) so that saved layouts diff nicely.
  std::sort(layout.arcs.begin(), layout.arcs.end(),
            [](const LayoutArc& a, const LayoutArc& b) { return a.id < b.id; });
  return true;
}

EditResult LayoutEditor::add_node(int vertex) {
  if (auto r = check_mesh(); !r) return r;
  if (!valid_vertex(*mesh_, vertex)) return EditResult::fail("vertex out of range");
  if (int id = node_at_vertex(layout_, vertex); id >= 0)
    return EditResult::fail("vertex " + std::to_string(vertex) + " already holds node " +
                            std::to_string(id));
  if (int arc = arc_through_vertex(layout_, vertex); arc >= 0)
    return EditResult::fail("vertex " + std::to_string(vertex) + " lies on arc " +
                            std::to_string(arc) + " (split the arc instead)");
  Layout before = layout_;
  LayoutNode node;
  node.id = next_node_id(layout_);
  node.vertex = vertex;
  layout_.nodes.push_back(node);
  layout_.patches.clear();
  commit("add node " + std::to_string(node.id), std::move(before));
  return {true, {}, node.id, -1};
}

EditResult LayoutEditor::add_arc(int from_id, int to_id) {
  if (auto r = check_mesh(); !r) return r;
  const int from = layout_.node_index(from_id);
  const int to = layout_.node_index(to_id);
  if (from < 0 || to < 0) return EditResult::fail("unknown node");
  if (from_id == to_id) return EditResult::fail("an arc needs two different nodes");
  const RoutingObstacles obstacles = obstacles_of_layout(*mesh_, layout_);
  std::vector<int> path =
      shortest_path(*mesh_, layout_.nodes[from].vertex, layout_.nodes[to].vertex, obstacles);
  if (path.size() < 2)
    return EditResult::fail("no free path from node " + std::to_string(from_id) + " to node " +
                            std::to_string(to_id) + " (other arcs are in the way)");
  Layout before = layout_;
  const int id = append_arc(layout_, from_id, to_id, std::move(path));
  commit("add arc " + std::to_string(id), std::move(before));
  return {true, {}, id, -1};
}

EditResult LayoutEditor::add_stroke_arc(int from_id, int to_id,
                                        const std::vector<SurfacePoint>& stroke,
                                        const StrokeOptions& options) {
  if (auto r = check_mesh(); !r) return r;
  const int from = layout_.node_index(from_id);
  if (from < 0) return EditResult::fail("the stroke must start at a node");
  if (stroke.size() < 2) return EditResult::fail("the stroke is too short");
  if (to_id >= 0 && layout_.node_index(to_id) < 0)
    return EditResult::fail("unknown node " + std::to_string(to_id));
  if (to_id < 0) {
    // End at the vertex nearest to the last sample: an existing node there, else a new one.
    int end_vertex = -1;
    try {
      end_vertex = snap_to_vertex(*mesh_, stroke.back());
    } catch (const InvalidInputError& e) {
      return EditResult::fail(std::string("the stroke's last sample is invalid: ") + e.what());
    }
    to_id = node_at_vertex(layout_, end_vertex);
    if (to_id < 0) {
      if (int arc = arc_through_vertex(layout_, end_vertex); arc >= 0)
        return EditResult::fail("the stroke ends on arc " + std::to_string(arc) +
                                " (end it at a node, or split the arc first)");
      Layout before = layout_;
      LayoutNode node;
      node.id = next_node_id(layout_);
      node.vertex = end_vertex;
      Layout edited = layout_;
      edited.nodes.push_back(node);
      std::string error;
      const RoutingObstacles obstacles = obstacles_of_layout(*mesh_, edited);
      std::vector<int> path = route_stroke(*mesh_, layout_.nodes[from].vertex, end_vertex, stroke,
                                           obstacles, &error, options);
      if (path.empty()) return EditResult::fail(error);
      const int id = append_arc(edited, from_id, node.id, std::move(path));
      layout_ = std::move(edited);
      commit("stroke arc " + std::to_string(id) + " to new node " + std::to_string(node.id),
             std::move(before));
      return {true, {}, id, node.id};
    }
  }
  if (to_id == from_id) return EditResult::fail("the stroke starts and ends at the same node");
  const int to = layout_.node_index(to_id);
  std::string error;
  const RoutingObstacles obstacles = obstacles_of_layout(*mesh_, layout_);
  std::vector<int> path = route_stroke(*mesh_, layout_.nodes[from].vertex, layout_.nodes[to].vertex,
                                       stroke, obstacles, &error, options);
  if (path.empty()) return EditResult::fail(error);
  Layout before = layout_;
  const int id = append_arc(layout_, from_id, to_id, std::move(path));
  commit("stroke arc " + std::to_string(id), std::move(before));
  return {true, {}, id, -1};
}

EditResult LayoutEditor::add_dangling_arc(int from_id, int boundary_vertex) {
  if (auto r = check_mesh(); !r) return r;
  const int from = layout_.node_index(from_id);
  if (from < 0) return EditResult::fail("unknown node " + std::to_string(from_id));
  const int source = layout_.nodes[from].vertex;
  if (!valid_vertex(*mesh_, source))
    return EditResult::fail("node " + std::to_string(from_id) + " has no valid vertex");
  if (nearest_boundary_vertex(*mesh_, Vec3(0, 0, 0)) < 0)
    return EditResult::fail("the mesh has no boundary: dangling arcs end on the boundary");
  const RoutingObstacles obstacles = obstacles_of_layout(*mesh_, layout_);
  std::vector<int> path;
  if (boundary_vertex < 0) {
    path = shortest_path_to_boundary(*mesh_, source, obstacles);
    if (path.size() < 2)
      return EditResult::fail("no free path from node " + std::to_string(from_id) +
                              " to the boundary (other arcs are in the way)");
  } else {
    if (!valid_vertex(*mesh_, boundary_vertex)) return EditResult::fail("vertex out of range");
    if (!mesh_->is_boundary(OpenMesh::VertexHandle(boundary_vertex)))
      return EditResult::fail("vertex " + std::to_string(boundary_vertex) +
                              " is not on the mesh boundary");
    if (boundary_vertex == source)
      return EditResult::fail("node " + std::to_string(from_id) +
                              " already sits on the boundary at that vertex");
    if (obstacles.vertex_blocked[boundary_vertex])
      return EditResult::fail("boundary vertex " + std::to_string(boundary_vertex) +
                              " is already used by an arc or node");
    path = shortest_path(*mesh_, source, boundary_vertex, obstacles);
    if (path.size() < 2)
      return EditResult::fail("no free path from node " + std::to_string(from_id) +
                              " to boundary vertex " + std::to_string(boundary_vertex));
  }
  Layout before = layout_;
  const int id = append_arc(layout_, from_id, -1, std::move(path));
  commit("dangling arc " + std::to_string(id), std::move(before));
  return {true, {}, id, -1};
}

EditResult LayoutEditor::delete_node(int id) {
  if (auto r = check_mesh(); !r) return r;
  const int index = layout_.node_index(id);
  if (index < 0) return EditResult::fail("unknown node " + std::to_string(id));
  Layout before = layout_;
  layout_.nodes.erase(layout_.nodes.begin() + index);
  std::erase_if(layout_.arcs, [&](const LayoutArc& a) { return a.from == id || a.to == id; });
  layout_.patches.clear();
  commit("delete node " + std::to_string(id), std::move(before));
  return {};
}

EditResult LayoutEditor::delete_arc(int id) {
  if (auto r = check_mesh(); !r) return r;
  const int index = layout_.arc_index(id);
  if (index < 0) return EditResult::fail("unknown arc " + std::to_string(id));
  Layout before = layout_;
  layout_.arcs.erase(layout_.arcs.begin() + index);
  layout_.patches.clear();
  commit("delete arc " + std::to_string(id), std::move(before));
  return {};
}

EditResult LayoutEditor::move_node(int id, int vertex) {
  if (auto r = check_mesh(); !r) return r;
  const int index = layout_.node_index(id);
  if (index < 0) return EditResult::fail("unknown node " + std::to_string(id));
  if (!valid_vertex(*mesh_, vertex)) return EditResult::fail("vertex out of range");
  if (layout_.nodes[index].vertex == vertex) return EditResult::fail("the node is already there");
  const int other = node_at_vertex(layout_, vertex);
  if (other >= 0) return EditResult::fail("vertex holds node " + std::to_string(other));
  Layout moved = layout_;
  {  // the node's own arcs may pass through the new vertex: they are re-routed anyway
    Layout without_own = layout_;
    std::erase_if(without_own.arcs, [&](const LayoutArc& a) { return a.from == id || a.to == id; });
    if (int arc = arc_through_vertex(without_own, vertex); arc >= 0)
      return EditResult::fail("vertex lies on arc " + std::to_string(arc));
  }
  moved.nodes[index].vertex = vertex;
  clear_node_outputs(moved.nodes[index]);
  std::string error;
  if (!reroute_arcs_of(moved, id, &error)) return EditResult::fail(error);
  moved.patches.clear();
  Layout before = std::move(layout_);
  layout_ = std::move(moved);
  commit("move node " + std::to_string(id), std::move(before));
  return {};
}

EditResult LayoutEditor::split_arc(int arc_id, int vertex) {
  if (auto r = check_mesh(); !r) return r;
  const int index = layout_.arc_index(arc_id);
  if (index < 0) return EditResult::fail("unknown arc " + std::to_string(arc_id));
  const auto& path = layout_.arcs[index].path;
  const auto it = std::find(path.begin(), path.end(), vertex);
  if (it == path.end() || it == path.begin() || it + 1 == path.end())
    return EditResult::fail("split needs an interior vertex of arc " + std::to_string(arc_id));
  const std::size_t k = static_cast<std::size_t>(it - path.begin());

  Layout before = layout_;
  LayoutNode node;
  node.id = next_node_id(layout_);
  node.vertex = vertex;
  LayoutArc second = layout_.arcs[index];
  second.id = next_arc_id(layout_);
  second.from = node.id;
  second.path.assign(path.begin() + static_cast<long>(k), path.end());
  clear_arc_outputs(second);
  LayoutArc& first = layout_.arcs[index];
  first.to = node.id;
  first.path.resize(k + 1);
  clear_arc_outputs(first);
  layout_.nodes.push_back(node);
  layout_.arcs.push_back(std::move(second));
  layout_.patches.clear();
  commit("split arc " + std::to_string(arc_id), std::move(before));
  return {true, {}, node.id, -1};
}

EditResult LayoutEditor::toggle_node_pin(int id) {
  if (auto r = check_mesh(); !r) return r;
  const int index = layout_.node_index(id);
  if (index < 0) return EditResult::fail("unknown node " + std::to_string(id));
  Layout before = layout_;
  layout_.nodes[index].pinned = !layout_.nodes[index].pinned;
  commit(std::string(layout_.nodes[index].pinned ? "pin" : "unpin") + " node " + std::to_string(id),
         std::move(before));
  return {};
}

EditResult LayoutEditor::replace_layout(Layout layout, const std::string& label) {
  if (auto r = check_mesh(); !r) return r;
  for (auto& arc : layout.arcs) {
    arc.polyline.clear();
    arc.samples.clear();
    arc.label.clear();
  }
  for (auto& node : layout.nodes) {
    node.position.reset();
    node.valence = -1;
  }
  layout.patches.clear();
  Layout before = layout_;
  layout_ = std::move(layout);
  commit(label, std::move(before));
  return {};
}

EditResult LayoutEditor::toggle_arc_pin(int id) {
  if (auto r = check_mesh(); !r) return r;
  const int index = layout_.arc_index(id);
  if (index < 0) return EditResult::fail("unknown arc " + std::to_string(id));
  Layout before = layout_;
  layout_.arcs[index].pinned = !layout_.arcs[index].pinned;
  commit(std::string(layout_.arcs[index].pinned ? "pin" : "unpin") + " arc " + std::to_string(id),
         std::move(before));
  return {};
}

bool LayoutEditor::begin_drag(int node_id) {
  if (!mesh_ || dragging() || layout_.node_index(node_id) < 0) return false;
  drag_node_ = node_id;
  drag_before_ = layout_;
  return true;
}

EditResult LayoutEditor::drag_to(int vertex) {
  if (!dragging()) return EditResult::fail("not dragging");
  const int index = layout_.node_index(drag_node_);
  if (index < 0 || !valid_vertex(*mesh_, vertex)) return EditResult::fail("vertex out of range");
  if (layout_.nodes[index].vertex == vertex) return {};
  if (node_at_vertex(layout_, vertex) >= 0) return EditResult::fail("vertex holds a node");
  // Route from the pre-drag layout each time, so that the preview does not drift with the
  // order in which intermediate positions were visited.
  Layout moved = drag_before_;
  {
    Layout without_own = drag_before_;
    std::erase_if(without_own.arcs,
                  [&](const LayoutArc& a) { return a.from == drag_node_ || a.to == drag_node_; });
    if (arc_through_vertex(without_own, vertex) >= 0)
      return EditResult::fail("vertex lies on another arc");
  }
  const int moved_index = moved.node_index(drag_node_);
  moved.nodes[moved_index].vertex = vertex;
  clear_node_outputs(moved.nodes[moved_index]);
  std::string error;
  if (!reroute_arcs_of(moved, drag_node_, &error)) return EditResult::fail(error);
  if (drag_follow) {
    try {
      error = drag_follow(drag_before_, moved, drag_node_);
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (!error.empty()) return EditResult::fail(error);
  }
  moved.patches.clear();
  set_layout(std::move(moved));
  return {};
}

void LayoutEditor::end_drag() {
  if (!dragging()) return;
  const int id = drag_node_;
  drag_node_ = -1;
  const int before_index = drag_before_.node_index(id);
  const int after_index = layout_.node_index(id);
  if (before_index >= 0 && after_index >= 0 &&
      drag_before_.nodes[before_index].vertex == layout_.nodes[after_index].vertex)
    return;  // a click without movement is not an edit
  commit("move node " + std::to_string(id), std::move(drag_before_));
}

void LayoutEditor::cancel_drag() {
  if (!dragging()) return;
  drag_node_ = -1;
  set_layout(std::move(drag_before_));
}

bool LayoutEditor::undo() {
  if (!can_undo() || dragging()) return false;
  --cursor_;
  set_layout(history_[cursor_].before);
  if (on_change) on_change(layout_);
  return true;
}

bool LayoutEditor::redo() {
  if (!can_redo() || dragging()) return false;
  set_layout(history_[cursor_].after);
  ++cursor_;
  if (on_change) on_change(layout_);
  return true;
}

std::string LayoutEditor::undo_label() const {
  return can_undo() ? history_[cursor_ - 1].label : std::string();
}

std::string LayoutEditor::redo_label() const {
  return can_redo() ? history_[cursor_].label : std::string();
}

}  // namespace qs::app
