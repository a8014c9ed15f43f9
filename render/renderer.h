// The editor's drawing: every OpenGL call of the application goes through here (the scene
// layers, the cached scene image, the ImGui draw data, read-backs and GPU waits). Main thread
// only, with the window's GL context current.
#pragma once

#include <chrono>
#include <memory>
#include <string>

#include "render/background.h"
#include "render/camera.h"
#include "render/field_layer.h"
#include "render/guide_layer.h"
#include "render/layers.h"
#include "render/layout_layer.h"
#include "render/mesh_layer.h"
#include "render/scene_cache.h"

namespace qs::render {

struct RendererOptions {
  bool show_field = false;  //!< the cross-field glyph layer starts visible
  bool scene_cache = true;  //!< reuse the last scene image while nothing it shows changed
  //! Resolution scale of the scene while the camera moves (0.25-1; 1: always full size).
  float motion_resolution = 0.5f;
  bool profile = false;  //!< per-stage frame timings (waits for the GPU between stages)
};

//! Stages of a frame timed by the profile (RendererOptions::profile).
enum ProfileStage {
  kStageUi,  //!< events and building the UI (before render)
  kStageUpload,
  kStageClear,
  kStageSurface,
  kStageField,
  kStageLayout,
  kStageBlit,
  kStageImgui,
  kStageSwap,
  kProfileStages
};

//! Name of the current context's renderer (GL_RENDERER), e.g. "llvmpipe (LLVM 15.0.6, 256
//! bits)"; "" without a context.
std::string current_renderer_name();
//! True when \p renderer names a software rasterizer (llvmpipe, softpipe, swrast).
bool is_software_renderer(const std::string& renderer);

class Renderer {
 public:
  Renderer();
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  //! Creates the layers and ImGui's OpenGL backend (after ImGui's context exists).
  //! \throw std::runtime_error when a shader does not compile.
  void init(const RendererOptions& options);
  //! Deletes every GL object and shuts the ImGui backend down (context still current).
  void shutdown();

  //! Draws the scene (or the cached image of it) into the window framebuffer of
  //! \p framebuffer pixels; \p camera sees the window in logical pixels. Returns true when the
  //! scene was rendered, false when the cached image was reused.
  bool draw_scene(const SceneData& scene, const Camera& camera, const glm::ivec2& framebuffer,
                  double time_s);
  //! Before ImGui::NewFrame: the backend's per-frame work (fonts, shaders on first use).
  void begin_ui_frame();
  //! Draws ImGui's current draw data over the scene.
  void draw_ui();

  //! Waits until the GPU has finished the frame (llvmpipe renders on the CPU: frame timings).
  void finish();
  //! Writes the back buffer (\p framebuffer pixels) as PNG; false with \p error on failure.
  bool save_png(const std::string& path, const glm::ivec2& framebuffer, std::string* error);
  //! Recompiles every shader (Debug: from disk); the log collects compiler errors.
  void reload_shaders(std::string* log);

  // Profile (RendererOptions::profile): the time since the previous mark is added to \p stage
  // after waiting for the GPU. begin_profile_frame starts a frame's first stage.
  void begin_profile_frame(std::chrono::steady_clock::time_point start);
  void profile_mark(int stage);
  void clear_profile();
  //! "frame profile (ms per frame, ...): events+ui X; upload Y; ..." or "" without frames.
  std::string profile_summary() const;
  void count_profile_frame() { profile_frames_ += options_.profile ? 1 : 0; }

  MeshLayer& mesh_layer() { return *mesh_layer_; }
  LayoutLayer& layout_layer() { return *layout_layer_; }
  FieldLayer& field_layer() { return *field_layer_; }
  GuideLayer& guide_layer() { return *guide_layer_; }
  const FieldLayer* field_layer_if() const { return field_layer_.get(); }
  SceneCache& cache() { return scene_cache_; }
  const RendererOptions& options() const { return options_; }

 private:
  RendererOptions options_;
  bool ready_ = false;
  std::unique_ptr<Background> background_;
  std::unique_ptr<MeshLayer> mesh_layer_;
  std::unique_ptr<LayoutLayer> layout_layer_;
  std::unique_ptr<FieldLayer> field_layer_;
  std::unique_ptr<GuideLayer> guide_layer_;
  SceneCache scene_cache_;
  std::uint64_t last_camera_key_ = 0;
  double profile_ms_[kProfileStages] = {};
  int profile_frames_ = 0;
  std::chrono::steady_clock::time_point profile_last_;
};

}  // namespace qs::render
