// Mouse and keyboard: camera navigation and the sketching tools.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "app/gui/app.h"
#include "core/layout/routing.h"

namespace qs::app {

namespace {

constexpr float kClickSlop = 4.0f;  // pixels a click may move before it becomes a drag
constexpr float kNodePickPx = 12.0f;
constexpr float kArcPickPx = 8.0f;

float distance_to_segment(const glm::vec2& p, const glm::vec2& a, const glm::vec2& b) {
  const glm::vec2 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::length(p - (a + t * ab));
}

}  // namespace

glm::vec3 App::vertex_position(int v) const {
  const auto& p = doc_.mesh->point(OpenMesh::VertexHandle(v));
  return {float(p[0]), float(p[1]), float(p[2])};
}

std::optional<render::SurfaceHit> App::pick_surface(const glm::vec2& mouse) const {
  if (!doc_.mesh) return std::nullopt;
  return picker_.pick(camera_.ray(mouse));
}

int App::pick_node(const glm::vec2& mouse, float radius_px) const {
  if (!doc_.mesh) return -1;
  // Nodes hidden behind the surface are not pickable: compare with the surface depth.
  const auto hit = pick_surface(mouse);
  const glm::vec3 eye = camera_.eye();
  const float slack = 0.02f * camera_.scene_radius();
  int best = -1;
  float best_d = radius_px;
  for (const auto& node : doc_.editor.layout().nodes) {
    if (node.vertex < 0 || node.vertex >= int(doc_.mesh->n_vertices())) continue;
    const glm::vec3 p = vertex_position(node.vertex);
    const glm::vec3 s = camera_.project(p);
    if (s.z > 1.0f) continue;
    const float d = glm::length(glm::vec2(s) - mouse);
    if (d > best_d) continue;
    if (hit && glm::length(p - eye) > glm::length(glm::vec3(hit->position) - eye) + slack) continue;
    best_d = d;
    best = node.id;
  }
  return best;
}

int App::pick_arc(const glm::vec2& mouse, float radius_px) const {
  if (!doc_.mesh) return -1;
  const auto hit = pick_surface(mouse);
  const glm::vec3 eye = camera_.eye();
  const float slack = 0.02f * camera_.scene_radius();
  int best = -1;
  float best_d = radius_px;
  for (const auto& arc : doc_.editor.layout().arcs) {
    glm::vec3 prev_world{0.0f};
    glm::vec2 prev{0.0f};
    bool have_prev = false;
    for (int v : arc.path) {
      if (v < 0 || v >= int(doc_.mesh->n_vertices())) continue;
      const glm::vec3 w = vertex_position(v);
      const glm::vec3 s = camera_.project(w);
      const glm::vec2 cur(s);
      if (have_prev && s.z <= 1.0f) {
        const float d = distance_to_segment(mouse, prev, cur);
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

void App::update_hover(const glm::vec2& mouse) {
  const int node = pick_node(mouse, kNodePickPx);
  const int arc = node >= 0 ? -1 : pick_arc(mouse, kArcPickPx);
  const auto hit = pick_surface(mouse);
  const int vertex = hit ? hit->nearest_vertex : -1;
  if (node != hovered_node_ || arc != hovered_arc_) {
    hovered_node_ = node;
    hovered_arc_ = arc;
    ++interaction_version_;
  }
  hovered_vertex_ = vertex;
  // Arc and dangling tools: preview the route to the node (or vertex) under the cursor, or to
  // the boundary vertex the click would end on.
  if ((tool_ == Tool::DrawArc || tool_ == Tool::Dangling) && arc_start_node_ >= 0) {
    const auto& layout = doc_.editor.layout();
    const int start = layout.node_index(arc_start_node_);
    int target = -1;
    if (tool_ == Tool::Dangling)
      target = hit && start >= 0 && node != arc_start_node_ ? dangling_target(*hit) : -1;
    else
      target = node >= 0 ? layout.nodes[layout.node_index(node)].vertex : vertex;
    if (start >= 0 && target != preview_target_vertex_) {
      preview_target_vertex_ = target;
      preview_path_.clear();
      if (target >= 0) {
        const RoutingObstacles obstacles = obstacles_of_layout(*doc_.mesh, layout);
        preview_path_ = shortest_path(*doc_.mesh, layout.nodes[start].vertex, target, obstacles);
      }
      ++interaction_version_;
    }
  }
}

void App::apply(const EditResult& result, const std::string& done_message) {
  if (result.ok) {
    status_ = done_message;
  } else {
    status_ = "Not done: " + result.error;
  }
  ++interaction_version_;
}

void App::click(const glm::vec2& mouse) {
  if (!doc_.mesh) return;
  const int node = pick_node(mouse, kNodePickPx);
  const int arc = node >= 0 ? -1 : pick_arc(mouse, kArcPickPx);
  switch (tool_) {
    case Tool::Select:
      selected_node_ = node;
      selected_arc_ = arc;
      status_ = node >= 0  ? "Node " + std::to_string(node) + " selected"
                : arc >= 0 ? "Arc " + std::to_string(arc) + " selected"
                           : "";
      ++interaction_version_;
      break;
    case Tool::PlaceNode: {
      const auto hit = pick_surface(mouse);
      if (!hit) return;
      const int through = arc_through_vertex(doc_.editor.layout(), hit->nearest_vertex);
      // Placing a node on an arc splits it: that is what sketching a T-junction means.
      if (through >= 0) {
        const auto r = doc_.editor.split_arc(through, hit->nearest_vertex);
        apply(r, "Split arc " + std::to_string(through) + " with node " + std::to_string(r.id));
      } else {
        const auto r = doc_.editor.add_node(hit->nearest_vertex);
        apply(r, "Node " + std::to_string(r.id) + " placed on vertex " +
                     std::to_string(hit->nearest_vertex));
        if (r) selected_node_ = r.id;
      }
      break;
    }
    case Tool::DrawArc:
      if (node < 0) {
        status_ = arc_start_node_ < 0 ? "Click a node to start an arc"
                                      : "Click a second node to finish the arc (Esc cancels)";
        return;
      }
      if (arc_start_node_ < 0 || arc_start_node_ == node) {
        arc_start_node_ = node;
        preview_target_vertex_ = -1;
        status_ = "Arc from node " + std::to_string(node) + ": click the end node";
      } else {
        const auto r = doc_.editor.add_arc(arc_start_node_, node);
        apply(r, "Arc " + std::to_string(r.id) + " added");
        // Chain: the end node starts the next arc, so outlines are drawn click by click.
        arc_start_node_ = r ? node : arc_start_node_;
      }
      preview_path_.clear();
      preview_target_vertex_ = -1;
      ++interaction_version_;
      break;
    case Tool::Stroke:
      status_ = node >= 0 ? "Drag from the node across the surface to draw the arc"
                          : "Press on a node and drag across the surface (release on a node, or "
                            "anywhere for a new end node)";
      break;
    case Tool::Dangling: {
      if (arc_start_node_ < 0) {
        if (node < 0) {
          status_ = "Click a node to start a dangling arc (it ends on the mesh boundary)";
          return;
        }
        arc_start_node_ = node;
        preview_target_vertex_ = -1;
        status_ = "Dangling arc from node " + std::to_string(node) +
                  ": click near the boundary where it ends (the node again: nearest boundary)";
      } else {
        int target = -1;
        if (node != arc_start_node_) {
          const auto hit = pick_surface(mouse);
          if (!hit) {
            status_ = "Click on the surface near the boundary (Esc cancels)";
            return;
          }
          target = dangling_target(*hit);
          if (target < 0) {
            status_ = "Not done: no free boundary vertex (closed mesh, or all taken)";
            return;
          }
        }
        const auto r = doc_.editor.add_dangling_arc(arc_start_node_, target);
        apply(r, "Dangling arc " + std::to_string(r.id) + " added");
        if (r) arc_start_node_ = -1;
      }
      preview_path_.clear();
      preview_target_vertex_ = -1;
      ++interaction_version_;
      break;
    }
    case Tool::Split: {
      if (arc < 0) {
        status_ = "Click on an arc to split it";
        return;
      }
      // Split at the interior path vertex nearest to the cursor.
      const auto& a = doc_.editor.layout().arcs[doc_.editor.layout().arc_index(arc)];
      int best = -1;
      float best_d = std::numeric_limits<float>::max();
      for (std::size_t i = 1; i + 1 < a.path.size(); ++i) {
        const float d = glm::length(glm::vec2(camera_.project(vertex_position(a.path[i]))) - mouse);
        if (d < best_d) {
          best_d = d;
          best = a.path[i];
        }
      }
      const auto r = doc_.editor.split_arc(arc, best);
      apply(r, "Split arc " + std::to_string(arc) + " with node " + std::to_string(r.id));
      break;
    }
    case Tool::Delete:
      if (node >= 0)
        apply(doc_.editor.delete_node(node), "Node " + std::to_string(node) + " deleted");
      else if (arc >= 0)
        apply(doc_.editor.delete_arc(arc), "Arc " + std::to_string(arc) + " deleted");
      if (node == selected_node_) selected_node_ = -1;
      if (arc == selected_arc_) selected_arc_ = -1;
      break;
    case Tool::Pin:
      if (node >= 0 && live_pins())
        toggle_live_pin(node);
      else if (node >= 0)
        apply(doc_.editor.toggle_node_pin(node), "Pin toggled on node " + std::to_string(node));
      else if (arc >= 0)
        apply(doc_.editor.toggle_arc_pin(arc), "Pin toggled on arc " + std::to_string(arc));
      break;
  }
}

void App::handle_mouse() {
  const ImGuiIO& io = ImGui::GetIO();
  const glm::vec2 mouse(io.MousePos.x, io.MousePos.y);
  const bool over_ui = io.WantCaptureMouse;

  // Drags that started in the viewport continue even over panels.
  if (drag_ == Drag::None && !over_ui) {
    if (io.MouseWheel != 0.0f) camera_.zoom(io.MouseWheel);
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
      press_pos_ = mouse;
      drag_ = Drag::Pending;
      press_node_ =
          tool_ == Tool::Select || tool_ == Tool::Stroke ? pick_node(mouse, kNodePickPx) : -1;
    } else if (ImGui::IsMouseClicked(ImGuiMouseButton_Right) ||
               ImGui::IsMouseClicked(ImGuiMouseButton_Middle)) {
      drag_ = Drag::Pan;
    } else if (mouse != last_mouse_ && ImGui::IsMousePosValid()) {
      update_hover(mouse);
    }
  }

  switch (drag_) {
    case Drag::None:
      break;
    case Drag::Pending:
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        drag_ = Drag::None;
        click(mouse);
      } else if (glm::length(mouse - press_pos_) > kClickSlop) {
        if (tool_ == Tool::Stroke && press_node_ >= 0) {
          drag_ = Drag::Stroke;
          begin_stroke(press_node_, press_pos_);
          add_stroke_sample(mouse);
        } else if (tool_ == Tool::Select && press_node_ >= 0 &&
                   doc_.editor.begin_drag(press_node_)) {
          drag_ = Drag::MoveNode;
          selected_node_ = press_node_;
          selected_arc_ = -1;
          ++interaction_version_;
        } else {
          drag_ = Drag::Orbit;
          camera_.begin_orbit(press_pos_);
          camera_.orbit_to(mouse);
        }
      }
      break;
    case Drag::Orbit:
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        drag_ = Drag::None;
      } else if (mouse != last_mouse_) {
        camera_.orbit_to(mouse);
      }
      break;
    case Drag::Pan:
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Right) &&
          !ImGui::IsMouseDown(ImGuiMouseButton_Middle)) {
        drag_ = Drag::None;
      } else {
        camera_.pan({io.MouseDelta.x, io.MouseDelta.y});
      }
      break;
    case Drag::Stroke:
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        drag_ = Drag::None;
        end_stroke(mouse);
      } else if (mouse != last_mouse_) {
        add_stroke_sample(mouse);
      }
      break;
    case Drag::MoveNode:
      if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
        drag_ = Drag::None;
        doc_.editor.end_drag();
        status_ = "Moved node " + std::to_string(selected_node_);
      } else if (mouse != last_mouse_) {
        if (const auto hit = pick_surface(mouse)) {
          const auto r = doc_.editor.drag_to(hit->nearest_vertex);
          if (!r) status_ = "Cannot move there: " + r.error;
        }
      }
      break;
  }
  last_mouse_ = mouse;
}

void App::handle_keys() {
  std::vector<std::pair<int, int>> keys;
  keys.swap(key_events_);
  if (ImGui::GetIO().WantCaptureKeyboard) return;  // typing into a text field
  for (const auto& [key, mods] : keys) {
    const bool ctrl = mods & GLFW_MOD_CONTROL;
    const bool shift = mods & GLFW_MOD_SHIFT;
    if (ctrl && key == GLFW_KEY_Z && shift) {
      redo();
    } else if (ctrl && key == GLFW_KEY_Z) {
      undo();
    } else if (ctrl && key == GLFW_KEY_Y) {
      redo();
    } else if (ctrl && key == GLFW_KEY_S) {
      if (doc_.layout_path.empty())
        status_ = "Choose a file name in the Files panel to save";
      else
        save_layout({});
    } else if (ctrl) {
      continue;
    } else if (key == GLFW_KEY_F) {
      focus_selection();
    } else if (key == GLFW_KEY_R || key == GLFW_KEY_HOME) {
      reset_view();
    } else if (key == GLFW_KEY_DELETE || key == GLFW_KEY_BACKSPACE) {
      delete_selection();
    } else if (key == GLFW_KEY_P) {
      toggle_pin_selection();
    } else if (key == GLFW_KEY_ESCAPE) {
      if (doc_.editor.dragging()) {
        doc_.editor.cancel_drag();
        drag_ = Drag::None;
      }
      if (drag_ == Drag::Stroke) {
        cancel_stroke();
        drag_ = Drag::None;
        status_ = "Stroke cancelled";
      }
      arc_start_node_ = -1;
      preview_path_.clear();
      selected_node_ = selected_arc_ = -1;
      ++interaction_version_;
    } else if (key >= GLFW_KEY_1 && key < GLFW_KEY_1 + kToolCount) {
      set_tool(static_cast<Tool>(key - GLFW_KEY_1));
    }
  }
}

void App::begin_stroke(int node, const glm::vec2& mouse) {
  stroke_node_ = node;
  stroke_samples_.clear();
  stroke_points_.clear();
  stroke_last_mouse_ = glm::vec2(-1e9f);
  add_stroke_sample(mouse);
  status_ = "Stroke from node " + std::to_string(node) + ": release on a node or anywhere";
}

void App::add_stroke_sample(const glm::vec2& mouse) {
  if (stroke_node_ < 0) return;
  if (glm::length(mouse - stroke_last_mouse_) < 2.0f) return;  // sub-pixel jitter
  // Each sample is projected onto the surface; samples off the surface are skipped.
  const auto hit = pick_surface(mouse);
  if (!hit) return;
  stroke_last_mouse_ = mouse;
  SurfacePoint p;
  p.face = hit->face;
  p.bary = hit->bary;
  stroke_samples_.push_back(p);
  stroke_points_.emplace_back(hit->position);
  ++interaction_version_;
}

void App::end_stroke(const glm::vec2& mouse) {
  if (stroke_node_ < 0) return;
  add_stroke_sample(mouse);
  int to = pick_node(mouse, kNodePickPx);
  if (to == stroke_node_ && stroke_samples_.size() < 3) to = -1;  // a click, not a loop
  const auto r = doc_.editor.add_stroke_arc(stroke_node_, to, stroke_samples_);
  if (r.ok && r.node_id >= 0)
    apply(r, "Stroke arc " + std::to_string(r.id) + " to new node " + std::to_string(r.node_id));
  else
    apply(r, "Stroke arc " + std::to_string(r.id) + " added");
  if (r) {
    selected_arc_ = r.id;
    selected_node_ = -1;
  }
  cancel_stroke();
}

void App::cancel_stroke() {
  stroke_node_ = -1;
  stroke_samples_.clear();
  stroke_points_.clear();
  ++interaction_version_;
}

void App::apply_scripted_stroke() {
  const auto& vs = options_.stroke_vertices;
  if (!doc_.mesh || vs.size() < 2) return;
  std::vector<glm::vec2> screen;
  for (int v : vs) {
    if (v < 0 || v >= int(doc_.mesh->n_vertices())) {
      report_error("--stroke-vertices: vertex " + std::to_string(v) + " out of range");
      return;
    }
    screen.emplace_back(camera_.project(vertex_position(v)));
  }
  const int node = pick_node(screen.front(), kNodePickPx);
  if (node < 0) {
    report_error("--stroke-vertices: no visible node at vertex " + std::to_string(vs.front()));
    return;
  }
  // Mouse-like samples every 3 pixels along the projected polyline.
  begin_stroke(node, screen.front());
  for (std::size_t k = 0; k + 1 < screen.size(); ++k) {
    const int steps = std::max(1, int(glm::length(screen[k + 1] - screen[k]) / 3.0f));
    for (int i = 1; i <= steps; ++i)
      add_stroke_sample(glm::mix(screen[k], screen[k + 1], float(i) / float(steps)));
  }
  end_stroke(screen.back());
  std::fprintf(stderr, "quadsketch: scripted stroke: %s\n", status_.c_str());
}

int App::dangling_target(const render::SurfaceHit& hit) const {
  if (!doc_.mesh) return -1;
  const RoutingObstacles obstacles = obstacles_of_layout(*doc_.mesh, doc_.editor.layout());
  return nearest_boundary_vertex(*doc_.mesh, Vec3(hit.position.x, hit.position.y, hit.position.z),
                                 &obstacles);
}

void App::set_tool(Tool tool) {
  if (drag_ == Drag::Stroke) {
    cancel_stroke();
    drag_ = Drag::None;
  }
  tool_ = tool;
  arc_start_node_ = -1;
  preview_path_.clear();
  preview_target_vertex_ = -1;
  ++interaction_version_;
}

void App::undo() {
  const std::string label = doc_.editor.undo_label();
  if (doc_.editor.undo()) {
    status_ = "Undid " + label;
    arc_start_node_ = -1;
  }
}

void App::redo() {
  const std::string label = doc_.editor.redo_label();
  if (doc_.editor.redo()) status_ = "Redid " + label;
}

void App::delete_selection() {
  if (selected_node_ >= 0) {
    apply(doc_.editor.delete_node(selected_node_),
          "Node " + std::to_string(selected_node_) + " deleted");
    selected_node_ = -1;
  } else if (selected_arc_ >= 0) {
    apply(doc_.editor.delete_arc(selected_arc_),
          "Arc " + std::to_string(selected_arc_) + " deleted");
    selected_arc_ = -1;
  }
}

bool App::live_pins() const {
  return job_layout_shown() &&
         (snapshot_->status == WorkerStatus::Running || snapshot_->status == WorkerStatus::Paused);
}

bool App::job_node_pinned(int node) const {
  for (auto it = pending_pins_.rbegin(); it != pending_pins_.rend(); ++it)
    if (it->node == node) return it->pinned;
  if (!snapshot_) return false;
  for (const auto& pin : snapshot_->pins)
    if (pin[0] == node) return true;
  if (snapshot_->layout)
    if (int k = snapshot_->layout->node_index(node); k >= 0)
      return snapshot_->layout->nodes[k].pinned;
  return false;
}

void App::toggle_live_pin(int node) {
  const Layout& layout = *snapshot_->layout;
  const int k = layout.node_index(node);
  if (k < 0) return;
  const bool pin = !job_node_pinned(node);
  const std::uint64_t seq = pin ? worker_->send(cmd::SetPin{node, layout.nodes[k].vertex})
                                : worker_->send(cmd::ClearPin{node});
  pending_pins_.push_back({node, pin, seq});
  ++interaction_version_;
  status_ = std::string(pin ? "Pinning" : "Unpinning") + " node " + std::to_string(node) +
            " in the running job (applies at the next step)";
}

void App::toggle_pin_selection() {
  if (selected_node_ >= 0 && live_pins())
    toggle_live_pin(selected_node_);
  else if (selected_node_ >= 0)
    apply(doc_.editor.toggle_node_pin(selected_node_), "Pin toggled");
  else if (selected_arc_ >= 0)
    apply(doc_.editor.toggle_arc_pin(selected_arc_), "Pin toggled");
}

void App::reset_view() {
  if (!doc_.mesh) return;
  Vec3 c;
  double r = 1.0;
  doc_.bounds(c, r);
  camera_.set_scene({float(c[0]), float(c[1]), float(c[2])}, float(r));
  camera_.reset();
}

void App::focus_vertices(const std::vector<int>& vertices) {
  if (!doc_.mesh) return;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  int count = 0;
  for (int v : vertices) {
    if (v < 0 || v >= int(doc_.mesh->n_vertices())) continue;
    lo = glm::min(lo, vertex_position(v));
    hi = glm::max(hi, vertex_position(v));
    ++count;
  }
  if (count == 0) return;
  // Look from the side the vertices face (area-weighted normals of their faces).
  Vec3 normal(0, 0, 0);
  for (int v : vertices) {
    if (v < 0 || v >= int(doc_.mesh->n_vertices())) continue;
    for (auto fh : doc_.mesh->vf_range(OpenMesh::VertexHandle(v))) {
      auto it = doc_.mesh->cfv_begin(fh);
      const Vec3 a = doc_.mesh->point(*it++), b = doc_.mesh->point(*it++),
                 c = doc_.mesh->point(*it);
      normal += OpenMesh::cross(b - a, c - a);
    }
  }
  camera_.focus(0.5f * (lo + hi), 0.5f * glm::length(hi - lo),
                glm::vec3(float(normal[0]), float(normal[1]), float(normal[2])));
}

void App::focus_selection() {
  const Layout& layout = doc_.editor.layout();
  if (selected_node_ >= 0 && layout.node_index(selected_node_) >= 0) {
    focus_vertices({layout.nodes[layout.node_index(selected_node_)].vertex});
  } else if (selected_arc_ >= 0 && layout.arc_index(selected_arc_) >= 0) {
    focus_vertices(layout.arcs[layout.arc_index(selected_arc_)].path);
  } else if (highlighted_issue_ >= 0 && highlighted_issue_ < int(doc_.validation.issues.size())) {
    focus_vertices(doc_.validation.issues[highlighted_issue_].vertices);
  } else {
    reset_view();
  }
}

}  // namespace qs::app
