// Files: open a mesh or a layout (path fields, the file browser, recent files), save the
// layout, what is open.
#include <imgui.h>
#include <imgui_stdlib.h>

#include "app/gui/actions.h"
#include "app/gui/panels.h"

namespace qs::app {

namespace {

void open_mesh_field(AppContext& ctx) {
  if (ctx.editor.open_mesh(ctx.ui.mesh_field)) ctx.ui.layout_field.clear();
}

void recent_popup(AppContext& ctx) {
  if (!ImGui::BeginPopup("recent")) return;
  Editor& editor = ctx.editor;
  ImGui::TextDisabled("Meshes");
  if (editor.recent.meshes().empty()) ImGui::TextDisabled("  (none)");
  for (const auto& m : editor.recent.meshes())
    if (ImGui::Selectable(m.c_str())) {
      const std::string path = m;  // opening reorders the list
      ImGui::CloseCurrentPopup();
      ctx.ui.mesh_field = path;
      open_mesh_field(ctx);
      break;
    }
  ImGui::Separator();
  ImGui::TextDisabled("Layouts");
  if (editor.recent.layouts().empty()) ImGui::TextDisabled("  (none)");
  for (const auto& l : editor.recent.layouts())
    if (ImGui::Selectable(l.c_str())) {
      const std::string path = l;
      ImGui::CloseCurrentPopup();
      ctx.ui.layout_field = path;
      editor.open_layout(path);
      break;
    }
  ImGui::EndPopup();
}

}  // namespace

void draw_files_panel(AppContext& ctx) {
  if (!ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) return;
  Editor& editor = ctx.editor;
  ImGui::PushID("files");
  const float button = 4.5f * ImGui::GetFontSize();
  ImGui::SetNextItemWidth(-button);
  const bool mesh_enter =
      ImGui::InputTextWithHint("##mesh", "mesh .obj .off .ply .stl", &ctx.ui.mesh_field,
                               ImGuiInputTextFlags_EnterReturnsTrue);
  tooltip("Path of a triangle mesh; Enter opens it");
  ImGui::SameLine();
  if (ImGui::Button("Open##mesh", ImVec2(-1, 0)) || mesh_enter) open_mesh_field(ctx);
  ImGui::SetNextItemWidth(-button);
  const bool layout_enter = ImGui::InputTextWithHint(
      "##layout", "layout .json", &ctx.ui.layout_field, ImGuiInputTextFlags_EnterReturnsTrue);
  tooltip("Path of a layout of the open mesh; Enter opens it");
  ImGui::SameLine();
  if (ImGui::Button("Open##layout", ImVec2(-1, 0)) || layout_enter)
    editor.open_layout(ctx.ui.layout_field);

  if (ImGui::Button("Browse...")) open_dialog(ctx);
  tooltip("Open a mesh or a layout from a folder (Ctrl+O)");
  ImGui::SameLine();
  if (ImGui::Button("Recent...")) ImGui::OpenPopup("recent");
  recent_popup(ctx);
  ImGui::SameLine();
  ImGui::TextDisabled("or drop files here");

  if (!editor.doc.mesh) ImGui::BeginDisabled();
  ImGui::SetNextItemWidth(-button);
  const bool save_enter = ImGui::InputTextWithHint(
      "##save", "save layout as .json", &editor.save_path, ImGuiInputTextFlags_EnterReturnsTrue);
  tooltip("Where Save writes the layout; Enter saves");
  ImGui::SameLine();
  if (ImGui::Button("Save", ImVec2(-1, 0)) || save_enter) editor.save();
  tooltip("Save the layout to the path on the left (Ctrl+S; Ctrl+Shift+S: choose a file)");
  if (ImGui::Button("Save as...")) save_as_dialog(ctx);
  if (!editor.doc.mesh) ImGui::EndDisabled();

  if (editor.doc.mesh) {
    const MeshReport& r = editor.doc.report;
    text_colored(kDimColor, file_name(editor.doc.mesh_path) + ": " + std::to_string(r.vertices) +
                                " vertices, " + std::to_string(r.faces) + " faces, genus " +
                                std::to_string(r.genus) + ", " + std::to_string(r.boundary_loops) +
                                (r.boundary_loops == 1 ? " boundary loop" : " boundary loops"));
    text_colored(kDimColor, "layout: " + file_name(editor.doc.layout_path) +
                                (editor.doc.dirty ? "  (modified, autosaved)" : ""));
    if (!editor.autosave_error.empty())
      text_colored(kWarningColor, "autosave failed: " + editor.autosave_error);
  } else {
    text_colored(kWarningColor, "No mesh is open: Ctrl+O, or drop a mesh file here.");
  }
  ImGui::PopID();
}

}  // namespace qs::app
