// The surface: shaded triangles, optional wireframe, optional uv checker for a
// parameterization, fold-over highlights.
#pragma once

#include <cstdint>

#include "render/gl_util.h"
#include "render/layers.h"

namespace qs::render {

class MeshLayer : public Layer {
 public:
  //! \throw std::runtime_error if the shaders do not compile.
  MeshLayer();
  const char* name() const override { return "Surface"; }
  void upload(const SceneData& data) override;
  void draw(const FrameContext& frame) override;
  void ui() override;
  std::uint64_t settings_key() const override;
  //! Recompiles the shaders (Debug: from disk). Returns false and keeps the old ones on error.
  bool reload(std::string* log);

  bool flat_shading = false;
  bool wireframe = true;
  bool checker = true;  //!< used only when a parameterization exists
  bool show_foldovers = true;
  float checker_scale = 1.0f;
  float wire_width = 1.0f;
  //! Closed meshes: skip the faces that turn away from the camera (they are always hidden
  //! behind the rest of the surface), which halves the rasterizer's work. Open meshes show
  //! both sides regardless.
  bool cull_hidden_faces = true;
  glm::vec3 front_color{0.78f, 0.76f, 0.72f};
  glm::vec3 back_color{0.55f, 0.60f, 0.72f};

  bool has_parameterization() const { return has_uv_; }
  //! True when the uploaded mesh is closed (no boundary), so hidden faces can be culled.
  bool mesh_closed() const { return closed_; }

 private:
  GlProgram program_;
  GlVertexArray vao_;
  GlBuffer geometry_;  // per corner: position, smooth normal
  GlBuffer param_;     // per corner: uv, fold-over flag
  int corners_ = 0;
  bool has_uv_ = false;
  bool closed_ = false;
  bool outward_ = true;  // counter-clockwise faces seen from outside (positive volume)
  std::uint64_t mesh_version_ = ~0ull;
  std::uint64_t param_version_ = ~0ull;
  const void* mesh_ptr_ = nullptr;
};

}  // namespace qs::render
