// Quad mesh & export: the quad size, the quad mesh of the shown result (also after Keep
// result), and the export buttons.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <cstdio>

#include "app/gui/panels.h"

namespace qs::app {

void draw_quads_panel(AppContext& ctx) {
  if (!ImGui::CollapsingHeader("Quad mesh & export", ImGuiTreeNodeFlags_DefaultOpen)) return;
  Editor& editor = ctx.editor;
  ImGui::PushID("quads");
  // Quad size in surface units; 0 = automatic (about kDefaultQuadCount quads).
  const float diag = editor.mesh_diagonal();
  float quad_size = float(editor.job.options.quad_size);
  char format[64];
  std::snprintf(format, sizeof(format), quad_size > 0.0f ? "q = %%.4g" : "auto (~%d quads)",
                kDefaultQuadCount);
  ImGui::SetNextItemWidth(-4.5f * ImGui::GetFontSize());
  if (ImGui::SliderFloat("Quad size", &quad_size, 0.0f, 0.2f * diag, format))
    editor.job.options.quad_size = quad_size;
  if (ImGui::IsItemDeactivatedAfterEdit()) editor.job.send_options();
  tooltip(
      "Target quad edge length; the quad mesh is built on the worker at the final step of a run "
      "(0: automatic). Ctrl+click to type a value.");
  const Snapshot* s = editor.result();
  if (s && s->quads) {
    const QuadOverlay& q = *s->quads;
    ImGui::TextColored(kOkColor, "%zu quads, %zu vertices, q = %.4g", q.quads.size(),
                       q.vertices.size(), q.quad_size);
    ImGui::TextColored(q.gridded_patches < q.patches ? kWarningColor : kDimColor,
                       "%d of %d patches gridded", q.gridded_patches, q.patches);
    if (!q.warnings.empty()) {
      std::string all;
      for (const auto& w : q.warnings) all += (all.empty() ? "" : "\n") + w;
      tooltip(all);
    }
  } else {
    ImGui::TextDisabled("Run the pipeline to the end to build the quad mesh.");
  }

  const float button = 4.5f * ImGui::GetFontSize();
  ImGui::SetNextItemWidth(-button);
  const bool enter = ImGui::InputTextWithHint("##dir", "export folder", &editor.exports.dir,
                                              ImGuiInputTextFlags_EnterReturnsTrue);
  tooltip("Folder the exports are written to (created if missing); Enter exports everything");
  const bool can_export = s && s->exports;
  if (!can_export) ImGui::BeginDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Export", ImVec2(-1, 0)) || (enter && can_export))
    editor.export_files(ExportSelection{});
  tooltip("param.obj, layout.json, quads.obj, patches.json, layout_curves.obj");
  if (ImGui::Button("param.obj")) editor.export_files({true, false, false});
  tooltip("The parameterization: the mesh with a uv per corner");
  ImGui::SameLine();
  if (ImGui::Button("layout.json")) editor.export_files({false, true, false});
  tooltip("The optimized layout");
  ImGui::SameLine();
  const bool has_quads = can_export && s->exports->quads;
  if (!has_quads && can_export) ImGui::BeginDisabled();
  if (ImGui::Button("quads.obj")) editor.export_files({false, false, true});
  tooltip("quads.obj, patches.json, layout_curves.obj");
  if (!has_quads && can_export) ImGui::EndDisabled();
  if (!can_export) ImGui::EndDisabled();
  if (!editor.exports.message.empty())
    text_colored(editor.exports.failed ? kErrorColor : kDimColor, editor.exports.message);
  ImGui::PopID();
}

}  // namespace qs::app
