// The status bar along the bottom: the tool and the last message; the run's step, E and
// fold-overs (or why Run cannot start); unsaved changes and the frame rate.
#include <cmath>

#include "app/gui/panels.h"
#include "app/gui/ui_text.h"

namespace qs::app {

float status_bar_height() {
  return 2.0f * ImGui::GetTextLineHeightWithSpacing() + 10.0f;
}

void draw_status_bar(AppContext& ctx) {
  Editor& editor = ctx.editor;
  const ImGuiIO& io = ImGui::GetIO();
  const float height = status_bar_height();
  ImGui::SetNextWindowPos(ImVec2(0.0f, io.DisplaySize.y - height));
  ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, height));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowRounding, 0.0f);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(10.0f, 5.0f));
  ImGui::PushStyleVar(ImGuiStyleVar_ItemSpacing, ImVec2(8.0f, 2.0f));
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                   ImGuiWindowFlags_NoBringToFrontOnFocus | ImGuiWindowFlags_NoScrollbar);
  // Line 1: the tool and the last message.
  const Tool tool = ctx.tools.tool();
  ImGui::TextColored(kDimColor, "[%s]", tool_name(tool));
  ImGui::SameLine();
  const std::string message = editor.status().empty() ? tool_hint(tool) : editor.status();
  text(message);
  tooltip(message);
  const std::string right = std::string(editor.doc.dirty ? "modified   " : "") +
                            std::to_string(int(std::lround(io.Framerate))) + " fps";
  ImGui::SameLine(io.DisplaySize.x - ImGui::CalcTextSize(right.c_str()).x - 14.0f);
  ImGui::TextColored(kDimColor, "%s", right.c_str());
  tooltip(editor.doc.dirty ? "The layout has unsaved changes (autosaved; Ctrl+S saves)"
                           : "Frames per second of the editor");

  // Line 2: the run (step, E, fold-overs), why it cannot start, or what Run does.
  const std::string summary = editor.job_summary();
  const ResultKind kind = editor.result_kind();
  if (!summary.empty()) {
    const Snapshot* s = editor.result();
    const bool failed = !s;
    const bool folds = s && s->metrics.valid && s->metrics.foldovers > 0;
    const ImVec4 color = failed  ? kErrorColor
                         : folds ? kWarningColor
                         : kind == ResultKind::Kept || (s && s->status == WorkerStatus::Finished)
                             ? kOkColor
                             : ImGui::GetStyle().Colors[ImGuiCol_Text];
    text_colored(color, summary);
    tooltip(s ? summary + "\n" + s->message : summary);
  } else if (const std::string why = editor.run_blocker(); !why.empty()) {
    text_colored(kWarningColor, "Run cannot start: " + why);
    tooltip("Run cannot start: " + why);
  } else {
    text_colored(kDimColor, "Ready: Run optimizes the layout (Pipeline panel)");
  }
  ImGui::End();
  ImGui::PopStyleVar(3);
}

}  // namespace qs::app
