// Windows that ask for attention: the problems (file errors) and the autosave offer.
#include <algorithm>
#include <filesystem>

#include "app/gui/panels.h"

namespace qs::app {

void draw_error_panel(AppContext& ctx) {
  Editor& editor = ctx.editor;
  if (editor.errors().empty()) return;
  const ImGuiIO& io = ImGui::GetIO();
  const float width = std::min(36.0f * ImGui::GetFontSize(), io.DisplaySize.x - 40.0f);
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f + 6.0f * ImGui::GetFontSize(), 12.0f),
                          ImGuiCond_Always, ImVec2(0.5f, 0.0f));
  ImGui::SetNextWindowSize(ImVec2(width, 0.0f), ImGuiCond_Always);
  ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.22f, 0.08f, 0.08f, 0.95f));
  ImGui::Begin("Problems", nullptr,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings);
  for (const auto& e : editor.errors()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kErrorColor);
    text_wrapped(e);
    ImGui::PopStyleColor();
    ImGui::Separator();
  }
  if (ImGui::Button("Dismiss")) editor.clear_errors();
  ImGui::End();
  ImGui::PopStyleColor();
}

void draw_autosave_prompt(AppContext& ctx) {
  Editor& editor = ctx.editor;
  if (!editor.autosave_offer) return;
  const AutosaveOffer& offer = *editor.autosave_offer;
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f, io.DisplaySize.y * 0.4f),
                          ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::Begin("Unsaved edits found", nullptr,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoSavedSettings);
  text("An earlier session left unsaved edits (autosaved " + offer.saved_at + "):");
  text("  mesh    " + file_name(offer.mesh_path));
  text("  layout  " +
       (offer.layout_path.empty() ? std::string("(new layout)") : file_name(offer.layout_path)));
  ImGui::TextDisabled("%s", offer.mesh_path.c_str());
  const bool other_mesh =
      editor.doc.mesh_path.empty() || std::filesystem::path(editor.doc.mesh_path).filename() !=
                                          std::filesystem::path(offer.mesh_path).filename();
  if (ImGui::Button("Restore")) editor.restore_autosave();
  tooltip(other_mesh ? "Open " + file_name(offer.mesh_path) + " with the autosaved layout"
                     : "Replace the open layout with the autosaved one (Ctrl+Z does not undo "
                       "this; the open file is unchanged)");
  ImGui::SameLine();
  if (ImGui::Button("Discard")) editor.discard_autosave();
  tooltip("Keep working without it (it is kept as autosave.previous.layout.json)");
  ImGui::End();
}

}  // namespace qs::app
