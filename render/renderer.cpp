#include "render/renderer.h"

#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <algorithm>
#include <cstdio>

#include "render/gl_util.h"
#include "render/screenshot.h"

namespace qs::render {

std::string current_renderer_name() {
  const char* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  return name ? name : "";
}

bool is_software_renderer(const std::string& renderer) {
  return renderer.find("llvmpipe") != std::string::npos ||
         renderer.find("softpipe") != std::string::npos ||
         renderer.find("swrast") != std::string::npos;
}

Renderer::Renderer() = default;

Renderer::~Renderer() {
  shutdown();
}

void Renderer::init(const RendererOptions& options) {
  options_ = options;
  ImGui_ImplOpenGL3_Init("#version 330 core");
  ready_ = true;
  background_ = std::make_unique<Background>();
  background_->init();
  mesh_layer_ = std::make_unique<MeshLayer>();
  layout_layer_ = std::make_unique<LayoutLayer>();
  field_layer_ = std::make_unique<FieldLayer>();
  field_layer_->visible = options.show_field;
  guide_layer_ = std::make_unique<GuideLayer>();
  scene_cache_.set_enabled(options.scene_cache);
}

void Renderer::shutdown() {
  if (!ready_) return;
  mesh_layer_.reset();
  layout_layer_.reset();
  field_layer_.reset();
  guide_layer_.reset();
  background_.reset();
  scene_cache_.release();
  ImGui_ImplOpenGL3_Shutdown();
  ready_ = false;
}

void Renderer::begin_ui_frame() {
  ImGui_ImplOpenGL3_NewFrame();
}

void Renderer::draw_ui() {
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void Renderer::finish() {
  glFinish();
}

bool Renderer::save_png(const std::string& path, const glm::ivec2& framebuffer,
                        std::string* error) {
  return save_framebuffer_png(path, framebuffer.x, framebuffer.y, error);
}

void Renderer::reload_shaders(std::string* log) {
  mesh_layer_->reload(log);
  layout_layer_->reload(log);
  field_layer_->reload(log);
  guide_layer_->reload(log);
  scene_cache_.invalidate();  // the cached image was drawn with the old shaders
}

void Renderer::begin_profile_frame(std::chrono::steady_clock::time_point start) {
  profile_last_ = start;
}

void Renderer::profile_mark(int stage) {
  if (!options_.profile) return;
  glFinish();
  const auto now = std::chrono::steady_clock::now();
  profile_ms_[stage] += std::chrono::duration<double, std::milli>(now - profile_last_).count();
  profile_last_ = now;
}

void Renderer::clear_profile() {
  std::fill(std::begin(profile_ms_), std::end(profile_ms_), 0.0);
  profile_frames_ = 0;
}

std::string Renderer::profile_summary() const {
  if (!options_.profile || profile_frames_ == 0) return {};
  static const char* kNames[kProfileStages] = {"events+ui", "upload", "clear+background",
                                               "surface",   "field",  "layout",
                                               "blit",      "imgui",  "swap"};
  std::string out = "frame profile (ms per frame, glFinish between stages, " +
                    std::to_string(profile_frames_) + " frames):";
  for (int i = 0; i < kProfileStages; ++i) {
    char part[64];
    std::snprintf(part, sizeof(part), " %s %.2f%s", kNames[i], profile_ms_[i] / profile_frames_,
                  i + 1 < kProfileStages ? ";" : "");
    out += part;
  }
  return out;
}

bool Renderer::draw_scene(const SceneData& scene, const Camera& camera,
                          const glm::ivec2& framebuffer, double time_s) {
  FrameContext frame;
  frame.camera = &camera;
  frame.framebuffer = framebuffer;
  frame.pixel_ratio = float(framebuffer.x) / std::max(1.0f, camera.viewport().x);
  frame.time_s = time_s;
  Layer* const layers[] = {mesh_layer_.get(), field_layer_.get(), guide_layer_.get(),
                           layout_layer_.get()};
  // The profile stage each layer's drawing counts to (the guides with the field).
  const int stages[] = {kStageSurface, kStageField, kStageField, kStageLayout};
  // Uploads happen only when a version changed (a new snapshot, an edit).
  for (Layer* layer : layers) layer->upload(scene);
  profile_mark(kStageUpload);

  // Everything the scene image depends on; an unchanged key reuses the cached image.
  FrameKey key;
  key.add(camera.view());
  key.add(camera.projection());
  key.add(frame.framebuffer);
  key.add(frame.pixel_ratio);
  key.add(background_->top);
  key.add(background_->bottom);
  add_scene(key, scene);
  for (Layer* layer : layers) {
    key.add(layer->settings_key());
    if (layer->visible && layer->animating()) key.add(frame.time_s);
  }
  // While the camera moves, a cheaper image at a fraction of the resolution; the first still
  // frame renders at full resolution again.
  FrameKey camera_key;
  camera_key.add(camera.view());
  camera_key.add(camera.projection());
  camera_key.add(frame.framebuffer);
  const bool moving = camera_key.value() != last_camera_key_;
  last_camera_key_ = camera_key.value();
  // A full-resolution moving frame is drawn straight into the window: the next frame needs a
  // new image anyway, so caching it would only add a copy.
  const bool direct = moving && options_.motion_resolution >= 1.0f;
  bool render = true;
  if (direct)
    scene_cache_.invalidate();
  else
    render = scene_cache_.begin(framebuffer.x, framebuffer.y, key.value(),
                                moving ? options_.motion_resolution : 1.0f);
  if (render) {
    if (!direct) {
      frame.framebuffer = {scene_cache_.render_width(), scene_cache_.render_height()};
      frame.pixel_ratio *= float(frame.framebuffer.x) / float(std::max(1, framebuffer.x));
    }
    glViewport(0, 0, frame.framebuffer.x, frame.framebuffer.y);
    // Clear only the part drawn (a reduced-resolution image uses a corner of the buffer).
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, 0, frame.framebuffer.x, frame.framebuffer.y);
    glClearColor(0.3f, 0.31f, 0.33f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_SCISSOR_TEST);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glEnable(GL_MULTISAMPLE);
    background_->draw();
    profile_mark(kStageClear);
    for (int i = 0; i < 4; ++i) {
      layers[i]->draw(frame);
      profile_mark(stages[i]);
    }
    if (!direct) scene_cache_.end();
  }
  glViewport(0, 0, framebuffer.x, framebuffer.y);
  if (!direct) scene_cache_.present();
  profile_mark(kStageBlit);
  return render;
}

}  // namespace qs::render
