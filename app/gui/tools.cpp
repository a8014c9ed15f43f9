#include "app/gui/tools.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/gui/sketch_edits.h"
#include "core/layout/routing.h"

namespace qs::app {

namespace {

constexpr float kClickSlop = 4.0f;  // pixels a click may move before it becomes a drag
constexpr float kNodePickPx = 12.0f;
constexpr float kArcPickPx = 8.0f;

struct ToolInfo {
  const char* name;
  const char* script_name;
  const char* hint;
};

const ToolInfo kTools[kToolCount] = {
    {"Select / move", "select", "Click a node or arc to select it; drag a node to move it."},
    {"Place node", "place_node", "Click the surface to place a node (on an arc: splits it)."},
    {"Draw arc", "draw_arc",
     "Click a node, then another node: the arc follows the shortest free path."},
    {"Split arc", "split", "Click an arc to split it with a new node."},
    {"Delete", "delete", "Click a node (with its arcs) or an arc to delete it."},
    {"Pin", "pin",
     "Click a node or arc to pin / unpin it (during a run: in the run, from its next step)."},
    {"Stroke arc", "stroke",
     "Press on a node and drag across the surface; release on a node, or anywhere for a new "
     "end node. The arc follows mesh edges close to the stroke."},
    {"Dangling arc", "dangling",
     "Click a node, then click near the mesh boundary: an arc from the node to the boundary "
     "(trimmed patches). Click the node twice for the nearest boundary."},
    {"Insert loop", "insert_loop",
     "Click an arc: a loop of arcs through every patch of the chord crossing it (each patch "
     "split in two, all stay 4-sided)."},
    {"Remove loop", "remove_loop",
     "Click an arc of an edge loop (through valence-4 nodes): the whole loop is removed and "
     "its patches merged."},
};

float distance_to_segment(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b) {
  const glm::vec2 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

glm::vec3 vertex_position(const TriMesh& mesh, int v) {
  const auto& p = mesh.point(OpenMesh::VertexHandle(v));
  return {float(p[0]), float(p[1]), float(p[2])};
}

// The layout on screen: the shown result's (nodes where the run moved them), else the edited
// one. Both have the same node and arc ids.
const Layout& shown_layout(const Editor& editor) {
  const Snapshot* s = editor.result();
  return s && s->layout ? *s->layout : editor.doc.editor.layout();
}

std::optional<render::SurfaceHit> pick_surface(const glm::vec2& at, const Editor& editor,
                                               const render::Camera& camera,
                                               const render::SurfacePicker& picker) {
  if (!editor.doc.mesh) return std::nullopt;
  return picker.pick(camera.ray(at));
}

}  // namespace

const char* tool_name(Tool tool) {
  return kTools[int(tool)].name;
}

char tool_key(Tool tool) {
  return int(tool) == 9 ? '0' : char('1' + int(tool));
}

const char* tool_hint(Tool tool) {
  return kTools[int(tool)].hint;
}

bool tool_from_name(const std::string& name, Tool& tool) {
  for (int i = 0; i < kToolCount; ++i)
    if (name == kTools[i].script_name) {
      tool = Tool(i);
      return true;
    }
  return false;
}

int Tools::pick_node(const glm::vec2& at, float radius_px, const Editor& editor,
                     const render::Camera& camera, const render::SurfacePicker& picker) const {
  const TriMesh* mesh = editor.doc.mesh.get();
  if (!mesh) return -1;
  // Nodes hidden behind the surface are not pickable: compare with the surface depth.
  const auto hit = pick_surface(at, editor, camera, picker);
  const glm::vec3 eye = camera.eye();
  const float slack = 0.02f * camera.scene_radius();
  int best = -1;
  float best_d = radius_px;
  for (const auto& node : shown_layout(editor).nodes) {
    if (node.vertex < 0 || node.vertex >= int(mesh->n_vertices())) continue;
    const glm::vec3 p = vertex_position(*mesh, node.vertex);
    const glm::vec3 s = camera.project(p);
    if (s.z > 1.0f) continue;
    const float d = glm::length(glm::vec2(s) - at);
    if (d > best_d) continue;
    if (hit && glm::length(p - eye) > glm::length(glm::vec3(hit->position) - eye) + slack) continue;
    best_d = d;
    best = node.id;
  }
  return best;
}

int Tools::pick_arc(const glm::vec2& at, float radius_px, const Editor& editor,
                    const render::Camera& camera, const render::SurfacePicker& picker) const {
  const TriMesh* mesh = editor.doc.mesh.get();
  if (!mesh) return -1;
  const auto hit = pick_surface(at, editor, camera, picker);
  const glm::vec3 eye = camera.eye();
  const float slack = 0.02f * camera.scene_radius();
  int best = -1;
  float best_d = radius_px;
  for (const auto& arc : shown_layout(editor).arcs) {
    glm::vec3 prev_world{0.0f};
    glm::vec2 prev{0.0f};
    bool have_prev = false;
    for (int v : arc.path) {
      if (v < 0 || v >= int(mesh->n_vertices())) continue;
      const glm::vec3 w = vertex_position(*mesh, v);
      const glm::vec3 s = camera.project(w);
      const glm::vec2 cur(s);
      if (have_prev && s.z <= 1.0f) {
        const float d = distance_to_segment(at, prev, cur);
        const bool visible = !hit || glm::length(0.5f * (w + prev_world) - eye) <=
                                         glm::length(glm::vec3(hit->position) - eye) + slack;
        if (d < best_d && visible) {
          best_d = d;
          best = arc.id;
        }
      }
      prev = cur;
      prev_world = w;
      have_prev = s.z <= 1.0f;
    }
  }
  return best;
}

void Tools::hover(const glm::vec2& at, Editor& editor, const render::Camera& camera,
                  const render::SurfacePicker& picker) {
  const int node = pick_node(at, kNodePickPx, editor, camera, picker);
  const int arc = node >= 0 ? -1 : pick_arc(at, kArcPickPx, editor, camera, picker);
  const auto hit = pick_surface(at, editor, camera, picker);
  const int vertex = hit ? hit->nearest_vertex : -1;
  if (node != hovered_node_ || arc != hovered_arc_) {
    hovered_node_ = node;
    hovered_arc_ = arc;
    ++version_;
  }
  // Arc and dangling tools: preview the route to the node (or vertex) under the cursor, or to
  // the boundary vertex the click would end on.
  if ((tool_ == Tool::DrawArc || tool_ == Tool::Dangling) && arc_start_node_ >= 0) {
    const Layout& layout = editor.doc.editor.layout();
    const int start = layout.node_index(arc_start_node_);
    int target = -1;
    if (tool_ == Tool::Dangling)
      target = hit && start >= 0 && node != arc_start_node_ ? dangling_target(*hit, editor) : -1;
    else
      target = node >= 0 ? layout.nodes[layout.node_index(node)].vertex : vertex;
    if (start >= 0 && target != preview_target_vertex_) {
      preview_target_vertex_ = target;
      preview_path_.clear();
      if (target >= 0) {
        const RoutingObstacles obstacles = obstacles_of_layout(*editor.doc.mesh, layout);
        preview_path_ =
            shortest_path(*editor.doc.mesh, layout.nodes[start].vertex, target, obstacles);
      }
      ++version_;
    }
  }
}

void Tools::click(const glm::vec2& at, Editor& editor, const render::Camera& camera,
                  const render::SurfacePicker& picker) {
  if (!editor.doc.mesh) return;
  LayoutEditor& layout_editor = editor.doc.editor;
  const int node = pick_node(at, kNodePickPx, editor, camera, picker);
  const int arc = node >= 0 ? -1 : pick_arc(at, kArcPickPx, editor, camera, picker);
  switch (tool_) {
    case Tool::Select:
      editor.select(node, arc);
      break;
    case Tool::PlaceNode: {
      const auto hit = pick_surface(at, editor, camera, picker);
      if (!hit) return;
      const int through = arc_through_vertex(layout_editor.layout(), hit->nearest_vertex);
      // Placing a node on an arc splits it: that is what sketching a T-junction means.
      if (through >= 0) {
        const auto r =
            sketch_split_arc(layout_editor, editor.mirror(), through, hit->nearest_vertex);
        editor.apply(r,
                     "Split arc " + std::to_string(through) + " with node " + std::to_string(r.id));
      } else {
        const auto r = sketch_add_node(layout_editor, editor.mirror(), hit->nearest_vertex);
        const int k = layout_editor.layout().node_index(r.id);
        editor.apply(r, "Node " + std::to_string(r.id) + " placed on vertex " +
                            std::to_string(k >= 0 ? layout_editor.layout().nodes[k].vertex : -1) +
                            (editor.mirror() ? " (mirrored)" : ""));
        if (r) editor.selection = {r.id, -1};
      }
      break;
    }
    case Tool::DrawArc:
      if (node < 0) {
        editor.set_status(arc_start_node_ < 0
                              ? "Click a node to start an arc"
                              : "Click a second node to finish the arc (Esc cancels)");
        return;
      }
      if (arc_start_node_ < 0 || arc_start_node_ == node) {
        arc_start_node_ = node;
        preview_target_vertex_ = -1;
        editor.set_status("Arc from node " + std::to_string(node) + ": click the end node");
      } else {
        const auto r = sketch_add_arc(layout_editor, editor.mirror(), arc_start_node_, node);
        editor.apply(r, "Arc " + std::to_string(r.id) + " added");
        // Chain: the end node starts the next arc, so outlines are drawn click by click.
        arc_start_node_ = r ? node : arc_start_node_;
      }
      preview_path_.clear();
      preview_target_vertex_ = -1;
      ++version_;
      break;
    case Tool::Stroke:
      editor.set_status(node >= 0 ? "Drag from the node across the surface to draw the arc"
                                  : "Press on a node and drag across the surface (release on a "
                                    "node, or anywhere for a new end node)");
      break;
    case Tool::Dangling: {
      if (arc_start_node_ < 0) {
        if (node < 0) {
          editor.set_status("Click a node to start a dangling arc (it ends on the mesh boundary)");
          return;
        }
        arc_start_node_ = node;
        preview_target_vertex_ = -1;
        editor.set_status("Dangling arc from node " + std::to_string(node) +
                          ": click near the boundary where it ends (the node again: nearest "
                          "boundary)");
      } else {
        int target = -1;
        if (node != arc_start_node_) {
          const auto hit = pick_surface(at, editor, camera, picker);
          if (!hit) {
            editor.set_status("Click on the surface near the boundary (Esc cancels)");
            return;
          }
          target = dangling_target(*hit, editor);
          if (target < 0) {
            editor.set_status("Not done: no free boundary vertex (closed mesh, or all taken)");
            return;
          }
        }
        const auto r =
            sketch_add_dangling_arc(layout_editor, editor.mirror(), arc_start_node_, target);
        editor.apply(r, "Dangling arc " + std::to_string(r.id) + " added");
        if (r) arc_start_node_ = -1;
      }
      preview_path_.clear();
      preview_target_vertex_ = -1;
      ++version_;
      break;
    }
    case Tool::Split: {
      if (arc < 0) {
        editor.set_status("Click on an arc to split it");
        return;
      }
      // Split at the interior path vertex nearest to the cursor.
      const Layout& layout = layout_editor.layout();
      const auto& a = layout.arcs[layout.arc_index(arc)];
      int best = -1;
      float best_d = std::numeric_limits<float>::max();
      for (std::size_t i = 1; i + 1 < a.path.size(); ++i) {
        const float d = glm::length(
            glm::vec2(camera.project(vertex_position(*editor.doc.mesh, a.path[i]))) - at);
        if (d < best_d) {
          best_d = d;
          best = a.path[i];
        }
      }
      const auto r = sketch_split_arc(layout_editor, editor.mirror(), arc, best);
      editor.apply(r, "Split arc " + std::to_string(arc) + " with node " + std::to_string(r.id));
      break;
    }
    case Tool::Delete:
      if (node >= 0)
        editor.apply(sketch_delete_node(layout_editor, editor.mirror(), node),
                     "Node " + std::to_string(node) + " deleted");
      else if (arc >= 0)
        editor.apply(sketch_delete_arc(layout_editor, editor.mirror(), arc),
                     "Arc " + std::to_string(arc) + " deleted");
      if (node >= 0 && node == editor.selection.node) editor.selection.node = -1;
      if (arc >= 0 && arc == editor.selection.arc) editor.selection.arc = -1;
      break;
    case Tool::Pin:
      if (node >= 0)
        editor.toggle_node_pin(node);
      else if (arc >= 0)
        editor.toggle_arc_pin(arc);
      break;
    case Tool::InsertLoop:
    case Tool::RemoveLoop:
      if (arc < 0) {
        editor.set_status(tool_ == Tool::InsertLoop
                              ? "Click an arc: the loop runs through the chord crossing it"
                              : "Click an arc of the edge loop to remove");
        return;
      }
      if (tool_ == Tool::InsertLoop)
        editor.insert_edge_loop(arc);
      else
        editor.remove_edge_loop(arc);
      break;
  }
}

void Tools::mouse(const MouseInput& in, Editor& editor, render::Camera& camera,
                  const render::SurfacePicker& picker) {
  const glm::vec2 at = in.position;
  // Drags that started in the viewport continue even over panels.
  if (drag_ == Drag::None && !in.over_ui) {
    if (in.wheel != 0.0f) camera.zoom(in.wheel);
    if (in.left_clicked) {
      press_ = at;
      drag_ = Drag::Pending;
      press_node_ = tool_ == Tool::Select || tool_ == Tool::Stroke
                        ? pick_node(at, kNodePickPx, editor, camera, picker)
                        : -1;
    } else if (in.pan_clicked) {
      drag_ = Drag::Pan;
    } else if (at != last_ && in.position_valid) {
      hover(at, editor, camera, picker);
    }
  }

  switch (drag_) {
    case Drag::None:
      break;
    case Drag::Pending:
      if (!in.left_down) {
        drag_ = Drag::None;
        click(at, editor, camera, picker);
      } else if (glm::length(at - press_) > kClickSlop) {
        if (tool_ == Tool::Stroke && press_node_ >= 0) {
          drag_ = Drag::Stroke;
          begin_stroke(press_node_, press_, editor, camera, picker);
          add_stroke_sample(at, editor, camera, picker);
        } else if (tool_ == Tool::Select && press_node_ >= 0 && editor.begin_drag(press_node_)) {
          drag_ = Drag::MoveNode;
          editor.selection = {press_node_, -1};
          ++editor.interaction_version;
        } else {
          drag_ = Drag::Orbit;
          camera.begin_orbit(press_);
          camera.orbit_to(at);
        }
      }
      break;
    case Drag::Orbit:
      if (!in.left_down)
        drag_ = Drag::None;
      else if (at != last_)
        camera.orbit_to(at);
      break;
    case Drag::Pan:
      if (!in.pan_down)
        drag_ = Drag::None;
      else
        camera.pan(in.delta);
      break;
    case Drag::Stroke:
      if (!in.left_down) {
        drag_ = Drag::None;
        end_stroke(at, editor, camera, picker);
      } else if (at != last_) {
        add_stroke_sample(at, editor, camera, picker);
      }
      break;
    case Drag::MoveNode:
      if (!in.left_down) {
        drag_ = Drag::None;
        editor.end_drag();
        editor.set_status("Moved node " + std::to_string(editor.selection.node));
      } else if (at != last_) {
        if (const auto hit = pick_surface(at, editor, camera, picker)) {
          const auto r = editor.drag_to(hit->nearest_vertex);
          if (!r) editor.set_status("Cannot move there: " + r.error);
        }
      }
      break;
  }
  last_ = at;
}

void Tools::escape(Editor& editor) {
  if (editor.doc.editor.dragging()) {
    editor.cancel_drag();
    drag_ = Drag::None;
  }
  if (drag_ == Drag::Stroke) {
    cancel_stroke();
    drag_ = Drag::None;
    editor.set_status("Stroke cancelled");
  }
  arc_start_node_ = -1;
  preview_path_.clear();
  editor.selection = {};
  ++editor.interaction_version;
  ++version_;
}

void Tools::begin_stroke(int node, const glm::vec2& at, Editor& editor,
                         const render::Camera& camera, const render::SurfacePicker& picker) {
  stroke_node_ = node;
  stroke_samples_.clear();
  stroke_points_.clear();
  stroke_last_ = glm::vec2(-1e9f);
  add_stroke_sample(at, editor, camera, picker);
  editor.set_status("Stroke from node " + std::to_string(node) + ": release on a node or anywhere");
}

void Tools::add_stroke_sample(const glm::vec2& at, const Editor& editor,
                              const render::Camera& camera, const render::SurfacePicker& picker) {
  if (stroke_node_ < 0) return;
  if (glm::length(at - stroke_last_) < 2.0f) return;  // sub-pixel jitter
  // Each sample is projected onto the surface; samples off the surface are skipped.
  const auto hit = pick_surface(at, editor, camera, picker);
  if (!hit) return;
  stroke_last_ = at;
  SurfacePoint p;
  p.face = hit->face;
  p.bary = hit->bary;
  stroke_samples_.push_back(p);
  stroke_points_.emplace_back(hit->position);
  ++version_;
}

void Tools::end_stroke(const glm::vec2& at, Editor& editor, const render::Camera& camera,
                       const render::SurfacePicker& picker) {
  if (stroke_node_ < 0) return;
  add_stroke_sample(at, editor, camera, picker);
  int to = pick_node(at, kNodePickPx, editor, camera, picker);
  if (to == stroke_node_ && stroke_samples_.size() < 3) to = -1;  // a click, not a loop
  const auto r =
      sketch_add_stroke_arc(editor.doc.editor, editor.mirror(), stroke_node_, to, stroke_samples_);
  if (r.ok && r.node_id >= 0)
    editor.apply(
        r, "Stroke arc " + std::to_string(r.id) + " to new node " + std::to_string(r.node_id));
  else
    editor.apply(r, "Stroke arc " + std::to_string(r.id) + " added");
  if (r) editor.selection = {-1, r.id};
  cancel_stroke();
}

void Tools::cancel_stroke() {
  stroke_node_ = -1;
  stroke_samples_.clear();
  stroke_points_.clear();
  ++version_;
}

bool Tools::stroke_through_vertices(const std::vector<int>& vertices, Editor& editor,
                                    const render::Camera& camera,
                                    const render::SurfacePicker& picker, std::string* error) {
  const TriMesh* mesh = editor.doc.mesh.get();
  if (!mesh || vertices.size() < 2) {
    if (error) *error = "a stroke needs a mesh and at least 2 vertices";
    return false;
  }
  std::vector<glm::vec2> screen;
  for (int v : vertices) {
    if (v < 0 || v >= int(mesh->n_vertices())) {
      if (error) *error = "vertex " + std::to_string(v) + " out of range";
      return false;
    }
    screen.emplace_back(camera.project(vertex_position(*mesh, v)));
  }
  const int node = pick_node(screen.front(), kNodePickPx, editor, camera, picker);
  if (node < 0) {
    if (error) *error = "no visible node at vertex " + std::to_string(vertices.front());
    return false;
  }
  // Mouse-like samples every 3 pixels along the projected polyline.
  begin_stroke(node, screen.front(), editor, camera, picker);
  for (std::size_t k = 0; k + 1 < screen.size(); ++k) {
    const int steps = std::max(1, int(glm::length(screen[k + 1] - screen[k]) / 3.0f));
    for (int i = 1; i <= steps; ++i)
      add_stroke_sample(glm::mix(screen[k], screen[k + 1], float(i) / float(steps)), editor, camera,
                        picker);
  }
  end_stroke(screen.back(), editor, camera, picker);
  return true;
}

int Tools::dangling_target(const render::SurfaceHit& hit, const Editor& editor) const {
  if (!editor.doc.mesh) return -1;
  const RoutingObstacles obstacles =
      obstacles_of_layout(*editor.doc.mesh, editor.doc.editor.layout());
  return nearest_boundary_vertex(*editor.doc.mesh,
                                 Vec3(hit.position.x, hit.position.y, hit.position.z), &obstacles);
}

void Tools::set_tool(Tool tool) {
  if (drag_ == Drag::Stroke) {
    cancel_stroke();
    drag_ = Drag::None;
  }
  tool_ = tool;
  arc_start_node_ = -1;
  preview_path_.clear();
  preview_target_vertex_ = -1;
  ++version_;
}

void Tools::sync(const Editor& editor) {
  const Layout& layout = editor.doc.editor.layout();
  if (arc_start_node_ >= 0 && layout.node_index(arc_start_node_) < 0) {
    arc_start_node_ = -1;
    preview_path_.clear();
    preview_target_vertex_ = -1;
    ++version_;
  }
  if (hovered_node_ >= 0 && layout.node_index(hovered_node_) < 0) hovered_node_ = -1, ++version_;
  if (hovered_arc_ >= 0 && layout.arc_index(hovered_arc_) < 0) hovered_arc_ = -1, ++version_;
}

}  // namespace qs::app
