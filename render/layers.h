// Render layers (polyscope's Quantity idea): each layer mirrors some scene data on the GPU,
// re-uploads only when that data's version changed, draws itself and offers an ImGui section.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "core/field/natural_field.h"
#include "core/layout/layout.h"
#include "core/layout/symmetry.h"
#include "core/mesh/mesh.h"
#include "core/pipeline/snapshot.h"
#include "render/camera.h"

namespace qs::render {

//! Everything the layers may show, as non-owning views plus version counters. The app fills
//! it every frame; a layer compares versions with what it uploaded last.
struct SceneData {
  const TriMesh* mesh = nullptr;
  std::uint64_t mesh_version = 0;
  const Layout* layout = nullptr;
  std::uint64_t layout_version = 0;
  //! Parameterization: uv per corner (size 3·#F) and per-face fold-over flags (size #F).
  //! Either may be null/empty.
  const std::vector<std::array<float, 2>>* corner_uv = nullptr;
  const std::vector<char>* face_foldover = nullptr;
  std::uint64_t param_version = 0;
  //! Validation problems to highlight: mesh vertices, node ids and arc ids.
  std::vector<int> issue_vertices;
  std::vector<int> issue_nodes;
  std::vector<int> issue_arcs;
  std::uint64_t issues_version = 0;
  //! Interaction state (ids; -1 for none) and a preview vertex path (arc tool).
  int selected_node = -1;
  int selected_arc = -1;
  int hovered_node = -1;
  int hovered_arc = -1;
  int arc_start_node = -1;
  std::vector<int> preview_path;
  //! Optimistic pin state (node id, pinned) for pins sent to the worker but not yet applied.
  std::vector<std::pair<int, bool>> pin_overrides;
  //! The same for arcs: (arc id, pinned).
  std::vector<std::pair<int, bool>> arc_pin_overrides;
  std::uint64_t interaction_version = 0;
  //! Node positions per streamed step (null: no trajectories) and the step shown (index into
  //! it, -1: none).
  const std::vector<std::shared_ptr<const NodeFrame>>* node_history = nullptr;
  int history_step = -1;
  std::uint64_t history_version = 0;
  //! Quad mesh overlay (null: none).
  const QuadOverlay* quads = nullptr;
  std::uint64_t quads_version = 0;
  //! Cross field of the job's latest step (null: none), for the glyph layer.
  const FieldView* field = nullptr;
  std::uint64_t field_version = 0;
  //! Free-hand stroke being drawn (points on the surface, drawing order); part of the
  //! interaction state (interaction_version).
  std::vector<glm::vec3> stroke_points;
  //! Field hints: the natural cross field of the bare mesh (null: not shown).
  const NaturalField* hints = nullptr;
  std::uint64_t hints_version = 0;
  //! The mirror plane of symmetric sketching (null: off).
  const MirrorPlane* mirror = nullptr;
  std::uint64_t mirror_version = 0;
};

//! Per-frame drawing context.
struct FrameContext {
  const Camera* camera = nullptr;
  glm::ivec2 framebuffer{1, 1};  //!< pixels
  float pixel_ratio = 1.0f;      //!< framebuffer pixels per window pixel
  double time_s = 0.0;           //!< for animations (pulsing highlights)
};

class Layer {
 public:
  virtual ~Layer() = default;
  virtual const char* name() const = 0;
  //! Mirrors \p data on the GPU when its versions changed. Main thread, GL context current.
  virtual void upload(const SceneData& data) = 0;
  virtual void draw(const FrameContext& frame) = 0;
  //! ImGui controls of the layer (inside an already open panel).
  virtual void ui() {}
  //! Hash of every setting that changes what draw() shows (visibility, sizes, colours, modes),
  //! so that a cached scene image is redrawn when one changes (render/scene_cache.h).
  virtual std::uint64_t settings_key() const { return visible ? 1 : 0; }
  //! True while draw() animates by itself (its image changes with FrameContext::time_s).
  virtual bool animating() const { return false; }
  bool visible = true;
};

}  // namespace qs::render
