#include "render/field_layer.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "render/scene_cache.h"

namespace qs::render {

namespace {

constexpr int kGlyphFloats = 18;  // center, dir, normal, color0, color1, width

void push_glyph(std::vector<float>& out, const glm::vec3& c, const glm::vec3& d, const glm::vec3& n,
                const glm::vec4& color0, const glm::vec4& color1, float width) {
  out.insert(out.end(), {c.x, c.y, c.z, d.x, d.y, d.z, n.x, n.y, n.z, color0.r, color0.g, color0.b,
                         color0.a, color1.r, color1.g, color1.b, color1.a, width});
}

glm::vec3 to_vec3(const Vec3& p) {
  return {float(p[0]), float(p[1]), float(p[2])};
}

}  // namespace

glm::vec3 FieldColors::constraint(int kind) {
  switch (kind) {
    case 1:
      return kFeature;
    case 2:
      return kBoundary;
    default:
      return kCurvature;
  }
}

std::vector<int> sample_faces(const std::vector<glm::vec3>& centroids, double total_area,
                              int max_glyphs, float* arm_length) {
  const int faces = int(centroids.size());
  std::vector<int> out;
  if (faces == 0 || max_glyphs <= 0 || !(total_area > 0.0)) {
    if (arm_length) *arm_length = 0.0f;
    return out;
  }
  if (faces <= max_glyphs) {
    out.resize(faces);
    for (int f = 0; f < faces; ++f) out[f] = f;
    // Arm: a bit less than half the typical face size.
    if (arm_length) *arm_length = float(0.4 * std::sqrt(2.0 * total_area / faces));
    return out;
  }
  // Cells of side s = sqrt(area / max_glyphs): about max_glyphs of them meet the surface; keep
  // the face whose centroid is nearest to each cell's centre.
  const double s = std::sqrt(total_area / max_glyphs);
  glm::vec3 lo = centroids[0];
  for (const auto& c : centroids) lo = glm::min(lo, c);
  struct Best {
    int face;
    float d2;
  };
  std::unordered_map<std::uint64_t, Best> cells;
  cells.reserve(std::size_t(max_glyphs) * 2);
  for (int f = 0; f < faces; ++f) {
    const glm::vec3 g = (centroids[f] - lo) / float(s);
    const auto ix = std::uint64_t(std::max(0.0f, std::floor(g.x)));
    const auto iy = std::uint64_t(std::max(0.0f, std::floor(g.y)));
    const auto iz = std::uint64_t(std::max(0.0f, std::floor(g.z)));
    const std::uint64_t key = (ix & 0x1fffff) | ((iy & 0x1fffff) << 21) | ((iz & 0x1fffff) << 42);
    const glm::vec3 centre = glm::vec3(float(ix), float(iy), float(iz)) + glm::vec3(0.5f);
    const float d2 = glm::dot(g - centre, g - centre);
    auto [it, inserted] = cells.try_emplace(key, Best{f, d2});
    if (!inserted && d2 < it->second.d2) it->second = Best{f, d2};
  }
  out.reserve(cells.size());
  for (const auto& [key, best] : cells) out.push_back(best.face);
  std::sort(out.begin(), out.end());
  if (arm_length) *arm_length = float(0.38 * s);
  return out;
}

FieldLayer::FieldLayer() {
  visible = false;  // toggled in the view panel
  std::string log;
  if (!reload(&log)) throw std::runtime_error("glyph shaders: " + log);
}

bool FieldLayer::reload(std::string* log) {
  return program_.build("glyph.vert", "glyph.frag", log);
}

void FieldLayer::upload(const SceneData& data) {
  const std::vector<std::uint64_t> key = {reinterpret_cast<std::uintptr_t>(data.mesh),
                                          data.mesh_version,
                                          reinterpret_cast<std::uintptr_t>(data.field),
                                          data.field_version,
                                          std::uint64_t(max_glyphs),
                                          std::uint64_t(glyph_scale * 64.0f),
                                          std::uint64_t(width * 16.0f),
                                          std::uint64_t(show_cross) * 2 + show_constraints,
                                          std::uint64_t(visible)};
  if (key == key_) return;
  key_ = key;
  crosses_ = constraints_ = 0;
  has_field_ = false;
  // Hidden layers do no work (a 70K-face field costs a few ms to rebuild).
  if (!visible || !data.mesh || !data.field) return;
  const TriMesh& mesh = *data.mesh;
  const FieldView& field = *data.field;
  const int nf = int(mesh.n_faces());
  if (int(field.direction.size()) != nf) return;  // stale: another mesh
  has_field_ = true;

  std::vector<glm::vec3> centroid(nf), normal(nf);
  double total_area = 0.0;
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const auto fh : mesh.faces()) {
    auto it = mesh.cfv_begin(fh);
    const Vec3 a = mesh.point(*it++), b = mesh.point(*it++), c = mesh.point(*it);
    const Vec3 n = OpenMesh::cross(b - a, c - a);
    const double len = n.norm();
    total_area += 0.5 * len;
    centroid[fh.idx()] = to_vec3((a + b + c) / 3.0);
    normal[fh.idx()] = len > 0 ? to_vec3(n / len) : glm::vec3(0.0f);
    lo = glm::min(lo, centroid[fh.idx()]);
    hi = glm::max(hi, centroid[fh.idx()]);
  }
  scene_scale_ = std::max(glm::length(hi - lo), 1e-6f);
  float arm = 0.0f;
  const std::vector<int> cross_faces = sample_faces(centroid, total_area, max_glyphs, &arm);
  std::vector<float> glyphs;
  // Direction \p d of face f, projected into the face plane of the drawn mesh (the job may
  // have moved vertices a little) and scaled to \p length; zero when degenerate.
  auto in_plane = [&](int f, const std::array<float, 3>& d, float length) {
    const glm::vec3 n = normal[f];
    glm::vec3 t(d[0], d[1], d[2]);
    t -= glm::dot(t, n) * n;
    const float l = glm::length(t);
    return l > 1e-6f && std::isfinite(l) ? t * (length / l) : glm::vec3(0.0f);
  };
  if (show_constraints && !field.constraint_faces.empty()) {
    // Constraint faces: subsampled on their own so that sparse ones are never dropped.
    const std::size_t count =
        std::min({field.constraint_faces.size(), field.constraint_direction.size(),
                  field.constraint_kind.size()});
    std::vector<glm::vec3> c_centroids;
    std::vector<int> c_index;
    double c_area = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      const int f = field.constraint_faces[k];
      if (f < 0 || f >= nf) continue;
      c_centroids.push_back(centroid[f]);
      c_index.push_back(int(k));
    }
    c_area = total_area * double(c_index.size()) / std::max(1, nf);
    float c_arm = 0.0f;
    const int budget = std::max(1, max_glyphs / 2);
    const auto picked = sample_faces(c_centroids, c_area, budget, &c_arm);
    // Same visual scale as the crosses where constraints are dense.
    c_arm = std::max(c_arm, arm) * glyph_scale * 1.15f;
    for (int i : picked) {
      const int k = c_index[i];
      const int f = field.constraint_faces[k];
      const glm::vec3 d = in_plane(f, field.constraint_direction[k], c_arm);
      if (d == glm::vec3(0.0f)) continue;
      const bool in_force =
          std::size_t(k) >= field.constraint_in_force.size() || field.constraint_in_force[k];
      const glm::vec3 color =
          in_force ? FieldColors::constraint(field.constraint_kind[k]) : FieldColors::kReleased;
      push_glyph(glyphs, centroid[f], d, normal[f], glm::vec4(color, 0.95f), glm::vec4(0.0f),
                 width * 2.4f);
      ++constraints_;
    }
  }
  if (show_cross) {
    const glm::vec4 color(FieldColors::kCross, 0.95f);
    for (int f : cross_faces) {
      const glm::vec3 d = in_plane(f, field.direction[f], arm * glyph_scale);
      if (d == glm::vec3(0.0f)) continue;
      push_glyph(glyphs, centroid[f], d, normal[f], color, color, width);
      ++crosses_;
    }
  }
  if (glyphs.empty()) return;
  buffer_.upload(glyphs.data(), glyphs.size() * sizeof(float), GL_DYNAMIC_DRAW);
  vao_.attribute(0, buffer_, 3, kGlyphFloats, 0, 1);
  vao_.attribute(1, buffer_, 3, kGlyphFloats, 3, 1);
  vao_.attribute(2, buffer_, 3, kGlyphFloats, 6, 1);
  vao_.attribute(3, buffer_, 4, kGlyphFloats, 9, 1);
  vao_.attribute(4, buffer_, 4, kGlyphFloats, 13, 1);
  vao_.attribute(5, buffer_, 1, kGlyphFloats, 17, 1);
}

void FieldLayer::draw(const FrameContext& frame) {
  const int count = crosses_ + constraints_;
  if (!visible || count == 0) return;
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  program_.use();
  program_.set("u_view", frame.camera->view());
  program_.set("u_proj", frame.camera->projection());
  program_.set("u_viewport", glm::vec2(frame.framebuffer));
  program_.set("u_pixel_ratio", frame.pixel_ratio);
  program_.set("u_pull", 0.003f * scene_scale_);
  vao_.bind();
  glDrawArraysInstanced(GL_TRIANGLES, 0, 12, count);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

std::uint64_t FieldLayer::settings_key() const {
  FrameKey key;
  for (bool b : {visible, show_cross, show_constraints}) key.add(b);
  key.add(max_glyphs);
  key.add(glyph_scale);
  key.add(width);
  return key.value();
}

void FieldLayer::ui() {
  ImGui::Checkbox("Cross field", &visible);
  if (!visible) return;
  ImGui::SameLine();
  ImGui::Checkbox("Crosses", &show_cross);
  ImGui::SameLine();
  ImGui::Checkbox("Constraints", &show_constraints);
  ImGui::SliderInt("Max glyphs", &max_glyphs, 500, 60000, "%d", ImGuiSliderFlags_Logarithmic);
  ImGui::SliderFloat("Glyph size", &glyph_scale, 0.25f, 3.0f, "%.2f");
  if (!has_field_) {
    ImGui::TextDisabled("No field yet: Run or Step computes it.");
    return;
  }
  ImGui::TextDisabled("%d crosses, %d constrained faces shown", crosses_, constraints_);
  const struct {
    int kind;
    const char* name;
  } kinds[] = {{0, "curvature"}, {1, "feature"}, {2, "boundary"}, {-1, "released"}};
  for (const auto& k : kinds) {
    const glm::vec3 c = k.kind < 0 ? FieldColors::kReleased : FieldColors::constraint(k.kind);
    ImGui::ColorButton(k.name, ImVec4(c.r, c.g, c.b, 1.0f),
                       ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoPicker,
                       ImVec2(ImGui::GetFontSize(), ImGui::GetFontSize()));
    ImGui::SameLine();
    ImGui::TextUnformatted(k.name);
    if (k.kind < 0 && ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "Constraints released because their cluster contradicts the layout's\n"
          "topology: the field ignores them.");
    ImGui::SameLine();
  }
  ImGui::NewLine();
}

}  // namespace qs::render
