#include "app/gui/scene.h"

namespace qs::app {

render::SceneData build_scene(Editor& editor, const Tools& tools) {
  const Document& doc = editor.doc;
  render::SceneData scene;
  scene.mesh = doc.mesh.get();
  scene.mesh_version = doc.mesh_version;
  scene.layout = &doc.editor.layout();
  scene.layout_version = doc.editor.version();
  const Snapshot* result = editor.result();
  if (result) {
    // While a job result is shown, its layout: traced iso-lines, moved nodes.
    scene.layout = result->layout.get();
    scene.layout_version = (std::uint64_t(1) << 62) + result->version;
    scene.corner_uv = &result->corner_uv;
    scene.face_foldover = &result->face_foldover;
    scene.node_history = &result->node_history;
    scene.history_step = editor.job.history_step;
    scene.history_version = result->version;
    scene.quads = result->quads.get();
    scene.quads_version = result->version;
    if (result->field) {
      scene.field = result->field.get();
      scene.field_version = result->version;
    }
  }
  if (doc.editor.dragging()) {
    // The dragged node follows the mouse; the solve shown (live) may lag behind it.
    scene.layout = &doc.editor.layout();
    scene.layout_version = doc.editor.version();
  }
  const std::uint64_t param = editor.job.param_version(doc);
  scene.param_version = param * 2 + (scene.corner_uv ? 1 : 0);
  for (const auto& issue : doc.validation.issues) {
    if (issue.severity != IssueSeverity::Error) continue;
    scene.issue_vertices.insert(scene.issue_vertices.end(), issue.vertices.begin(),
                                issue.vertices.end());
    scene.issue_nodes.insert(scene.issue_nodes.end(), issue.node_ids.begin(), issue.node_ids.end());
    scene.issue_arcs.insert(scene.issue_arcs.end(), issue.arc_ids.begin(), issue.arc_ids.end());
  }
  scene.issues_version = doc.validated_layout_version;
  scene.selected_node = editor.selection.node;
  scene.selected_arc = editor.selection.arc;
  scene.hovered_node = tools.hovered_node();
  scene.hovered_arc = tools.hovered_arc();
  scene.arc_start_node = tools.arc_start_node();
  scene.preview_path = tools.preview_path();
  scene.stroke_points = tools.stroke_points();
  if (editor.job.live_pins()) {
    scene.pin_overrides = editor.job.pending_node_pins();
    scene.arc_pin_overrides = editor.job.pending_arc_pins();
  }
  scene.interaction_version = editor.interaction_version * 1000003ull + tools.version();
  if (editor.field_hints.enabled) {
    scene.hints = editor.field_hints.field();
    scene.hints_version = editor.field_hints.version();
  }
  if (const Mirror* m = editor.mirror()) {
    scene.mirror = &m->plane;
    scene.mirror_version = editor.symmetry.version();
  }
  return scene;
}

}  // namespace qs::app
