// Sketch: the tools, undo / redo, the mouse and keyboard reference.
#include <cstdio>

#include "app/gui/panels.h"

namespace qs::app {

namespace {

// Mirrored sketching: on / off, the plane's axis (or fitted), and its residual.
void draw_symmetry(AppContext& ctx) {
  SymmetryState& symmetry = ctx.editor.symmetry;
  bool on = symmetry.enabled();
  if (ImGui::Checkbox("Mirror", &on)) {
    if (on)
      symmetry.enable(symmetry.axis());
    else
      symmetry.disable();
  }
  tooltip(
      "Symmetric sketching: nodes and arcs drawn on one side appear mirrored on the other; "
      "moves, splits, deletes, pins and edge loops are mirrored too; a node placed near the "
      "plane goes onto it and stays on it. Run keeps the layout symmetric: mirror pairs move "
      "as mirror images, nodes on the plane stay in it.");
  ImGui::SameLine();
  int axis = int(symmetry.axis());
  ImGui::SetNextItemWidth(9.0f * ImGui::GetFontSize());
  if (ImGui::Combo("Plane", &axis, "x (centre)\0y (centre)\0z (centre)\0fitted\0"))
    symmetry.enable(SymmetryAxis(axis));
  tooltip(
      "x / y / z: the plane x, y or z = const through the centre of the mesh's bounding box. "
      "Fitted: the plane that maps the mesh onto itself best (principal axes refined by "
      "closest-point iterations); the residual says how symmetric the mesh is.");
  if (const std::string d = symmetry.description(); !d.empty()) {
    ImGui::PushTextWrapPos(0.0f);  // the residual must not be cut off by the panel's edge
    text_colored(symmetry.error().empty() ? kDimColor : kErrorColor, d);
    ImGui::PopTextWrapPos();
  }
}

}  // namespace

void draw_sketch_panel(AppContext& ctx) {
  if (!ImGui::CollapsingHeader("Sketch", ImGuiTreeNodeFlags_DefaultOpen)) return;
  Editor& editor = ctx.editor;
  for (int i = 0; i < kToolCount; ++i) {
    const Tool t = static_cast<Tool>(i);
    char label[64];
    std::snprintf(label, sizeof(label), "%c %s", tool_key(t), tool_name(t));
    if (i % 2 == 1) ImGui::SameLine(11.0f * ImGui::GetFontSize());
    if (ImGui::RadioButton(label, ctx.tools.tool() == t)) ctx.tools.set_tool(t);
    tooltip(std::string(tool_hint(t)) + " (key " + tool_key(t) + ")");
  }
  text_wrapped(tool_hint(ctx.tools.tool()));
  const LayoutEditor& layout_editor = editor.doc.editor;
  if (!layout_editor.can_undo()) ImGui::BeginDisabled();
  if (ImGui::Button("Undo")) {
    editor.undo();
    ctx.tools.sync(editor);
  }
  tooltip("Ctrl+Z");
  if (!layout_editor.can_undo()) ImGui::EndDisabled();
  ImGui::SameLine();
  if (!layout_editor.can_redo()) ImGui::BeginDisabled();
  if (ImGui::Button("Redo")) {
    editor.redo();
    ctx.tools.sync(editor);
  }
  tooltip("Ctrl+Shift+Z or Ctrl+Y");
  if (!layout_editor.can_redo()) ImGui::EndDisabled();
  ImGui::SameLine();
  if (layout_editor.can_undo()) text_colored(kDimColor, "last: " + layout_editor.undo_label());
  help_marker(
      "Mouse: left drag turns the view (turntable; trackball in the View panel), right or "
      "middle drag pans, the wheel zooms.\n"
      "Keys: 1-9, 0 tools, Del delete, P pin, Esc cancel, Ctrl+Z undo, Ctrl+Shift+Z / Ctrl+Y "
      "redo, Ctrl+O open, Ctrl+S save, Ctrl+Shift+S save as.\n"
      "View (numpad, as in Blender): 1 front, 3 right, 7 top (with Ctrl: back, left, bottom), "
      "5 perspective / orthographic, 4 6 8 2 turn by 15 degrees, . or F frame the selection, "
      "Home frame all, R reset.");
  draw_symmetry(ctx);
}

}  // namespace qs::app
