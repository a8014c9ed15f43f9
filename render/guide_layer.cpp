#include "render/guide_layer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render/field_layer.h"
#include "render/layout_layer.h"
#include "render/scene_cache.h"

namespace qs::render {

namespace {

constexpr int kGlyphFloats = 18;  // center, dir, normal, color0, color1, width
constexpr int kPointFloats = 9;   // position, rgba, size, ring
constexpr int kLineFloats = 11;   // p0, p1, rgba, width

glm::vec3 to_vec3(const Vec3& p) {
  return {float(p[0]), float(p[1]), float(p[2])};
}

}  // namespace

glm::vec3 GuideColors::singularity(int quarter_index) {
  // The valence a node there would have: 4 − index.
  return LayoutColors::valence(4 - quarter_index);
}

std::vector<std::array<glm::vec3, 2>> plane_section(const TriMesh& mesh, const MirrorPlane& plane) {
  std::vector<std::array<glm::vec3, 2>> out;
  for (const auto fh : mesh.faces()) {
    std::array<Vec3, 3> x;
    std::array<double, 3> d;
    int k = 0;
    for (const auto vh : mesh.fv_range(fh)) {
      if (k == 3) break;
      x[k] = mesh.point(vh);
      d[k] = plane.signed_distance(x[k]);
      ++k;
    }
    if (k != 3) continue;
    std::vector<Vec3> cut;
    for (int e = 0; e < 3; ++e) {
      const int a = e, b = (e + 1) % 3;
      if (d[a] == 0.0) {
        cut.push_back(x[a]);
      } else if ((d[a] < 0.0) != (d[b] < 0.0) && d[b] != 0.0) {
        const double t = d[a] / (d[a] - d[b]);
        cut.push_back((1.0 - t) * x[a] + t * x[b]);
      }
    }
    if (cut.size() == 2) out.push_back({to_vec3(cut[0]), to_vec3(cut[1])});
  }
  return out;
}

GuideLayer::GuideLayer() {
  std::string log;
  if (!reload(&log)) throw std::runtime_error("guide shaders: " + log);
}

bool GuideLayer::reload(std::string* log) {
  return glyphs_.build("glyph.vert", "glyph.frag", log) &&
         points_.build("points.vert", "points.frag", log) &&
         lines_.build("lines.vert", "lines.frag", log);
}

void GuideLayer::upload(const SceneData& data) {
  const std::vector<std::uint64_t> hints_key = {reinterpret_cast<std::uintptr_t>(data.mesh),
                                                data.mesh_version,
                                                reinterpret_cast<std::uintptr_t>(data.hints),
                                                data.hints_version,
                                                std::uint64_t(max_glyphs),
                                                std::uint64_t(hint_alpha * 256.0f),
                                                std::uint64_t(marker_size * 16.0f)};
  if (hints_key != hints_key_) {
    hints_key_ = hints_key;
    crosses_ = markers_ = 0;
    const TriMesh* mesh = data.mesh;
    const NaturalField* field = data.hints;
    if (mesh && field && field->direction.size() == mesh->n_faces()) {
      const int nf = int(mesh->n_faces());
      std::vector<glm::vec3> centroid(nf), normal(nf);
      double area = 0.0;
      glm::vec3 lo(1e30f), hi(-1e30f);
      for (const auto fh : mesh->faces()) {
        auto it = mesh->cfv_begin(fh);
        const Vec3 a = mesh->point(*it++), b = mesh->point(*it++), c = mesh->point(*it);
        const Vec3 n = OpenMesh::cross(b - a, c - a);
        const double len = n.norm();
        area += 0.5 * len;
        centroid[fh.idx()] = to_vec3((a + b + c) / 3.0);
        normal[fh.idx()] = len > 0 ? to_vec3(n / len) : glm::vec3(0.0f);
        lo = glm::min(lo, centroid[fh.idx()]);
        hi = glm::max(hi, centroid[fh.idx()]);
      }
      scene_scale_ = std::max(glm::length(hi - lo), 1e-6f);
      float arm = 0.0f;
      const std::vector<int> faces = sample_faces(centroid, area, max_glyphs, &arm);
      std::vector<float> glyphs;
      const glm::vec4 color(GuideColors::kHintCross, hint_alpha);
      for (int f : faces) {
        const glm::vec3 d = to_vec3(field->direction[f]) * arm;
        if (!(glm::length(d) > 0.0f)) continue;
        const glm::vec3& c = centroid[f];
        const glm::vec3& n = normal[f];
        glyphs.insert(glyphs.end(), {c.x, c.y, c.z, d.x, d.y, d.z, n.x, n.y, n.z, color.r, color.g,
                                     color.b, color.a, color.r, color.g, color.b, color.a, 1.5f});
      }
      crosses_ = int(glyphs.size() / kGlyphFloats);
      if (crosses_ > 0) {
        glyph_buffer_.upload(glyphs.data(), glyphs.size() * sizeof(float), GL_DYNAMIC_DRAW);
        for (int k = 0, offset = 0; k < 6; ++k) {
          const int size = k == 5 ? 1 : k >= 3 ? 4 : 3;
          glyph_vao_.attribute(k, glyph_buffer_, size, kGlyphFloats, offset, 1);
          offset += size;
        }
      }
      std::vector<float> points;
      for (const auto& s : field->singularities) {
        if (s.vertex < 0 || s.vertex >= int(mesh->n_vertices())) continue;
        const glm::vec3 p = to_vec3(mesh->point(OpenMesh::VertexHandle(s.vertex)));
        const glm::vec3 c = GuideColors::singularity(s.index);
        points.insert(points.end(), {p.x, p.y, p.z, c.r, c.g, c.b, 0.8f, marker_size, 3.0f});
      }
      markers_ = int(points.size() / kPointFloats);
      if (markers_ > 0) {
        marker_buffer_.upload(points.data(), points.size() * sizeof(float), GL_DYNAMIC_DRAW);
        marker_vao_.attribute(0, marker_buffer_, 3, kPointFloats, 0);
        marker_vao_.attribute(1, marker_buffer_, 4, kPointFloats, 3);
        marker_vao_.attribute(2, marker_buffer_, 1, kPointFloats, 7);
        marker_vao_.attribute(3, marker_buffer_, 1, kPointFloats, 8);
      }
    }
  }
  const std::vector<std::uint64_t> mirror_key = {
      reinterpret_cast<std::uintptr_t>(data.mesh), data.mesh_version,
      reinterpret_cast<std::uintptr_t>(data.mirror), data.mirror_version,
      std::uint64_t(mirror_width * 16.0f)};
  if (mirror_key != mirror_key_) {
    mirror_key_ = mirror_key;
    segments_ = 0;
    if (data.mesh && data.mirror) {
      if (data.mesh->n_vertices() > 0) {
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (const auto vh : data.mesh->vertices()) {
          lo = glm::min(lo, to_vec3(data.mesh->point(vh)));
          hi = glm::max(hi, to_vec3(data.mesh->point(vh)));
        }
        scene_scale_ = std::max(glm::length(hi - lo), 1e-6f);
      }
      std::vector<float> lines;
      const glm::vec3& c = GuideColors::kMirror;
      for (const auto& [a, b] : plane_section(*data.mesh, *data.mirror))
        lines.insert(lines.end(),
                     {a.x, a.y, a.z, b.x, b.y, b.z, c.r, c.g, c.b, 0.9f, mirror_width});
      segments_ = int(lines.size() / kLineFloats);
      if (segments_ > 0) {
        line_buffer_.upload(lines.data(), lines.size() * sizeof(float), GL_DYNAMIC_DRAW);
        line_vao_.attribute(0, line_buffer_, 3, kLineFloats, 0, 1);
        line_vao_.attribute(1, line_buffer_, 3, kLineFloats, 3, 1);
        line_vao_.attribute(2, line_buffer_, 4, kLineFloats, 6, 1);
        line_vao_.attribute(3, line_buffer_, 1, kLineFloats, 10, 1);
      }
    }
  }
}

void GuideLayer::draw(const FrameContext& frame) {
  if (!visible || crosses_ + markers_ + segments_ == 0) return;
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glDepthMask(GL_FALSE);
  const float pull = 0.003f * scene_scale_;
  if (crosses_ > 0) {
    glyphs_.use();
    glyphs_.set("u_view", frame.camera->view());
    glyphs_.set("u_proj", frame.camera->projection());
    glyphs_.set("u_viewport", glm::vec2(frame.framebuffer));
    glyphs_.set("u_pixel_ratio", frame.pixel_ratio);
    glyphs_.set("u_pull", pull);
    glyph_vao_.bind();
    glDrawArraysInstanced(GL_TRIANGLES, 0, 12, crosses_);
  }
  if (segments_ > 0) {
    lines_.use();
    lines_.set("u_view", frame.camera->view());
    lines_.set("u_proj", frame.camera->projection());
    lines_.set("u_viewport", glm::vec2(frame.framebuffer));
    lines_.set("u_pixel_ratio", frame.pixel_ratio);
    lines_.set("u_pull", 0.8f * pull);
    lines_.set("u_width_scale", 1.0f);
    line_vao_.bind();
    glDrawArraysInstanced(GL_TRIANGLES, 0, 6, segments_);
  }
  if (markers_ > 0) {
    glEnable(GL_PROGRAM_POINT_SIZE);
    points_.use();
    points_.set("u_view", frame.camera->view());
    points_.set("u_proj", frame.camera->projection());
    points_.set("u_pixel_ratio", frame.pixel_ratio);
    // A flat ring at a grazing angle would be cut by the surface in front of its centre: pulled
    // towards the eye by 2.5 % of the scene's size (far less than the depth of the far side).
    points_.set("u_pull", 0.025f * scene_scale_);
    points_.set("u_size_scale", 1.0f);
    marker_vao_.bind();
    glDrawArrays(GL_POINTS, 0, markers_);
  }
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

std::uint64_t GuideLayer::settings_key() const {
  FrameKey key;
  key.add(visible);
  key.add(max_glyphs);
  key.add(hint_alpha);
  key.add(marker_size);
  key.add(mirror_width);
  return key.value();
}

}  // namespace qs::render
