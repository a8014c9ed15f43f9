#include "render/scene_cache.h"

#include <algorithm>
#include <cmath>

namespace qs::render {

void FrameKey::add_bytes(const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    hash_ ^= p[i];
    hash_ *= 1099511628211ull;
  }
}

void add_scene(FrameKey& key, const SceneData& scene) {
  key.add(reinterpret_cast<std::uintptr_t>(scene.mesh));
  key.add(scene.mesh_version);
  key.add(reinterpret_cast<std::uintptr_t>(scene.layout));
  key.add(scene.layout_version);
  key.add(reinterpret_cast<std::uintptr_t>(scene.corner_uv));
  key.add(reinterpret_cast<std::uintptr_t>(scene.face_foldover));
  key.add(scene.param_version);
  key.add(scene.issue_vertices);
  key.add(scene.issue_nodes);
  key.add(scene.issue_arcs);
  key.add(scene.issues_version);
  for (int id : {scene.selected_node, scene.selected_arc, scene.hovered_node, scene.hovered_arc,
                 scene.arc_start_node})
    key.add(id);
  key.add(scene.preview_path);
  key.add(scene.pin_overrides.size());
  for (const auto& [node, pinned] : scene.pin_overrides) {
    key.add(node);
    key.add(pinned);
  }
  key.add(scene.arc_pin_overrides.size());
  for (const auto& [arc, pinned] : scene.arc_pin_overrides) {
    key.add(arc);
    key.add(pinned);
  }
  key.add(scene.interaction_version);
  key.add(reinterpret_cast<std::uintptr_t>(scene.node_history));
  key.add(scene.history_step);
  key.add(scene.history_version);
  key.add(reinterpret_cast<std::uintptr_t>(scene.quads));
  key.add(scene.quads_version);
  key.add(reinterpret_cast<std::uintptr_t>(scene.field));
  key.add(scene.field_version);
  key.add(scene.stroke_points);
  key.add(reinterpret_cast<std::uintptr_t>(scene.hints));
  key.add(scene.hints_version);
  key.add(reinterpret_cast<std::uintptr_t>(scene.mirror));
  key.add(scene.mirror_version);
}

SceneCache::~SceneCache() {
  release();
}

void SceneCache::release() {
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  if (color_) glDeleteRenderbuffers(1, &color_);
  if (depth_) glDeleteRenderbuffers(1, &depth_);
  fbo_ = color_ = depth_ = 0;
  width_ = height_ = 0;
  valid_ = false;
}

bool SceneCache::allocate(int width, int height) {
  release();
  // Same sample count as the window, so that the blit is a plain copy (multisampled to
  // multisampled with equal counts) and anti-aliasing stays what the window has.
  GLint samples = 0;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glGetIntegerv(GL_SAMPLES, &samples);
  samples_ = samples;
  glGenRenderbuffers(1, &color_);
  glBindRenderbuffer(GL_RENDERBUFFER, color_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_RGBA8, width, height);
  glGenRenderbuffers(1, &depth_);
  glBindRenderbuffer(GL_RENDERBUFFER, depth_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples_, GL_DEPTH24_STENCIL8, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, 0);
  glGenFramebuffers(1, &fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, depth_);
  const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (!complete) {
    release();
    return false;
  }
  width_ = width;
  height_ = height;
  return true;
}

bool SceneCache::begin(int width, int height, std::uint64_t key, float scale) {
  bound_ = false;
  if (!enabled_) {
    render_width_ = width;
    render_height_ = height;
    return true;
  }
  if (width != width_ || height != height_ || !fbo_) {
    if (!allocate(width, height)) {
      enabled_ = false;  // draw directly from now on
      render_width_ = width;
      render_height_ = height;
      return true;
    }
  }
  if (!(scale > 0.0f && scale < 1.0f) || samples_ > 0) scale = 1.0f;
  const int w = std::max(1, int(std::lround(float(width) * scale)));
  const int h = std::max(1, int(std::lround(float(height) * scale)));
  if (valid_ && key == key_ && w == render_width_ && h == render_height_) return false;
  key_ = key;
  valid_ = true;
  render_width_ = w;
  render_height_ = h;
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  bound_ = true;
  return true;
}

void SceneCache::end() {
  if (bound_) glBindFramebuffer(GL_FRAMEBUFFER, 0);
  bound_ = false;
}

void SceneCache::present() {
  if (!enabled_ || !fbo_ || !valid_) return;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  const bool scaled = render_width_ != width_ || render_height_ != height_;
  glBlitFramebuffer(0, 0, render_width_, render_height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                    scaled ? GL_LINEAR : GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace qs::render
