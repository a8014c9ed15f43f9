// The quad layout on the surface: arcs as thick polylines coloured by their u/v label, nodes
// as sphere impostors coloured by valence, pins and selection marked, validation problems
// highlighted (pulsing red vertices, red arcs and nodes).
#pragma once

#include <cstdint>
#include <vector>

#include "render/gl_util.h"
#include "render/layers.h"

namespace qs::render {

//! Colours shared with the UI legend.
struct LayoutColors {
  static glm::vec3 valence(int valence);
  static glm::vec3 label(const std::string& label);
  static constexpr glm::vec3 kSelected{1.0f, 0.86f, 0.15f};
  static constexpr glm::vec3 kProblem{0.95f, 0.10f, 0.10f};
  static constexpr glm::vec3 kPreview{1.0f, 0.60f, 0.10f};
  static constexpr glm::vec3 kPin{0.98f, 0.78f, 0.20f};
  static constexpr glm::vec3 kTrajectory{0.82f, 0.18f, 0.72f};
  static constexpr glm::vec3 kStep{0.05f, 0.85f, 0.95f};
  static constexpr glm::vec3 kQuads{0.13f, 0.30f, 0.70f};
};

class LayoutLayer : public Layer {
 public:
  //! \throw std::runtime_error if the shaders do not compile.
  LayoutLayer();
  const char* name() const override { return "Layout"; }
  void upload(const SceneData& data) override;
  void draw(const FrameContext& frame) override;
  void ui() override;
  std::uint64_t settings_key() const override;
  //! Validation problems pulse while they are shown.
  bool animating() const override { return visible && show_issues && issue_points_ > 0; }
  bool reload(std::string* log);

  bool show_nodes = true;
  bool show_arcs = true;
  bool show_issues = true;
  bool show_trajectories = true;
  bool show_quads = true;
  float node_size = 14.0f;  //!< window pixels
  float arc_width = 4.0f;   //!< window pixels

 private:
  void upload_history(const SceneData& data);
  void upload_quads(const SceneData& data);
  void draw_lines(const FrameContext& frame, GlVertexArray& vao, int count, float pull);
  void draw_points(const FrameContext& frame, GlVertexArray& vao, int count, float scale,
                   float pull);

  GlProgram lines_;
  GlProgram points_;
  GlVertexArray arc_vao_, node_vao_, issue_vao_, traj_vao_, step_vao_, quad_vao_;
  GlBuffer arc_buffer_, node_buffer_, issue_buffer_, traj_buffer_, step_buffer_, quad_buffer_;
  int arc_segments_ = 0, nodes_ = 0, issue_points_ = 0;
  int traj_segments_ = 0, step_points_ = 0, quad_segments_ = 0;
  float scene_scale_ = 1.0f;
  std::vector<std::uint64_t> uploaded_key_, history_key_, quads_key_;
};

}  // namespace qs::render
