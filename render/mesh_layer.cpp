#include "render/mesh_layer.h"

#include <imgui.h>

#include <stdexcept>
#include <vector>

#include "render/scene_cache.h"

namespace qs::render {

MeshLayer::MeshLayer() {
  std::string log;
  if (!reload(&log)) throw std::runtime_error("mesh shader: " + log);
}

bool MeshLayer::reload(std::string* log) {
  return program_.build("mesh.vert", "mesh.frag", log);
}

void MeshLayer::upload(const SceneData& data) {
  const bool mesh_changed = data.mesh != mesh_ptr_ || data.mesh_version != mesh_version_;
  if (mesh_changed) {
    mesh_ptr_ = data.mesh;
    mesh_version_ = data.mesh_version;
    param_version_ = ~0ull;  // sizes change with the mesh
    corners_ = 0;
    if (data.mesh) {
      const TriMesh& mesh = *data.mesh;
      // Area-weighted vertex normals (cross products are twice the area), computed here so
      // that the mesh need not carry OpenMesh normal properties.
      std::vector<Vec3> normals(mesh.n_vertices(), Vec3(0, 0, 0));
      for (auto fh : mesh.faces()) {
        auto it = mesh.cfv_begin(fh);
        const auto a = *it++, b = *it++, c = *it;
        const Vec3 n =
            OpenMesh::cross(mesh.point(b) - mesh.point(a), mesh.point(c) - mesh.point(a));
        normals[a.idx()] += n;
        normals[b.idx()] += n;
        normals[c.idx()] += n;
      }
      std::vector<float> buffer;
      buffer.reserve(mesh.n_faces() * 3 * 6);
      for (auto fh : mesh.faces()) {
        for (auto vh : mesh.fv_range(fh)) {
          const auto& p = mesh.point(vh);
          Vec3 n = normals[vh.idx()];
          const double len = n.norm();
          if (len > 0) n /= len;
          buffer.insert(buffer.end(), {float(p[0]), float(p[1]), float(p[2]), float(n[0]),
                                       float(n[1]), float(n[2])});
        }
      }
      corners_ = static_cast<int>(buffer.size() / 6);
      // Closed and consistently oriented (the loader checks orientation): the sign of the
      // enclosed volume tells whether faces wind counter-clockwise seen from outside.
      closed_ = true;
      for (auto heh : mesh.halfedges())
        if (mesh.is_boundary(heh)) {
          closed_ = false;
          break;
        }
      double volume6 = 0.0;
      for (auto fh : mesh.faces()) {
        auto it = mesh.cfv_begin(fh);
        const Vec3 a = mesh.point(*it++), b = mesh.point(*it++), c = mesh.point(*it);
        volume6 += OpenMesh::dot(a, OpenMesh::cross(b, c));
      }
      outward_ = volume6 >= 0.0;
      // Parameter units are world units: about 3 mesh edges per checker cell makes the
      // iso-lines readable at any model scale.
      double edge_sum = 0;
      for (auto eh : mesh.edges()) edge_sum += mesh.calc_edge_length(eh);
      if (mesh.n_edges() > 0 && edge_sum > 0)
        checker_scale = float(mesh.n_edges() / (3.0 * edge_sum));
      geometry_.upload(buffer.data(), buffer.size() * sizeof(float));
      vao_.attribute(0, geometry_, 3, 6, 0);
      vao_.attribute(1, geometry_, 3, 6, 3);
    }
  }
  if (corners_ > 0 && (mesh_changed || data.param_version != param_version_)) {
    param_version_ = data.param_version;
    const int faces = corners_ / 3;
    has_uv_ = data.corner_uv && static_cast<int>(data.corner_uv->size()) == corners_;
    const bool has_flags =
        data.face_foldover && static_cast<int>(data.face_foldover->size()) == faces;
    std::vector<float> buffer(static_cast<std::size_t>(corners_) * 3, 0.0f);
    for (int c = 0; c < corners_; ++c) {
      if (has_uv_) {
        buffer[3 * c] = (*data.corner_uv)[c][0];
        buffer[3 * c + 1] = (*data.corner_uv)[c][1];
      }
      if (has_flags) buffer[3 * c + 2] = (*data.face_foldover)[c / 3] ? 1.0f : 0.0f;
    }
    param_.upload(buffer.data(), buffer.size() * sizeof(float), GL_DYNAMIC_DRAW);
    vao_.attribute(2, param_, 2, 3, 0);
    vao_.attribute(3, param_, 1, 3, 2);
  }
}

void MeshLayer::draw(const FrameContext& frame) {
  if (!visible || corners_ == 0) return;
  program_.use();
  program_.set("u_view", frame.camera->view());
  program_.set("u_proj", frame.camera->projection());
  program_.set("u_front_color", front_color);
  program_.set("u_back_color", back_color);
  program_.set("u_flat", flat_shading ? 1 : 0);
  program_.set("u_wireframe", wireframe ? 1 : 0);
  program_.set("u_wire_color", glm::vec3(0.16f, 0.17f, 0.20f));
  program_.set("u_wire_width", wire_width * frame.pixel_ratio);
  program_.set("u_mode", checker && has_uv_ ? 1 : 0);
  program_.set("u_checker_scale", checker_scale);
  program_.set("u_show_foldovers", show_foldovers ? 1 : 0);
  // Push the surface back a little so that arcs and nodes drawn on it win the depth test.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  const bool cull = cull_hidden_faces && closed_;
  if (cull) {
    glEnable(GL_CULL_FACE);
    glFrontFace(GL_CCW);
    glCullFace(outward_ ? GL_BACK : GL_FRONT);
  }
  vao_.bind();
  glDrawArrays(GL_TRIANGLES, 0, corners_);
  glDisable(GL_POLYGON_OFFSET_FILL);
  if (cull) glDisable(GL_CULL_FACE);
}

std::uint64_t MeshLayer::settings_key() const {
  FrameKey key;
  for (bool b : {visible, flat_shading, wireframe, checker, show_foldovers, cull_hidden_faces})
    key.add(b);
  key.add(checker_scale);
  key.add(wire_width);
  key.add(front_color);
  key.add(back_color);
  return key.value();
}

void MeshLayer::ui() {
  ImGui::Checkbox("Surface", &visible);
  ImGui::SameLine();
  ImGui::Checkbox("Wireframe", &wireframe);
  ImGui::SameLine();
  ImGui::Checkbox("Flat", &flat_shading);
  if (!has_uv_) ImGui::BeginDisabled();
  ImGui::Checkbox("UV checker", &checker);
  ImGui::SameLine();
  ImGui::Checkbox("Fold-overs", &show_foldovers);
  ImGui::SliderFloat("Checker scale", &checker_scale, 0.01f, 1000.0f, "%.3g",
                     ImGuiSliderFlags_Logarithmic);
  if (!has_uv_) {
    ImGui::EndDisabled();
    ImGui::TextDisabled("No parameterization yet (the pipeline provides it).");
  }
  if (closed_) {
    ImGui::Checkbox("Cull hidden faces", &cull_hidden_faces);
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "The mesh is closed: faces turned away from the camera are always "
          "hidden, skipping them makes every frame cheaper. Turn off to see the "
          "inside when the view cuts into the surface.");
  }
  ImGui::SliderFloat("Wire width", &wire_width, 0.5f, 3.0f, "%.1f px");
  ImGui::ColorEdit3("Front", &front_color.x, ImGuiColorEditFlags_NoInputs);
  ImGui::SameLine();
  ImGui::ColorEdit3("Back", &back_color.x, ImGuiColorEditFlags_NoInputs);
}

}  // namespace qs::render
