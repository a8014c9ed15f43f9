// Metrics: the convergence plot, the quality of the shown result and the time of its last
// step, each with a tooltip saying what it measures and which values are good.
#include <cmath>
#include <cstdio>

#include "app/gui/energy_plot.h"
#include "app/gui/panels.h"
#include "app/gui/ui_text.h"

namespace qs::app {

namespace {

// One "name  value" row; NaN shows as a dash. The tooltip covers the whole row.
void metric_row(const char* name, double value, const char* format, const std::string& tip) {
  ImGui::TableNextRow();
  ImGui::TableNextColumn();
  text(name);
  tooltip(tip);
  ImGui::TableNextColumn();
  if (std::isfinite(value)) {
    char buffer[64];
    std::snprintf(buffer, sizeof(buffer), format, value);
    text(buffer);
  } else {
    ImGui::TextDisabled("-");
  }
  tooltip(tip);
}

}  // namespace

void draw_metrics_panel(AppContext& ctx) {
  const Snapshot* shown = ctx.editor.result();
  if (!shown) return;
  const Snapshot& s = *shown;
  const StepMetrics& m = s.metrics;
  const ImGuiIO& io = ImGui::GetIO();
  // Along the right edge; as wide as the plot (its widest item).
  const float plot_width = 15.0f * ImGui::GetFontSize();
  const float width = plot_width + 2.0f * ImGui::GetStyle().WindowPadding.x;
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width - 10.0f, 10.0f), ImGuiCond_FirstUseEver);
  ImGui::Begin("Metrics", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  const JobControl& job = ctx.editor.job;
  draw_energy_plot(s.energy_history, job.history_live ? -1 : job.history_step, plot_width,
                   7.0f * ImGui::GetFontSize());
  const ImGuiTableFlags flags = ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_RowBg;
  if (ImGui::BeginTable("quality", 2, flags)) {
    metric_row("E_init", s.energy_init, "%.6g",
               "Energy (1) after the initial solve, before any node moved: how far the "
               "parameterization is from the cross field (misalignment and distortion, area "
               "weighted; squared length units, so compare values on the same mesh only).");
    metric_row("E", m.valid ? m.E : s.energy, "%.6g",
               "Energy (1) at the latest step. Lower is better; node optimization lowers it "
               "step by step (rejected steps keep it).");
    if (std::isfinite(s.energy_init) && s.energy_init > 0.0 && std::isfinite(m.E))
      metric_row("E / E_init", m.E / s.energy_init, "%.3f",
                 "What the run has gained: below 1 it lowered the energy of the sketch (0.5: "
                 "half of it). Lower is better.");
    metric_row("E_confor", m.E_confor, "%.4f",
               "Conformality: area-weighted mean of sigma1/sigma2 + sigma2/sigma1 of the "
               "parameterization's faces. 2 is the least, angle-preserving (squares stay "
               "square); lower is better.");
    metric_row("E\xc2\xb0", m.E_angle_deg, "%.2f\xc2\xb0",
               "Alignment: curvature-weighted deviation of the iso-lines from the principal "
               "curvature directions, in degrees from 0 (aligned) to 45 (diagonal); lower is "
               "better. A run with 'No alignment' (Options) shows what the alignment gains.");
    metric_row("E_planar", m.E_planar, "%.4g",
               "Conjugacy of the iso-lines (dimensionless): how far the quads are from planar. "
               "0 is ideal; lower is better.");
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    text("fold-overs");
    const char* fold_tip =
        "Faces whose parametric image is flipped or collapsed. 0 is required for a valid quad "
        "mesh; the run's last step removes them when it can.";
    tooltip(fold_tip);
    ImGui::TableNextColumn();
    if (m.valid)
      ImGui::TextColored(m.foldovers > 0 ? kErrorColor : kOkColor, "%d", m.foldovers);
    else
      ImGui::TextDisabled("-");
    tooltip(fold_tip);
    // Direction constraints in force: few when the layout contradicts the curvature/features.
    if (s.field && !s.field->constraint_faces.empty()) {
      const FieldView& f = *s.field;
      const std::string tip =
          "Faces whose direction constraint (curvature, feature, boundary) is in force. "
          "Constraint clusters that contradict the layout's topology are released (grey bars "
          "in the cross-field view): there the field follows the layout. Most in force is "
          "good." +
          (f.warning.empty() ? std::string() : "\n" + f.warning);
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      text("aligned faces");
      tooltip(tip);
      ImGui::TableNextColumn();
      ImGui::TextColored(f.warning.empty() ? kOkColor : kWarningColor, "%d / %d", f.in_force,
                         int(f.constraint_faces.size()));
      tooltip(tip);
    }
    ImGui::EndTable();
  }
  ImGui::TextDisabled("Timings, step %d (ms)", s.iteration);
  if (ImGui::BeginTable("timings", 2, flags)) {
    metric_row("node opt.", m.nodeopt_ms, "%.1f",
               "Moving the nodes in this step (gradient, traces, trial solves). Empty for the "
               "initial solve.");
    metric_row("field", m.field_ms, "%.1f", "Solving the cross field of the step's layout.");
    metric_row("param.", m.param_ms, "%.1f", "Solving the parameterization (energy (1)).");
    metric_row("extract", m.extract_ms, "%.1f", "Tracing the layout's arcs as iso-lines.");
    metric_row("metrics", m.metrics_ms, "%.1f", "Measuring the values above.");
    metric_row("quad mesh", m.quads_ms, "%.1f",
               "Building the quad mesh (the run's last step only).");
    metric_row("total", m.total_ms, "%.1f",
               "The whole step on the worker thread; the editor stays responsive meanwhile.");
    ImGui::EndTable();
  }
  ImGui::End();
}

}  // namespace qs::app
