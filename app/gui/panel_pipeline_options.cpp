// Pipeline options (collapsed by default): the settings of the next Run / Step, as the
// command line's `quadsketch-cli optimize` flags.
#include <algorithm>
#include <optional>

#include "app/gui/panels.h"
#include "app/gui/ui_text.h"

namespace qs::app {

namespace {

// A setting that is on, off, or left to the run ("Auto": off, retried with it when the
// fold-over removal fails, as the command line does without the flag).
void tri_state(const char* label, std::optional<bool>& value) {
  const char* names[] = {"Auto", "On", "Off"};
  int index = !value ? 0 : *value ? 1 : 2;
  if (ImGui::Combo(label, &index, names, 3))
    value = index == 0 ? std::nullopt : std::optional<bool>(index == 1);
}

}  // namespace

void draw_pipeline_options(AppContext& ctx) {
  // Collapsed by default: the defaults suit most layouts.
  if (!ImGui::TreeNodeEx("Options")) return;
  WorkerOptions& o = ctx.editor.job.options;
  ImGui::PushItemWidth(-7.5f * ImGui::GetFontSize());
  bool no_align = !o.align;
  if (ImGui::Checkbox("No alignment (--no-align)", &no_align)) o.align = !no_align;
  tooltip(
      "Ignore the principal curvature directions: the alignment-oblivious "
      "baseline (features and the boundary still constrain the field)");
  float sharp = float(o.sharp_angle_deg);
  if (ImGui::SliderFloat("Sharp angle", &sharp, 1.0f, 180.0f, ui_text("%.0f\xc2\xb0").c_str()))
    o.sharp_angle_deg = sharp;
  tooltip("Edges with a dihedral angle above this are features (--sharp-angle)");
  if (!o.align) ImGui::BeginDisabled();
  ImGui::SliderInt("Cluster size", &o.max_cluster_faces, 0, 100,
                   o.max_cluster_faces ? "%d" : "off");
  tooltip(
      "Split the curvature constraints into clusters of at most this many faces, released one "
      "by one where they contradict the layout (0: whole connected regions, which a layout "
      "that crosses them mostly releases). 10 (the default) keeps far more in force and lowers "
      "the angle error on most layouts (--max-cluster-faces)");
  if (!o.align) ImGui::EndDisabled();
  ImGui::Checkbox("Wrap free holes", &o.wrap_free_holes);
  tooltip(
      "Holes that only dangling arcs run into: the iso-lines wrap around them (an O-grid, for "
      "many arcs radiating into a hole) instead of running on across them as around a "
      "regular point (--wrap-free-holes)");
  float anisotropy = float(o.anisotropy);
  if (ImGui::SliderFloat("Anisotropy", &anisotropy, 1.0f, 100.0f, "%.1f",
                         ImGuiSliderFlags_Logarithmic))
    o.anisotropy = anisotropy;
  tooltip("How much more misalignment costs than scale in energy (1) (1: isotropic)");
  tri_state("Sizing field", o.sizing);
  tooltip(
      "Scale the targets by the curl-reducing sizing field (paper \xc2\xa7"
      "5.3): patches may "
      "vary in size, which lowers E (on the paper's models by 6-64 %) and can unfold a "
      "layout, but the node optimization takes longer and lands in other optima (--sizing). "
      "Auto: off, and the run tries again with it when fold-overs remain");
  ImGui::Checkbox("Node optimization", &o.node_optimization);
  if (!o.node_optimization) ImGui::BeginDisabled();
  ImGui::SliderInt("Descent steps", &o.descent_steps, 0, 200, "%d", ImGuiSliderFlags_Logarithmic);
  tooltip(
      "Gradient steps before the first hop sweep; each sweep that moves nodes allows more "
      "(--steps)");
  ImGui::SliderInt("Max steps", &o.max_steps, 1, 1000, "%d", ImGuiSliderFlags_Logarithmic);
  tooltip(
      "Steps of a run at most: the initial solve, descent steps and hop sweeps; the last one "
      "also removes fold-overs");
  ImGui::Checkbox("Keep sharp edges", &o.keep_sharp_edges);
  tooltip(
      "Nodes on sharp edges slide along them and no vertex on a sharp edge is moved: sharp "
      "edges keep their shape, at a higher E (--keep-sharp-edges)");
  tri_state("Keep nodes apart", o.keep_nodes_apart);
  tooltip(
      "No node moves onto a vertex next to another node (no two nodes on one triangle): for "
      "dense layouts with a few edges per patch side, where crowded nodes keep fold-overs "
      "(--keep-nodes-apart). Auto: off, and the run tries again with it when fold-overs remain "
      "or the fold-over removal falls back");
  ImGui::Checkbox("Untangle fold-overs", &o.untangle);
  tooltip(
      "Where the orientation constraints leave fold-overs, untangle the parameterization: a "
      "barrier on each triangle's area, with the same layout constraints (off: "
      "--no-untangle)");
  ImGui::Checkbox("Separate crowded nodes", &o.separate_nodes);
  tooltip(
      "Before the node optimization, nodes sketched next to another node (on its 1-ring) "
      "move apart, at most 2 edge rings, keeping every patch (--separate-nodes; not with "
      "Mirror on, whose Run keeps the layout symmetric)");
  float alpha = float(o.alpha);
  if (ImGui::SliderFloat("alpha (damping)", &alpha, 0.05f, 1.0f, "%.2f")) o.alpha = alpha;
  tooltip("Initial damping factor of the node steps; halved after a rejected step");
  if (!o.node_optimization) ImGui::EndDisabled();
  if (o.node_optimization) ImGui::BeginDisabled();
  ImGui::Checkbox("Remove fold-overs", &o.remove_foldovers);
  tooltip(
      "Without node optimization: when the parameterization of the fixed nodes folds, solve "
      "it again with strict orientation constraints (--no-node-opt --orientation). Node "
      "optimization always does this at its end");
  if (o.node_optimization) ImGui::EndDisabled();
  ImGui::PopItemWidth();
  // Clamp typed values (Ctrl+click) to what the pipeline accepts.
  o.sharp_angle_deg = std::clamp(o.sharp_angle_deg, 1.0, 180.0);
  o.anisotropy = std::clamp(o.anisotropy, 1.0, 1000.0);
  o.max_cluster_faces = std::clamp(o.max_cluster_faces, 0, 100000);
  o.max_steps = std::clamp(o.max_steps, 1, 10000);
  o.descent_steps = std::clamp(o.descent_steps, 0, 10000);
  o.alpha = std::clamp(o.alpha, 0.01, 1.0);
  if (ImGui::Button("Defaults")) {
    const WorkerOptions defaults;
    o.align = defaults.align;
    o.sharp_angle_deg = defaults.sharp_angle_deg;
    o.max_cluster_faces = defaults.max_cluster_faces;
    o.wrap_free_holes = defaults.wrap_free_holes;
    o.anisotropy = defaults.anisotropy;
    o.sizing = defaults.sizing;
    o.node_optimization = defaults.node_optimization;
    o.max_steps = defaults.max_steps;
    o.descent_steps = defaults.descent_steps;
    o.keep_sharp_edges = defaults.keep_sharp_edges;
    o.keep_nodes_apart = defaults.keep_nodes_apart;
    o.separate_nodes = defaults.separate_nodes;
    o.untangle = defaults.untangle;
    o.remove_foldovers = defaults.remove_foldovers;
    o.alpha = defaults.alpha;
  }
  ImGui::SameLine();
  ImGui::TextDisabled("apply to the next Run / Step");
  ImGui::TreePop();
}

}  // namespace qs::app
