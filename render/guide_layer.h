// Sketching guides: the field hints (the natural cross field of the bare mesh as faint crosses,
// and hollow rings at its singularities, coloured like the nodes of the valence that belongs
// there) and the mirror plane of symmetric sketching (the curve where it cuts the surface).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/layout/symmetry.h"
#include "render/gl_util.h"
#include "render/layers.h"

namespace qs::render {

//! Colours shared with the UI legend.
struct GuideColors {
  static constexpr glm::vec3 kHintCross{0.30f, 0.36f, 0.52f};
  static constexpr glm::vec3 kMirror{0.10f, 0.72f, 0.95f};
  //! Marker colour of a singularity of index \p quarter_index (+1: valence 3, −1: valence 5).
  static glm::vec3 singularity(int quarter_index);
};

//! The segments where \p plane cuts the faces of \p mesh (one per face crossed; a face with an
//! edge in the plane gives that edge). GL-free.
std::vector<std::array<glm::vec3, 2>> plane_section(const TriMesh& mesh, const MirrorPlane& plane);

class GuideLayer : public Layer {
 public:
  //! \throw std::runtime_error if the shaders do not compile.
  GuideLayer();
  const char* name() const override { return "Guides"; }
  void upload(const SceneData& data) override;
  void draw(const FrameContext& frame) override;
  std::uint64_t settings_key() const override;
  bool reload(std::string* log);

  int max_glyphs = 6000;
  float hint_alpha = 0.6f;    //!< of the hint crosses
  float marker_size = 18.0f;  //!< ring diameter, window pixels
  float mirror_width = 2.5f;  //!< window pixels

  int hint_crosses() const { return crosses_; }
  int hint_markers() const { return markers_; }
  int mirror_segments() const { return segments_; }

 private:
  GlProgram glyphs_, points_, lines_;
  GlVertexArray glyph_vao_, marker_vao_, line_vao_;
  GlBuffer glyph_buffer_, marker_buffer_, line_buffer_;
  int crosses_ = 0, markers_ = 0, segments_ = 0;
  float scene_scale_ = 1.0f;
  std::vector<std::uint64_t> hints_key_, mirror_key_;
};

}  // namespace qs::render
