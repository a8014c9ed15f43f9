// Pipeline: Run / Pause / Step / Stop, why Run cannot start, the live solve while dragging, the
// run's state, Keep result / Discard and the step history (the convergence plot is in the Metrics
// window).
#include <algorithm>
#include <cmath>

#include "app/gui/panels.h"

namespace qs::app {

namespace {

void draw_history(AppContext& ctx, const Snapshot& s) {
  JobControl& job = ctx.editor.job;
  const int steps = int(s.node_history.size());
  if (steps == 0) return;
  ImGui::PushID("history");
  // Scrub through the streamed steps (1 = initial solve); "Live" follows the newest one.
  int shown = std::clamp(job.history_step, 0, steps - 1) + 1;
  ImGui::SetNextItemWidth(-4.5f * ImGui::GetFontSize());
  if (steps == 1) ImGui::BeginDisabled();
  if (ImGui::SliderInt("##step", &shown, 1, std::max(1, steps), "step %d")) {
    job.history_step = std::clamp(shown, 1, steps) - 1;
    job.history_live = job.history_step == steps - 1;
  }
  if (steps == 1) ImGui::EndDisabled();
  tooltip(
      "Scrub through the streamed steps; node trajectories show where each node moved, the "
      "chosen step's nodes are ringed in cyan.");
  ImGui::SameLine();
  if (ImGui::Checkbox("Live", &job.history_live) && job.history_live) job.history_step = steps - 1;
  tooltip("Follow the newest step");
  const int k = std::clamp(job.history_step, 0, steps - 1);
  if (k < int(s.energy_history.size()) && std::isfinite(s.energy_history[k]))
    ImGui::TextColored(kDimColor, "step %d of %d: E = %.6g%s", k + 1, steps, s.energy_history[k],
                       k == 0 ? " (initial solve)" : "");
  ImGui::PopID();
}

}  // namespace

void draw_pipeline_panel(AppContext& ctx) {
  if (!ImGui::CollapsingHeader("Pipeline", ImGuiTreeNodeFlags_DefaultOpen)) return;
  Editor& editor = ctx.editor;
  JobControl& job = editor.job;
  const bool running = job.running();
  const bool paused = job.paused();
  const std::string blocker = running || paused ? std::string() : editor.run_blocker();

  // Run stays clickable when blocked: it says why on the status line.
  if (running) ImGui::BeginDisabled();
  if (ImGui::Button(paused ? "Resume" : "Run")) editor.run();
  tooltip(blocker.empty() ? std::string("Optimize the layout: the initial solve, then node "
                                        "optimization step by step (every step is shown)")
                          : "Cannot run: " + blocker);
  ImGui::SameLine();
  if (ImGui::Button("Step")) editor.step();
  tooltip("One step (of the paused run, or the first of a new one)");
  if (running) ImGui::EndDisabled();
  ImGui::SameLine();
  if (!running) ImGui::BeginDisabled();
  if (ImGui::Button("Pause")) editor.pause();
  tooltip("Pause after the current step (Resume goes on)");
  if (!running) ImGui::EndDisabled();
  ImGui::SameLine();
  if (!running && !paused) ImGui::BeginDisabled();
  if (ImGui::Button("Stop")) editor.stop();
  tooltip("End the run now; the state reached stays on screen: Keep result or Discard it");
  if (!running && !paused) ImGui::EndDisabled();
  if (!blocker.empty()) text_wrapped("Run: " + blocker);  // also in the status bar
  ImGui::Checkbox("Live solve while dragging", &editor.live_solve);
  tooltip(
      "While you drag a node (select tool) and no run is in progress, solve the layout at every "
      "position (as Run without node optimization) and show it: the checker, fold-overs, E and "
      "the structural check follow the drag");
  draw_pipeline_options(ctx);

  const Snapshot* s = editor.result();
  const ResultKind kind = editor.result_kind();
  const SnapshotPtr& latest = job.latest();
  if (!s) {
    if (latest && latest->status == WorkerStatus::Failed && latest->mesh == editor.doc.mesh)
      text_colored(kErrorColor, "Run failed: " + latest->message);
    return;
  }
  const ImVec4 color =
      s->status == WorkerStatus::Finished || kind == ResultKind::Kept ? kOkColor : kDimColor;
  const std::string state = kind == ResultKind::Stopped ? "stopped"
                            : kind == ResultKind::Kept  ? "kept"
                                                        : to_string(s->status);
  ImGui::TextColored(color, "%s", state.c_str());
  ImGui::SameLine();
  ImGui::Text("step %d", s->iteration);
  if (std::isfinite(s->energy)) {
    ImGui::SameLine();
    ImGui::Text("E = %.6g", s->energy);
  }
  if (!s->message.empty()) text_wrapped(s->message);
  if (kind != ResultKind::Kept && !running) {
    if (ImGui::Button("Keep result")) editor.keep_result();
    tooltip(
        "Make the optimized layout the one you edit and save, with its quad mesh and exports "
        "(undo with Ctrl+Z)");
    ImGui::SameLine();
    if (ImGui::Button("Discard")) editor.discard_result();
    tooltip("Drop this result and show the layout you edit");
  }
  draw_history(ctx, *s);
}

}  // namespace qs::app
