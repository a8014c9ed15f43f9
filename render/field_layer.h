// The cross field as glyphs: a short cross per face (subsampled on a uniform grid for large
// meshes) from the job's latest field, and the faces whose direction is constrained (reliable
// curvature directions, features, boundary) as single bars coloured by kind, grey where the
// constraint was released as contradicting the layout.
#pragma once

#include <cstdint>
#include <vector>

#include "render/gl_util.h"
#include "render/layers.h"

namespace qs::render {

//! Colours shared with the UI legend.
struct FieldColors {
  static constexpr glm::vec3 kCross{0.40f, 0.12f, 0.62f};
  static constexpr glm::vec3 kCurvature{0.95f, 0.55f, 0.05f};
  static constexpr glm::vec3 kFeature{0.05f, 0.75f, 0.85f};
  static constexpr glm::vec3 kBoundary{0.85f, 0.15f, 0.65f};
  //! A constraint released because its cluster contradicts the layout (the field ignores it).
  static constexpr glm::vec3 kReleased{0.55f, 0.55f, 0.55f};
  //! Colour of a ConstraintKind value (0 curvature, 1 feature, 2 boundary).
  static glm::vec3 constraint(int kind);
};

//! Faces to draw glyphs on: every face when #F <= max_glyphs, otherwise one face per cell of a
//! uniform grid whose cells hold about #F / max_glyphs faces (so glyphs stay evenly spread).
//! Also returns the arm length (world units) that suits the spacing. \p centroids: per face.
std::vector<int> sample_faces(const std::vector<glm::vec3>& centroids, double total_area,
                              int max_glyphs, float* arm_length);

class FieldLayer : public Layer {
 public:
  //! \throw std::runtime_error if the shaders do not compile.
  FieldLayer();
  const char* name() const override { return "Cross field"; }
  void upload(const SceneData& data) override;
  void draw(const FrameContext& frame) override;
  void ui() override;
  std::uint64_t settings_key() const override;
  bool reload(std::string* log);

  bool show_cross = true;
  bool show_constraints = true;
  int max_glyphs = 12000;
  float glyph_scale = 1.0f;  //!< multiplies the automatic arm length
  float width = 1.6f;        //!< window pixels

  //! Number of glyph instances uploaded (crosses + constraint bars), for tests and the UI.
  int crosses() const { return crosses_; }
  int constraint_bars() const { return constraints_; }
  bool has_field() const { return has_field_; }

 private:
  GlProgram program_;
  GlVertexArray vao_;
  GlBuffer buffer_;
  int crosses_ = 0;
  int constraints_ = 0;
  bool has_field_ = false;
  float scene_scale_ = 1.0f;
  std::vector<std::uint64_t> key_;
};

}  // namespace qs::render
