// The sketching tools and the mouse (GL-free): picking nodes, arcs and the surface under the
// cursor, the tools' clicks and drags, free-hand strokes, edge loops, and the camera drags
// (orbit, pan, zoom). Acts on the Editor (mirrored with its symmetry on: sketch_edits.h);
// reads the camera and the surface picker of the 3D view.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/gui/editor.h"
#include "render/camera.h"
#include "render/picking.h"

namespace qs::app {

enum class Tool {
  Select,
  PlaceNode,
  DrawArc,
  Split,
  Delete,
  Pin,
  Stroke,
  Dangling,
  InsertLoop,
  RemoveLoop
};
constexpr int kToolCount = 10;
//! The key of a tool ('1'..'9', '0' for the tenth).
char tool_key(Tool tool);

const char* tool_name(Tool tool);
//! One sentence on how to use the tool.
const char* tool_hint(Tool tool);
//! Script name of a tool ("select", "place_node", "draw_arc", "split", "delete", "pin",
//! "stroke", "dangling", "insert_loop", "remove_loop"); false when \p name is none of them.
bool tool_from_name(const std::string& name, Tool& tool);

//! One frame of mouse input, in window pixels (y down).
struct MouseInput {
  glm::vec2 position{-1.0f};
  bool position_valid = true;
  bool over_ui = false;  //!< the cursor is over a panel (clicks and the wheel go to it)
  bool left_clicked = false;
  bool left_down = false;
  bool pan_clicked = false;  //!< right or middle button pressed
  bool pan_down = false;
  float wheel = 0.0f;
  glm::vec2 delta{0.0f};
};

class Tools {
 public:
  Tool tool() const { return tool_; }
  void set_tool(Tool tool);

  //! Routes one frame of mouse input: clicks and drags of the current tool, camera drags.
  void mouse(const MouseInput& in, Editor& editor, render::Camera& camera,
             const render::SurfacePicker& picker);
  //! The current tool's click at screen point \p at.
  void click(const glm::vec2& at, Editor& editor, const render::Camera& camera,
             const render::SurfacePicker& picker);
  //! Esc: cancels a drag or stroke, the arc being drawn and the selection.
  void escape(Editor& editor);
  //! A stroke-tool stroke through the screen positions of mesh \p vertices (the first must
  //! hold a visible node), sampled like a mouse drag. False with \p error when it cannot start.
  bool stroke_through_vertices(const std::vector<int>& vertices, Editor& editor,
                               const render::Camera& camera, const render::SurfacePicker& picker,
                               std::string* error);
  //! Forgets state that refers to nodes that no longer exist (after undo, open, ...).
  void sync(const Editor& editor);

  // What the scene shows of the tools (ids, -1: none).
  int hovered_node() const { return hovered_node_; }
  int hovered_arc() const { return hovered_arc_; }
  int arc_start_node() const { return arc_start_node_; }
  const std::vector<int>& preview_path() const { return preview_path_; }
  const std::vector<glm::vec3>& stroke_points() const { return stroke_points_; }
  //! Changes whenever any of the above changes.
  std::uint64_t version() const { return version_; }
  //! True while a drag of the mouse is in progress (camera or tool).
  bool dragging() const { return drag_ != Drag::None && drag_ != Drag::Pending; }

  // Picking in the layout on screen (the shown result's, else the edited one), window
  // pixels; nodes and arcs hidden behind the surface are not picked.
  int pick_node(const glm::vec2& at, float radius_px, const Editor& editor,
                const render::Camera& camera, const render::SurfacePicker& picker) const;
  int pick_arc(const glm::vec2& at, float radius_px, const Editor& editor,
               const render::Camera& camera, const render::SurfacePicker& picker) const;

 private:
  enum class Drag { None, Pending, Orbit, Pan, MoveNode, Stroke };
  void hover(const glm::vec2& at, Editor& editor, const render::Camera& camera,
             const render::SurfacePicker& picker);
  void begin_stroke(int node, const glm::vec2& at, Editor& editor, const render::Camera& camera,
                    const render::SurfacePicker& picker);
  void add_stroke_sample(const glm::vec2& at, const Editor& editor, const render::Camera& camera,
                         const render::SurfacePicker& picker);
  void end_stroke(const glm::vec2& at, Editor& editor, const render::Camera& camera,
                  const render::SurfacePicker& picker);
  void cancel_stroke();
  //! Dangling tool: the boundary vertex a click at surface point \p hit would end on.
  int dangling_target(const render::SurfaceHit& hit, const Editor& editor) const;

  Tool tool_ = Tool::Select;
  Drag drag_ = Drag::None;
  int hovered_node_ = -1;
  int hovered_arc_ = -1;
  int arc_start_node_ = -1;
  std::vector<int> preview_path_;
  int preview_target_vertex_ = -1;
  // Free-hand stroke in progress: start node, samples on the surface, their 3D points.
  int stroke_node_ = -1;
  std::vector<SurfacePoint> stroke_samples_;
  std::vector<glm::vec3> stroke_points_;
  glm::vec2 stroke_last_{-1.0f};
  glm::vec2 press_{0.0f};
  glm::vec2 last_{-1.0f};
  int press_node_ = -1;
  std::uint64_t version_ = 0;
};

}  // namespace qs::app
