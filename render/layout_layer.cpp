#include "render/layout_layer.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>
#include <unordered_set>

#include "render/scene_cache.h"

namespace qs::render {

glm::vec3 LayoutColors::valence(int valence) {
  switch (valence) {
    case 4:
      return {0.93f, 0.93f, 0.91f};  // regular: neutral
    case 3:
      return {0.22f, 0.56f, 0.97f};
    case 5:
      return {0.97f, 0.47f, 0.13f};
    default:
      return {0.78f, 0.28f, 0.88f};  // anything else stands out
  }
}

glm::vec3 LayoutColors::label(const std::string& label) {
  if (label == "u") return {0.89f, 0.30f, 0.24f};
  if (label == "v") return {0.16f, 0.66f, 0.42f};
  return {0.14f, 0.16f, 0.22f};  // unknown: dark slate, readable on the light surface
}

namespace {

constexpr int kLineFloats = 11;  // p0, p1, rgba, width
constexpr int kPointFloats = 9;  // position, rgba, size, ring

void push_point(std::vector<float>& out, const glm::vec3& p, const glm::vec3& c, float alpha,
                float size, float ring) {
  out.insert(out.end(), {p.x, p.y, p.z, c.r, c.g, c.b, alpha, size, ring});
}

void push_segment(std::vector<float>& out, const glm::vec3& a, const glm::vec3& b,
                  const glm::vec3& c, float alpha, float width) {
  out.insert(out.end(), {a.x, a.y, a.z, b.x, b.y, b.z, c.r, c.g, c.b, alpha, width});
}

void push_polyline(std::vector<float>& out, const std::vector<glm::vec3>& points,
                   const glm::vec3& c, float width) {
  for (std::size_t i = 0; i + 1 < points.size(); ++i)
    push_segment(out, points[i], points[i + 1], c, 1.0f, width);
}

glm::vec3 to_vec3(const std::array<float, 3>& p) {
  return {p[0], p[1], p[2]};
}

void upload_instances(GlVertexArray& vao, GlBuffer& buffer, const std::vector<float>& data,
                      bool lines_format) {
  if (data.empty()) return;
  buffer.upload(data.data(), data.size() * sizeof(float), GL_DYNAMIC_DRAW);
  if (lines_format) {
    vao.attribute(0, buffer, 3, kLineFloats, 0, 1);
    vao.attribute(1, buffer, 3, kLineFloats, 3, 1);
    vao.attribute(2, buffer, 4, kLineFloats, 6, 1);
    vao.attribute(3, buffer, 1, kLineFloats, 10, 1);
  } else {
    vao.attribute(0, buffer, 3, kPointFloats, 0);
    vao.attribute(1, buffer, 4, kPointFloats, 3);
    vao.attribute(2, buffer, 1, kPointFloats, 7);
    vao.attribute(3, buffer, 1, kPointFloats, 8);
  }
}

glm::vec3 vertex_position(const TriMesh& mesh, int v) {
  const auto& p = mesh.point(OpenMesh::VertexHandle(v));
  return {float(p[0]), float(p[1]), float(p[2])};
}

bool valid_vertex(const TriMesh& mesh, int v) {
  return v >= 0 && v < int(mesh.n_vertices());
}

}  // namespace

LayoutLayer::LayoutLayer() {
  std::string log;
  if (!reload(&log)) throw std::runtime_error("layout shaders: " + log);
}

bool LayoutLayer::reload(std::string* log) {
  return lines_.build("lines.vert", "lines.frag", log) &&
         points_.build("points.vert", "points.frag", log);
}

void LayoutLayer::upload(const SceneData& data) {
  upload_history(data);
  upload_quads(data);
  const std::vector<std::uint64_t> key = {reinterpret_cast<std::uintptr_t>(data.mesh),
                                          data.mesh_version,
                                          reinterpret_cast<std::uintptr_t>(data.layout),
                                          data.layout_version,
                                          data.issues_version,
                                          data.interaction_version};
  if (key == uploaded_key_) return;
  uploaded_key_ = key;
  arc_segments_ = nodes_ = issue_points_ = 0;
  if (!data.mesh) return;
  const TriMesh& mesh = *data.mesh;

  // Scene scale: used to pull lines/points towards the camera by a size-relative amount.
  if (mesh.n_vertices() > 0) {
    auto lo = vertex_position(mesh, 0), hi = lo;
    for (auto vh : mesh.vertices()) {
      const auto p = vertex_position(mesh, vh.idx());
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
    scene_scale_ = std::max(glm::length(hi - lo), 1e-6f);
  }

  const std::unordered_set<int> bad_nodes(data.issue_nodes.begin(), data.issue_nodes.end());
  const std::unordered_set<int> bad_arcs(data.issue_arcs.begin(), data.issue_arcs.end());

  std::vector<float> lines, points, issues;
  if (data.layout) {
    const Layout& layout = *data.layout;
    std::unordered_map<int, int> valence;
    for (const auto& arc : layout.arcs) {
      ++valence[arc.from];
      if (arc.to >= 0) ++valence[arc.to];
    }
    // Pinned arcs first (a wide gold underlay), then every arc on top.
    std::vector<glm::vec3> poly;
    for (int pass = 0; pass < 2; ++pass) {
      for (const auto& arc : layout.arcs) {
        bool pinned = arc.pinned;
        for (const auto& [id, state] : data.arc_pin_overrides)
          if (id == arc.id) pinned = state;
        if (pass == 0 && !pinned && arc.id != data.selected_arc) continue;
        poly.clear();
        if (!arc.polyline.empty()) {
          for (const auto& p : arc.polyline) poly.emplace_back(p[0], p[1], p[2]);
        } else {
          for (int v : arc.path)
            if (valid_vertex(mesh, v)) poly.push_back(vertex_position(mesh, v));
        }
        if (poly.size() < 2) continue;
        if (pass == 0) {
          const bool selected = arc.id == data.selected_arc;
          push_polyline(lines, poly, selected ? LayoutColors::kSelected : LayoutColors::kPin,
                        arc_width * (selected ? 2.6f : 2.2f));
          continue;
        }
        glm::vec3 color = LayoutColors::label(arc.label);
        if (bad_arcs.count(arc.id)) color = LayoutColors::kProblem;
        if (arc.id == data.hovered_arc) color = glm::mix(color, glm::vec3(1.0f), 0.45f);
        push_polyline(lines, poly, color, arc_width);
      }
    }
    for (const auto& node : layout.nodes) {
      glm::vec3 p;
      if (valid_vertex(mesh, node.vertex)) {
        p = vertex_position(mesh, node.vertex);
      } else if (node.position) {
        p = {float((*node.position)[0]), float((*node.position)[1]), float((*node.position)[2])};
      } else {
        continue;
      }
      const auto it = valence.find(node.id);
      glm::vec3 color = LayoutColors::valence(it == valence.end() ? 0 : it->second);
      if (bad_nodes.count(node.id)) color = LayoutColors::kProblem;
      float size = node_size;
      if (node.id == data.hovered_node || node.id == data.arc_start_node) size *= 1.3f;
      bool pinned = node.pinned;
      for (const auto& [id, state] : data.pin_overrides)
        if (id == node.id) pinned = state;
      const float ring = node.id == data.selected_node || node.id == data.arc_start_node ? 2.0f
                         : pinned                                                        ? 1.0f
                                                                                         : 0.0f;
      if (ring > 0.0f) size *= 1.25f;
      push_point(points, p, color, 1.0f, size, ring);
    }
  }
  if (data.preview_path.size() >= 2) {
    std::vector<glm::vec3> poly;
    for (int v : data.preview_path)
      if (valid_vertex(mesh, v)) poly.push_back(vertex_position(mesh, v));
    push_polyline(lines, poly, LayoutColors::kPreview, arc_width * 0.8f);
  }
  if (data.stroke_points.size() >= 2)
    push_polyline(lines, data.stroke_points, LayoutColors::kPreview, arc_width * 0.7f);
  for (int v : data.issue_vertices)
    if (valid_vertex(mesh, v))
      push_point(issues, vertex_position(mesh, v), LayoutColors::kProblem, 0.9f, node_size * 0.8f,
                 0.0f);

  upload_instances(arc_vao_, arc_buffer_, lines, true);
  upload_instances(node_vao_, node_buffer_, points, false);
  upload_instances(issue_vao_, issue_buffer_, issues, false);
  arc_segments_ = static_cast<int>(lines.size() / kLineFloats);
  nodes_ = static_cast<int>(points.size() / kPointFloats);
  issue_points_ = static_cast<int>(issues.size() / kPointFloats);
}

void LayoutLayer::upload_history(const SceneData& data) {
  const std::vector<std::uint64_t> key = {
      reinterpret_cast<std::uintptr_t>(data.node_history), data.history_version,
      std::uint64_t(std::int64_t(data.history_step)), std::uint64_t(node_size * 16.0f),
      std::uint64_t(arc_width * 16.0f)};
  if (key == history_key_) return;
  history_key_ = key;
  traj_segments_ = step_points_ = 0;
  if (!data.node_history || data.node_history->empty()) return;
  const auto& history = *data.node_history;
  // Trajectories (paper Fig. 4): one polyline per node id through its positions over the
  // steps; older segments fade so that the direction of motion reads at a glance.
  std::unordered_map<int, glm::vec3> last;
  std::vector<float> lines, points;
  const float n = float(history.size());
  for (std::size_t k = 0; k < history.size(); ++k) {
    if (!history[k]) continue;
    const NodeFrame& frame = *history[k];
    const float alpha = 0.35f + 0.65f * float(k + 1) / n;
    for (std::size_t i = 0; i < frame.ids.size() && i < frame.positions.size(); ++i) {
      const glm::vec3 p = to_vec3(frame.positions[i]);
      const auto it = last.find(frame.ids[i]);
      if (it != last.end() && glm::length(p - it->second) > 0.0f)
        push_segment(lines, it->second, p, LayoutColors::kTrajectory, alpha, 0.6f * arc_width);
      last[frame.ids[i]] = p;
      // Small beads at every step position.
      push_point(points, p, LayoutColors::kTrajectory, alpha, 0.35f * node_size, 0.0f);
    }
  }
  // The scrubbed step: its node positions, highlighted.
  if (data.history_step >= 0 && data.history_step < int(history.size()) &&
      history[data.history_step]) {
    for (const auto& p : history[data.history_step]->positions)
      push_point(points, to_vec3(p), LayoutColors::kStep, 1.0f, 0.9f * node_size, 2.0f);
  }
  upload_instances(traj_vao_, traj_buffer_, lines, true);
  upload_instances(step_vao_, step_buffer_, points, false);
  traj_segments_ = int(lines.size() / kLineFloats);
  step_points_ = int(points.size() / kPointFloats);
}

void LayoutLayer::upload_quads(const SceneData& data) {
  const std::vector<std::uint64_t> key = {reinterpret_cast<std::uintptr_t>(data.quads),
                                          data.quads_version, std::uint64_t(arc_width * 16.0f)};
  if (key == quads_key_) return;
  quads_key_ = key;
  quad_segments_ = 0;
  if (!data.quads) return;
  const QuadOverlay& q = *data.quads;
  const int nv = int(q.vertices.size());
  // Each shared edge once: key (min, max) vertex pair.
  std::unordered_set<std::uint64_t> seen;
  std::vector<float> lines;
  for (const auto& quad : q.quads) {
    for (int k = 0; k < 4; ++k) {
      const int a = quad[k], b = quad[(k + 1) % 4];
      if (a < 0 || b < 0 || a >= nv || b >= nv) continue;
      const std::uint64_t e = (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b));
      if (!seen.insert(e).second) continue;
      push_segment(lines, to_vec3(q.vertices[a]), to_vec3(q.vertices[b]), LayoutColors::kQuads,
                   0.75f, std::max(1.0f, 0.35f * arc_width));
    }
  }
  upload_instances(quad_vao_, quad_buffer_, lines, true);
  quad_segments_ = int(lines.size() / kLineFloats);
}

void LayoutLayer::draw_lines(const FrameContext& frame, GlVertexArray& vao, int count, float pull) {
  lines_.use();
  lines_.set("u_view", frame.camera->view());
  lines_.set("u_proj", frame.camera->projection());
  lines_.set("u_viewport", glm::vec2(frame.framebuffer));
  lines_.set("u_pixel_ratio", frame.pixel_ratio);
  lines_.set("u_pull", pull);
  lines_.set("u_width_scale", 1.0f);
  vao.bind();
  glDrawArraysInstanced(GL_TRIANGLES, 0, 6, count);
}

void LayoutLayer::draw_points(const FrameContext& frame, GlVertexArray& vao, int count, float scale,
                              float pull) {
  points_.use();
  points_.set("u_view", frame.camera->view());
  points_.set("u_proj", frame.camera->projection());
  points_.set("u_pixel_ratio", frame.pixel_ratio);
  points_.set("u_pull", pull);
  points_.set("u_size_scale", scale);
  vao.bind();
  glDrawArrays(GL_POINTS, 0, count);
}

void LayoutLayer::draw(const FrameContext& frame) {
  if (!visible) return;
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_PROGRAM_POINT_SIZE);
  // Overlays are lifted towards the camera by a small fraction of the scene so they sit on
  // the surface without z-fighting yet stay hidden behind it from the other side.
  const float pull = 0.004f * scene_scale_;
  if (show_quads && quad_segments_ > 0) {
    glDepthMask(GL_FALSE);
    draw_lines(frame, quad_vao_, quad_segments_, 0.75f * pull);
    glDepthMask(GL_TRUE);
  }
  if (show_arcs && arc_segments_ > 0) {
    glDepthMask(GL_FALSE);  // overlapping translucent edges must not occlude each other
    draw_lines(frame, arc_vao_, arc_segments_, pull);
    glDepthMask(GL_TRUE);
  }
  if (show_nodes && nodes_ > 0) draw_points(frame, node_vao_, nodes_, 1.0f, 2.0f * pull);
  if (show_trajectories && traj_segments_ > 0) {
    glDepthMask(GL_FALSE);
    draw_lines(frame, traj_vao_, traj_segments_, 1.5f * pull);
    glDepthMask(GL_TRUE);
  }
  if (show_trajectories && step_points_ > 0)
    draw_points(frame, step_vao_, step_points_, 1.0f, 2.2f * pull);
  if (show_issues && issue_points_ > 0) {
    // Pulsing draws the eye to problems without hiding what is underneath.
    const float pulse = 1.0f + 0.35f * float(std::sin(frame.time_s * 5.0));
    draw_points(frame, issue_vao_, issue_points_, pulse, 2.5f * pull);
  }
  glDisable(GL_BLEND);
}

std::uint64_t LayoutLayer::settings_key() const {
  FrameKey key;
  for (bool b : {visible, show_nodes, show_arcs, show_issues, show_trajectories, show_quads})
    key.add(b);
  key.add(node_size);
  key.add(arc_width);
  return key.value();
}

void LayoutLayer::ui() {
  bool changed = false;
  ImGui::Checkbox("Layout", &visible);
  ImGui::SameLine();
  ImGui::Checkbox("Nodes", &show_nodes);
  ImGui::SameLine();
  ImGui::Checkbox("Arcs", &show_arcs);
  ImGui::SameLine();
  ImGui::Checkbox("Problems", &show_issues);
  ImGui::Checkbox("Node trajectories", &show_trajectories);
  ImGui::SameLine();
  ImGui::Checkbox("Quad mesh", &show_quads);
  changed |= ImGui::SliderFloat("Node size", &node_size, 4.0f, 40.0f, "%.0f px");
  changed |= ImGui::SliderFloat("Arc width", &arc_width, 1.0f, 12.0f, "%.1f px");
  if (changed) uploaded_key_.clear();  // sizes are baked into the instance data
}

}  // namespace qs::render
