// Layout: counts, the selected node or arc, and the validation issues (click one to see it).
#include <algorithm>
#include <cstdio>

#include "app/gui/actions.h"
#include "app/gui/panels.h"
#include "app/gui/ui_text.h"

namespace qs::app {

namespace {

void draw_validation(AppContext& ctx) {
  Editor& editor = ctx.editor;
  const auto& v = editor.doc.validation;
  char header[96];
  std::snprintf(header, sizeof(header), "Validation (%d errors, %d warnings)###validation",
                v.errors(), v.warnings());
  if (!ImGui::CollapsingHeader(header, ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (!editor.doc.mesh) {
    ImGui::TextDisabled("No mesh.");
    return;
  }
  if (v.issues.empty()) {
    ImGui::TextColored(kOkColor, "The layout is valid.");
    return;
  }
  const float height =
      std::min(10.0f, float(v.issues.size()) + 0.5f) * ImGui::GetTextLineHeightWithSpacing();
  ImGui::BeginChild("issues", ImVec2(0, height), true);
  for (int i = 0; i < int(v.issues.size()); ++i) {
    const auto& issue = v.issues[i];
    const bool error = issue.severity == IssueSeverity::Error;
    ImGui::PushID(i);
    ImGui::PushStyleColor(ImGuiCol_Text, error ? kErrorColor : kWarningColor);
    const std::string label = ui_text(std::string(error ? "E " : "W ") + issue.message);
    if (ImGui::Selectable(label.c_str(), editor.highlighted_issue == i))
      focus_vertices(ctx, editor.highlight_issue(i));
    ImGui::PopStyleColor();
    tooltip("[" + issue.code + "] " + issue.message + "\nClick to bring it into view.");
    ImGui::PopID();
  }
  ImGui::EndChild();
}

}  // namespace

void draw_layout_panel(AppContext& ctx) {
  Editor& editor = ctx.editor;
  if (ImGui::CollapsingHeader("Layout", ImGuiTreeNodeFlags_DefaultOpen)) {
    const Layout& layout = editor.doc.editor.layout();
    int irregular = 0, pinned = 0, dangling = 0;
    for (const auto& n : layout.nodes) {
      if (node_valence(layout, n.id) != 4) ++irregular;
      pinned += n.pinned;
    }
    for (const auto& a : layout.arcs) {
      pinned += a.pinned;
      dangling += a.dangling();
    }
    if (ImGui::BeginTable("counts", 2, ImGuiTableFlags_SizingStretchSame)) {
      ImGui::TableNextColumn();
      ImGui::Text("%zu nodes", layout.nodes.size());
      ImGui::TableNextColumn();
      ImGui::Text("%zu arcs", layout.arcs.size());
      ImGui::TableNextColumn();
      ImGui::Text("%d irregular nodes", irregular);
      tooltip("Nodes whose valence is not 4 (the singularities of the quad layout)");
      ImGui::TableNextColumn();
      ImGui::Text("%d pinned", pinned);
      tooltip("Pinned nodes and arcs do not move when the pipeline optimizes the layout");
      ImGui::EndTable();
    }
    if (dangling > 0 || !layout.patches.empty())
      ImGui::TextColored(kDimColor, "%d dangling arcs, %zu patches", dangling,
                         layout.patches.size());
    const int n = layout.node_index(editor.selection.node);
    const int a = layout.arc_index(editor.selection.arc);
    if (editor.selection.node >= 0 && n >= 0) {
      const auto& node = layout.nodes[n];
      ImGui::Text("Node %d: vertex %d, valence %d%s", node.id, node.vertex,
                  node_valence(layout, node.id), editor.node_pinned(node.id) ? ", pinned" : "");
    } else if (editor.selection.arc >= 0 && a >= 0) {
      const auto& arc = layout.arcs[a];
      ImGui::Text("Arc %d: nodes %d -> %s, %zu edges%s", arc.id, arc.from,
                  arc.dangling() ? "boundary" : std::to_string(arc.to).c_str(),
                  arc.path.empty() ? 0 : arc.path.size() - 1,
                  editor.arc_pinned(arc.id) ? ", pinned" : "");
    } else {
      ImGui::TextDisabled("Nothing selected.");
    }
  }
  draw_validation(ctx);
}

}  // namespace qs::app
