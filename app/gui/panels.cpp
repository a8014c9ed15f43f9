// ImGui panels: files, tools, view, layout info, validation, pipeline, errors, status bar.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "app/gui/app.h"
#include "app/gui/pipeline_job.h"
#include "core/layout/layout_io.h"

namespace qs::app {

namespace {

const ImVec4 kErrorColor(1.0f, 0.42f, 0.38f, 1.0f);
const ImVec4 kWarningColor(1.0f, 0.80f, 0.35f, 1.0f);
const ImVec4 kOkColor(0.45f, 0.85f, 0.50f, 1.0f);
const ImVec4 kDimColor(0.62f, 0.65f, 0.70f, 1.0f);

ImVec4 to_imvec(const glm::vec3& c) {
  return ImVec4(c.r, c.g, c.b, 1.0f);
}

void color_swatch(const char* id, const glm::vec3& color) {
  ImGui::ColorButton(id, to_imvec(color),
                     ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoPicker,
                     ImVec2(ImGui::GetFontSize(), ImGui::GetFontSize()));
}

void help_marker(const char* text) {
  ImGui::SameLine();
  ImGui::TextDisabled("(?)");
  if (ImGui::IsItemHovered()) {
    ImGui::BeginTooltip();
    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
    ImGui::TextUnformatted(text);
    ImGui::PopTextWrapPos();
    ImGui::EndTooltip();
  }
}

std::string file_name(const std::string& path) {
  return path.empty() ? std::string("(none)") : std::filesystem::path(path).filename().string();
}

const char* tool_name(Tool tool) {
  switch (tool) {
    case Tool::Select:
      return "Select / move";
    case Tool::PlaceNode:
      return "Place node";
    case Tool::DrawArc:
      return "Draw arc";
    case Tool::Split:
      return "Split arc";
    case Tool::Delete:
      return "Delete";
    case Tool::Pin:
      return "Pin";
    case Tool::Stroke:
      return "Stroke arc";
    case Tool::Dangling:
      return "Dangling arc";
  }
  return "";
}

const char* tool_hint(Tool tool) {
  switch (tool) {
    case Tool::Select:
      return "Click a node or arc to select it; drag a node to move it.";
    case Tool::PlaceNode:
      return "Click the surface to place a node (on an arc: splits it).";
    case Tool::DrawArc:
      return "Click a node, then another node: the arc follows the shortest free path.";
    case Tool::Split:
      return "Click an arc to split it with a new node.";
    case Tool::Delete:
      return "Click a node (with its arcs) or an arc to delete it.";
    case Tool::Pin:
      return "Click a node or arc to pin / unpin it.";
    case Tool::Stroke:
      return "Press on a node and drag across the surface; release on a node, or anywhere for a "
             "new end node. The arc follows mesh edges close to the stroke.";
    case Tool::Dangling:
      return "Click a node, then click near the mesh boundary: an arc from the node to the "
             "boundary (trimmed patches). Click the node twice for the nearest boundary.";
  }
  return "";
}

// One "name  value" row of the metrics table; NaN shows as a dash.
void metric_row(const char* name, double value, const char* format, const char* tip = nullptr) {
  ImGui::TableNextRow();
  ImGui::TableNextColumn();
  ImGui::TextUnformatted(name);
  if (tip && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", tip);
  ImGui::TableNextColumn();
  if (std::isfinite(value))
    ImGui::Text(format, value);
  else
    ImGui::TextDisabled("-");
}

}  // namespace

void App::draw_ui() {
  draw_main_panel();
  draw_metrics_panel();
  draw_error_panel();
  draw_autosave_prompt();
  draw_status_bar();
  if (show_demo_) ImGui::ShowDemoWindow(&show_demo_);
}

void App::draw_main_panel() {
  const ImGuiIO& io = ImGui::GetIO();
  const float width = 22.0f * ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(10.0f, 10.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(width, io.DisplaySize.y - 60.0f), ImGuiCond_FirstUseEver);
  ImGui::Begin("QuadSketch");
  // Centre the scene in the part of the window the panel leaves free.
  camera_.set_view_offset(ImGui::IsWindowCollapsed()
                              ? 0.0f
                              : 0.5f * (ImGui::GetWindowPos().x + ImGui::GetWindowWidth()));
  draw_files_section();
  draw_tools_section();
  draw_layout_section();
  draw_validation_section();
  draw_pipeline_section();
  draw_quads_section();
  draw_view_section();
  ImGui::End();
}

void App::draw_files_section() {
  if (!ImGui::CollapsingHeader("Files", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::PushID("files");
  const float button = 4.5f * ImGui::GetFontSize();
  ImGui::SetNextItemWidth(-button);
  const bool mesh_enter = ImGui::InputTextWithHint(
      "##mesh", "mesh .obj .off .ply .stl", &mesh_field_, ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if (ImGui::Button("Open##mesh", ImVec2(-1, 0)) || mesh_enter) open_mesh(mesh_field_);
  ImGui::SetNextItemWidth(-button);
  const bool layout_enter = ImGui::InputTextWithHint("##layout", "layout .json", &layout_field_,
                                                     ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if (ImGui::Button("Open##layout", ImVec2(-1, 0)) || layout_enter) open_layout(layout_field_);

  if (ImGui::Button("Recent...")) ImGui::OpenPopup("recent");
  if (ImGui::BeginPopup("recent")) {
    ImGui::TextDisabled("Meshes");
    if (recent_.meshes().empty()) ImGui::TextDisabled("  (none)");
    for (const auto& m : recent_.meshes())
      if (ImGui::Selectable(m.c_str())) {
        const std::string path = m;  // open_mesh reorders the list
        ImGui::CloseCurrentPopup();
        open_mesh(path);
        break;
      }
    ImGui::Separator();
    ImGui::TextDisabled("Layouts");
    if (recent_.layouts().empty()) ImGui::TextDisabled("  (none)");
    for (const auto& l : recent_.layouts())
      if (ImGui::Selectable(l.c_str())) {
        const std::string path = l;
        ImGui::CloseCurrentPopup();
        open_layout(path);
        break;
      }
    ImGui::EndPopup();
  }
  ImGui::SameLine();
  ImGui::TextDisabled("or drop files on the window");

  ImGui::SetNextItemWidth(-button);
  ImGui::InputTextWithHint("##save", "save layout as .json", &save_field_);
  ImGui::SameLine();
  if (!doc_.mesh) ImGui::BeginDisabled();
  if (ImGui::Button("Save", ImVec2(-1, 0))) save_layout(save_field_);
  if (!doc_.mesh) ImGui::EndDisabled();

  if (doc_.mesh) {
    ImGui::PushStyleColor(ImGuiCol_Text, kDimColor);
    ImGui::TextWrapped("%s: %d vertices, %d faces, genus %d, %d boundary loop%s",
                       file_name(doc_.mesh_path).c_str(), doc_.report.vertices, doc_.report.faces,
                       doc_.report.genus, doc_.report.boundary_loops,
                       doc_.report.boundary_loops == 1 ? "" : "s");
    ImGui::PopStyleColor();
    ImGui::TextColored(kDimColor, "layout: %s%s", file_name(doc_.layout_path).c_str(),
                       doc_.dirty ? "  (modified, autosaved)" : "");
    if (!autosave_error_.empty())
      ImGui::TextColored(kWarningColor, "autosave failed: %s", autosave_error_.c_str());
  } else {
    ImGui::TextColored(kWarningColor, "No mesh loaded.");
  }
  ImGui::PopID();
}

void App::draw_tools_section() {
  if (!ImGui::CollapsingHeader("Sketch", ImGuiTreeNodeFlags_DefaultOpen)) return;
  for (int i = 0; i < kToolCount; ++i) {
    const Tool t = static_cast<Tool>(i);
    char label[64];
    std::snprintf(label, sizeof(label), "%d %s", i + 1, tool_name(t));
    if (i % 2 == 1) ImGui::SameLine(11.0f * ImGui::GetFontSize());
    if (ImGui::RadioButton(label, tool_ == t)) set_tool(t);
  }
  ImGui::TextWrapped("%s", tool_hint(tool_));
  if (!doc_.editor.can_undo()) ImGui::BeginDisabled();
  if (ImGui::Button("Undo")) undo();
  if (!doc_.editor.can_undo()) ImGui::EndDisabled();
  ImGui::SameLine();
  if (!doc_.editor.can_redo()) ImGui::BeginDisabled();
  if (ImGui::Button("Redo")) redo();
  if (!doc_.editor.can_redo()) ImGui::EndDisabled();
  ImGui::SameLine();
  if (doc_.editor.can_undo())
    ImGui::TextColored(kDimColor, "last: %s", doc_.editor.undo_label().c_str());
  help_marker(
      "Mouse: left drag orbits, right/middle drag pans, wheel zooms.\n"
      "Keys: 1-8 tools, F focus selection, R/Home reset view, Del delete, P pin, Esc cancel,\n"
      "Ctrl+Z undo, Ctrl+Shift+Z / Ctrl+Y redo, Ctrl+S save.");
}

void App::draw_layout_section() {
  if (!ImGui::CollapsingHeader("Layout", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const Layout& layout = doc_.editor.layout();
  int irregular = 0, pinned_nodes = 0, pinned_arcs = 0, dangling = 0;
  for (const auto& n : layout.nodes) {
    if (node_valence(layout, n.id) != 4) ++irregular;
    pinned_nodes += n.pinned;
  }
  for (const auto& a : layout.arcs) {
    pinned_arcs += a.pinned;
    dangling += a.dangling();
  }
  if (ImGui::BeginTable("counts", 2, ImGuiTableFlags_SizingStretchSame)) {
    ImGui::TableNextColumn();
    ImGui::Text("%zu nodes", layout.nodes.size());
    ImGui::TableNextColumn();
    ImGui::Text("%zu arcs", layout.arcs.size());
    ImGui::TableNextColumn();
    ImGui::Text("%d irregular nodes", irregular);
    ImGui::TableNextColumn();
    ImGui::Text("%d pinned", pinned_nodes + pinned_arcs);
    ImGui::EndTable();
  }
  if (dangling > 0 || !layout.patches.empty())
    ImGui::TextColored(kDimColor, "%d dangling arcs, %zu patches", dangling, layout.patches.size());
  if (selected_node_ >= 0 && layout.node_index(selected_node_) >= 0) {
    const auto& n = layout.nodes[layout.node_index(selected_node_)];
    ImGui::Text("Node %d: vertex %d, valence %d%s", n.id, n.vertex, node_valence(layout, n.id),
                n.pinned ? ", pinned" : "");
  } else if (selected_arc_ >= 0 && layout.arc_index(selected_arc_) >= 0) {
    const auto& a = layout.arcs[layout.arc_index(selected_arc_)];
    ImGui::Text("Arc %d: nodes %d -> %s, %zu edges, label %s%s", a.id, a.from,
                a.dangling() ? "boundary" : std::to_string(a.to).c_str(),
                a.path.empty() ? 0 : a.path.size() - 1, a.label.empty() ? "?" : a.label.c_str(),
                a.pinned ? ", pinned" : "");
  } else {
    ImGui::TextDisabled("Nothing selected.");
  }
}

void App::draw_validation_section() {
  const auto& v = doc_.validation;
  char header[96];
  std::snprintf(header, sizeof(header), "Validation (%d errors, %d warnings)###validation",
                v.errors(), v.warnings());
  if (!ImGui::CollapsingHeader(header, ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (!doc_.mesh) {
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
    const std::string label = std::string(error ? "E " : "W ") + issue.message;
    if (ImGui::Selectable(label.c_str(), highlighted_issue_ == i)) {
      highlighted_issue_ = i;
      // Focus on the problem: its vertices, or the nodes/arcs it names.
      std::vector<int> vertices = issue.vertices;
      const Layout& layout = doc_.editor.layout();
      for (int id : issue.node_ids)
        if (int k = layout.node_index(id); k >= 0) vertices.push_back(layout.nodes[k].vertex);
      for (int id : issue.arc_ids)
        if (int k = layout.arc_index(id); k >= 0)
          vertices.insert(vertices.end(), layout.arcs[k].path.begin(), layout.arcs[k].path.end());
      focus_vertices(vertices);
      selected_node_ = issue.node_ids.size() == 1 ? issue.node_ids[0] : -1;
      selected_arc_ = issue.arc_ids.size() == 1 && selected_node_ < 0 ? issue.arc_ids[0] : -1;
      ++interaction_version_;
    }
    ImGui::PopStyleColor();
    if (ImGui::IsItemHovered()) {
      ImGui::BeginTooltip();
      ImGui::Text("[%s] %s", issue.code.c_str(), issue.message.c_str());
      ImGui::TextDisabled("click to focus the camera on it");
      ImGui::EndTooltip();
    }
    ImGui::PopID();
  }
  ImGui::EndChild();
}

void App::draw_pipeline_section() {
  if (!ImGui::CollapsingHeader("Pipeline", ImGuiTreeNodeFlags_DefaultOpen)) return;
  const bool has_mesh = doc_.mesh != nullptr;
  if (!has_mesh) ImGui::BeginDisabled();
  if (ImGui::Button("Run")) {
    send_options();
    worker_->send(cmd::Run{});
  }
  ImGui::SameLine();
  if (ImGui::Button("Pause")) worker_->send(cmd::Pause{});
  ImGui::SameLine();
  if (ImGui::Button("Step")) {
    send_options();
    worker_->send(cmd::Step{});
  }
  ImGui::SameLine();
  if (ImGui::Button("Stop")) worker_->send(cmd::Stop{});
  if (!has_mesh) ImGui::EndDisabled();
  draw_pipeline_options();
  if (!snapshot_) return;
  const Snapshot& s = *snapshot_;
  const ImVec4 color = s.status == WorkerStatus::Failed     ? kErrorColor
                       : s.status == WorkerStatus::Finished ? kOkColor
                                                            : kDimColor;
  ImGui::TextColored(color, "%s", to_string(s.status));
  if (s.iteration > 0) {
    ImGui::SameLine();
    ImGui::Text("step %d", s.iteration);
    if (std::isfinite(s.energy)) {
      ImGui::SameLine();
      ImGui::Text("E = %.6g", s.energy);
    }
  }
  if (!s.message.empty()) ImGui::TextWrapped("%s", s.message.c_str());
  if (job_layout_shown() && s.status != WorkerStatus::Running) {
    if (ImGui::Button("Keep result")) {
      const Layout result = *s.layout;
      apply(doc_.editor.replace_layout(result, "keep optimized layout"), "Optimized layout kept");
    }
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("Make the optimized layout the one you edit and save (undo with Ctrl+Z)");
  }
  std::vector<float> energies;
  for (double e : s.energy_history)
    if (std::isfinite(e)) energies.push_back(float(e));
  // imgui 1.86's PlotLines does not accept a negative width: pass the available width.
  if (energies.size() >= 2)
    ImGui::PlotLines("##energy", energies.data(), int(energies.size()), 0, "energy", FLT_MAX,
                     FLT_MAX,
                     ImVec2(ImGui::GetContentRegionAvail().x, 3.0f * ImGui::GetFontSize()));
  draw_history_controls();
}

void App::draw_pipeline_options() {
  if (!ImGui::TreeNodeEx("Options", ImGuiTreeNodeFlags_DefaultOpen)) return;
  WorkerOptions& o = worker_options_;
  ImGui::PushItemWidth(-7.5f * ImGui::GetFontSize());
  bool no_align = !o.align;
  if (ImGui::Checkbox("No alignment (--no-align)", &no_align)) o.align = !no_align;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Ignore the principal curvature directions: the alignment-oblivious "
        "baseline (features and the boundary still constrain the field)");
  float sharp = float(o.sharp_angle_deg);
  if (ImGui::SliderFloat("Sharp angle", &sharp, 1.0f, 180.0f, "%.0f\xc2\xb0"))
    o.sharp_angle_deg = sharp;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Edges with a dihedral angle above this are features (--sharp-angle)");
  if (!o.align) ImGui::BeginDisabled();
  ImGui::SliderInt("Cluster size", &o.max_cluster_faces, 0, 100,
                   o.max_cluster_faces ? "%d" : "off");
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Split the curvature constraints into clusters of at most this many faces, released one "
        "by one where they contradict the layout (0: whole connected regions, which a layout "
        "that crosses them mostly releases). 10 (the default) keeps far more in force and lowers "
        "the angle error on most layouts (--max-cluster-faces)");
  if (!o.align) ImGui::EndDisabled();
  ImGui::Checkbox("Wrap free holes", &o.wrap_free_holes);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Holes that only dangling arcs run into: the iso-lines wrap around them (an O-grid, for "
        "many arcs radiating into a hole) instead of running on across them as around a "
        "regular point (--wrap-free-holes)");
  float anisotropy = float(o.anisotropy);
  if (ImGui::SliderFloat("Anisotropy", &anisotropy, 1.0f, 100.0f, "%.1f",
                         ImGuiSliderFlags_Logarithmic))
    o.anisotropy = anisotropy;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("How much more misalignment costs than scale in energy (1) (1: isotropic)");
  ImGui::Checkbox("Sizing field", &o.sizing);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Scale the targets by the curl-reducing sizing field (paper \xc2\xa7"
        "5.3): patches may "
        "vary in size, which lowers E (on the paper's models by 6-64 %%) and can unfold a "
        "layout, but the node optimization takes longer and lands in other optima (--sizing)");
  ImGui::Checkbox("Node optimization", &o.node_optimization);
  if (!o.node_optimization) ImGui::BeginDisabled();
  ImGui::SliderInt("Descent steps", &o.descent_steps, 0, 200, "%d", ImGuiSliderFlags_Logarithmic);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Gradient steps before the first hop sweep; each sweep that moves nodes allows more "
        "(--steps)");
  ImGui::SliderInt("Max steps", &o.max_steps, 1, 1000, "%d", ImGuiSliderFlags_Logarithmic);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Steps of a run at most: the initial solve, descent steps and hop sweeps; the last one "
        "also removes fold-overs");
  ImGui::Checkbox("Keep sharp edges", &o.keep_sharp_edges);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Nodes on sharp edges slide along them and no vertex on a sharp edge is moved: sharp "
        "edges keep their shape, at a higher E (--keep-sharp-edges)");
  ImGui::Checkbox("Keep nodes apart", &o.keep_nodes_apart);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "No node moves onto a vertex next to another node (no two nodes on one triangle): for "
        "dense layouts with a few edges per patch side, where crowded nodes keep fold-overs "
        "(--keep-nodes-apart)");
  ImGui::Checkbox("Untangle fold-overs", &o.untangle);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Where the orientation constraints leave fold-overs, untangle the parameterization: a "
        "barrier on each triangle's area, with the same layout constraints (off: "
        "--no-untangle)");
  ImGui::Checkbox("Separate crowded nodes", &o.separate_nodes);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Before the node optimization, nodes sketched next to another node (on its 1-ring) "
        "move apart, at most 2 edge rings, keeping every patch (--separate-nodes)");
  float alpha = float(o.alpha);
  if (ImGui::SliderFloat("alpha (damping)", &alpha, 0.05f, 1.0f, "%.2f")) o.alpha = alpha;
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("Initial damping factor of the node steps; halved after a rejected step");
  if (!o.node_optimization) ImGui::EndDisabled();
  if (o.node_optimization) ImGui::BeginDisabled();
  ImGui::Checkbox("Remove fold-overs", &o.remove_foldovers);
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip(
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

void App::draw_history_controls() {
  if (!job_layout_shown()) return;
  const Snapshot& s = *snapshot_;
  const int steps = int(s.node_history.size());
  if (steps == 0) return;
  ImGui::PushID("history");
  // Scrub through the streamed steps (1 = initial solve); "Live" follows the newest one.
  int shown = std::clamp(history_step_, 0, steps - 1) + 1;
  ImGui::SetNextItemWidth(-4.5f * ImGui::GetFontSize());
  if (steps == 1) ImGui::BeginDisabled();
  if (ImGui::SliderInt("##step", &shown, 1, std::max(1, steps), "step %d")) {
    history_step_ = std::clamp(shown, 1, steps) - 1;
    history_live_ = history_step_ == steps - 1;
  }
  if (steps == 1) ImGui::EndDisabled();
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Scrub through the streamed steps; node trajectories show where each "
        "node moved, the chosen step's nodes are ringed in cyan.");
  ImGui::SameLine();
  if (ImGui::Checkbox("Live", &history_live_) && history_live_) history_step_ = steps - 1;
  const int k = std::clamp(history_step_, 0, steps - 1);
  if (k < int(s.energy_history.size()) && std::isfinite(s.energy_history[k]))
    ImGui::TextColored(kDimColor, "step %d of %d: E = %.6g%s", k + 1, steps, s.energy_history[k],
                       k == 0 ? " (initial solve)" : "");
  ImGui::PopID();
}

void App::draw_quads_section() {
  if (!ImGui::CollapsingHeader("Quad mesh & export", ImGuiTreeNodeFlags_DefaultOpen)) return;
  ImGui::PushID("quads");
  // Quad size in surface units; 0 = automatic (about kDefaultQuadCount quads).
  // The mesh's diagonal, once per mesh (not a loop over every vertex each frame).
  if (mesh_diagonal_version_ != doc_.mesh_version) {
    mesh_diagonal_version_ = doc_.mesh_version;
    mesh_diagonal_ = 1.0f;
    if (doc_.mesh && doc_.mesh->n_vertices() > 0) {
      glm::vec3 lo(1e30f), hi(-1e30f);
      for (auto vh : doc_.mesh->vertices()) {
        const auto& p = doc_.mesh->point(vh);
        const glm::vec3 q{float(p[0]), float(p[1]), float(p[2])};
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
      }
      mesh_diagonal_ = std::max(glm::length(hi - lo), 1e-6f);
    }
  }
  const float diag = mesh_diagonal_;
  float quad_size = float(worker_options_.quad_size);
  char format[64];
  std::snprintf(format, sizeof(format), quad_size > 0.0f ? "q = %%.4g" : "auto (~%d quads)",
                kDefaultQuadCount);
  ImGui::SetNextItemWidth(-4.5f * ImGui::GetFontSize());
  if (ImGui::SliderFloat("Quad size", &quad_size, 0.0f, 0.2f * diag, format))
    worker_options_.quad_size = quad_size;
  if (ImGui::IsItemDeactivatedAfterEdit()) worker_->send(cmd::SetOptions{worker_options_});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "Target quad edge length; the quad mesh is built on the worker at the "
        "final step of a run (0: automatic). Ctrl+click to type a value.");
  const Snapshot* s = job_layout_shown() ? snapshot_.get() : nullptr;
  if (s && s->quads) {
    const QuadOverlay& q = *s->quads;
    ImGui::TextColored(kOkColor, "%zu quads, %zu vertices, q = %.4g", q.quads.size(),
                       q.vertices.size(), q.quad_size);
    ImGui::TextColored(q.gridded_patches < q.patches ? kWarningColor : kDimColor,
                       "%d of %d patches gridded", q.gridded_patches, q.patches);
    if (!q.warnings.empty() && ImGui::IsItemHovered()) {
      ImGui::BeginTooltip();
      for (const auto& w : q.warnings) ImGui::TextUnformatted(w.c_str());
      ImGui::EndTooltip();
    }
  } else {
    ImGui::TextDisabled("Run the pipeline to the end to build the quad mesh.");
  }

  const float button = 4.5f * ImGui::GetFontSize();
  ImGui::SetNextItemWidth(-button);
  ImGui::InputTextWithHint("##dir", "export folder", &export_dir_);
  const bool can_export = s && s->exports;
  if (!can_export) ImGui::BeginDisabled();
  auto export_files = [&](const ExportSelection& what) {
    try {
      const auto written = write_job_exports(*s->exports, export_dir_, what);
      std::string list;
      for (const auto& f : written) list += (list.empty() ? "" : ", ") + f;
      export_message_ = "Wrote " + list + " to " + export_dir_;
      export_failed_ = false;
      status_ = export_message_;
    } catch (const std::exception& e) {
      export_message_ = std::string("Export failed: ") + e.what();
      export_failed_ = true;
    }
  };
  ImGui::SameLine();
  if (ImGui::Button("Export...", ImVec2(-1, 0))) export_files(ExportSelection{});
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("param.obj, layout.json, quads.obj, patches.json, layout_curves.obj");
  if (ImGui::Button("param.obj")) export_files({true, false, false});
  ImGui::SameLine();
  if (ImGui::Button("layout.json")) export_files({false, true, false});
  ImGui::SameLine();
  const bool has_quads = can_export && s->exports->quads;
  if (!has_quads && can_export) ImGui::BeginDisabled();
  if (ImGui::Button("quads.obj...")) export_files({false, false, true});
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("quads.obj, patches.json, layout_curves.obj");
  if (!has_quads && can_export) ImGui::EndDisabled();
  if (!can_export) ImGui::EndDisabled();
  if (!export_message_.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, export_failed_ ? kErrorColor : kDimColor);
    ImGui::TextWrapped("%s", export_message_.c_str());
    ImGui::PopStyleColor();
  }
  ImGui::PopID();
}

void App::draw_metrics_panel() {
  if (!job_layout_shown()) return;
  const Snapshot& s = *snapshot_;
  const StepMetrics& m = s.metrics;
  const ImGuiIO& io = ImGui::GetIO();
  const float width = 15.0f * ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - width - 10.0f, 10.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(width, 0.0f), ImGuiCond_FirstUseEver);
  ImGui::Begin("Metrics", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  const ImGuiTableFlags flags = ImGuiTableFlags_SizingStretchProp | ImGuiTableFlags_RowBg;
  if (ImGui::BeginTable("quality", 2, flags)) {
    metric_row("E_init", s.energy_init, "%.6g", "Energy (1) after the initial solve");
    metric_row("E", m.valid ? m.E : s.energy, "%.6g", "Energy (1) at the latest step");
    if (std::isfinite(s.energy_init) && s.energy_init > 0.0 && std::isfinite(m.E))
      metric_row("E / E_init", m.E / s.energy_init, "%.3f");
    metric_row("E_confor", m.E_confor, "%.4f",
               "Mean sigma1/sigma2 + sigma2/sigma1 (2 = conformal)");
    metric_row("E\xc2\xb0", m.E_angle_deg, "%.2f\xc2\xb0",
               "Deviation of the iso-lines from the principal directions, degrees in [0, 45]");
    metric_row("E_planar", m.E_planar, "%.4g", "Conjugacy (dimensionless)");
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted("fold-overs");
    ImGui::TableNextColumn();
    if (m.valid)
      ImGui::TextColored(m.foldovers > 0 ? kErrorColor : kOkColor, "%d", m.foldovers);
    else
      ImGui::TextDisabled("-");
    // Direction constraints in force: few when the layout contradicts the curvature/features.
    if (s.field && !s.field->constraint_faces.empty()) {
      const FieldView& f = *s.field;
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted("aligned faces");
      if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "Faces whose direction constraint (curvature, feature, boundary) is in force.\n"
            "Constraint clusters that contradict the layout's topology are released\n"
            "(grey bars in the cross-field view): there the field follows the layout.");
      ImGui::TableNextColumn();
      ImGui::TextColored(f.warning.empty() ? kOkColor : kWarningColor, "%d / %d", f.in_force,
                         int(f.constraint_faces.size()));
      if (!f.warning.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", f.warning.c_str());
    }
    ImGui::EndTable();
  }
  ImGui::TextDisabled("Timings, step %d (ms)", s.iteration);
  if (ImGui::BeginTable("timings", 2, flags)) {
    metric_row("node opt.", m.nodeopt_ms, "%.1f");
    metric_row("field", m.field_ms, "%.1f");
    metric_row("param.", m.param_ms, "%.1f");
    metric_row("extract", m.extract_ms, "%.1f");
    metric_row("metrics", m.metrics_ms, "%.1f");
    metric_row("quad mesh", m.quads_ms, "%.1f");
    metric_row("total", m.total_ms, "%.1f");
    ImGui::EndTable();
  }
  ImGui::End();
}

void App::draw_view_section() {
  if (!ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) return;
  if (ImGui::Button("Reset view (R)")) reset_view();
  ImGui::SameLine();
  if (ImGui::Button("Focus (F)")) focus_selection();
  ImGui::PushID("mesh_layer");
  mesh_layer_->ui();
  ImGui::PopID();
  ImGui::Separator();
  ImGui::PushID("layout_layer");
  layout_layer_->ui();
  ImGui::PopID();
  ImGui::Separator();
  ImGui::PushID("field_layer");
  field_layer_->ui();
  ImGui::PopID();
  draw_legend();
#ifndef NDEBUG
  if (ImGui::Button("Reload shaders")) {
    shader_log_.clear();
    mesh_layer_->reload(&shader_log_);
    layout_layer_->reload(&shader_log_);
    field_layer_->reload(&shader_log_);
    scene_cache_.invalidate();  // the cached image was drawn with the old shaders
  }
  if (!shader_log_.empty()) ImGui::TextColored(kErrorColor, "%s", shader_log_.c_str());
  ImGui::SameLine();
  ImGui::Checkbox("ImGui demo", &show_demo_);
#endif
}

void App::draw_legend() {
  ImGui::TextDisabled("Nodes by valence");
  const struct {
    int valence;
    const char* label;
  } nodes[] = {{4, "4"}, {3, "3"}, {5, "5"}, {6, "other"}};
  for (const auto& n : nodes) {
    color_swatch(n.label, render::LayoutColors::valence(n.valence));
    ImGui::SameLine();
    ImGui::TextUnformatted(n.label);
    ImGui::SameLine();
  }
  ImGui::NewLine();
  ImGui::TextDisabled("Arcs by label");
  const struct {
    const char* label;
    const char* name;
  } arcs[] = {{"u", "u"}, {"v", "v"}, {"", "unknown"}};
  for (const auto& a : arcs) {
    color_swatch(a.name, render::LayoutColors::label(a.label));
    ImGui::SameLine();
    ImGui::TextUnformatted(a.name);
    ImGui::SameLine();
  }
  color_swatch("pinned", render::LayoutColors::kPin);
  ImGui::SameLine();
  ImGui::TextUnformatted("pinned");
  ImGui::SameLine();
  color_swatch("problem", render::LayoutColors::kProblem);
  ImGui::SameLine();
  ImGui::TextUnformatted("problem");
}

void App::draw_error_panel() {
  if (errors_.empty()) return;
  const ImGuiIO& io = ImGui::GetIO();
  const float width = std::min(36.0f * ImGui::GetFontSize(), io.DisplaySize.x - 40.0f);
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f + 6.0f * ImGui::GetFontSize(), 12.0f),
                          ImGuiCond_Always, ImVec2(0.5f, 0.0f));
  ImGui::SetNextWindowSize(ImVec2(width, 0.0f), ImGuiCond_Always);
  ImGui::PushStyleColor(ImGuiCol_WindowBg, ImVec4(0.22f, 0.08f, 0.08f, 0.95f));
  ImGui::Begin("Problems", nullptr,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings);
  ImGui::PushTextWrapPos(0.0f);
  for (const auto& e : errors_) {
    ImGui::TextColored(kErrorColor, "%s", e.c_str());
    ImGui::Separator();
  }
  ImGui::PopTextWrapPos();
  if (ImGui::Button("Dismiss")) errors_.clear();
  ImGui::End();
  ImGui::PopStyleColor();
}

void App::draw_autosave_prompt() {
  if (!autosave_offer_) return;
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f, io.DisplaySize.y * 0.4f),
                          ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::Begin("Restore autosave?", nullptr,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoSavedSettings);
  ImGui::Text("An autosaved layout from %s is newer than the opened file.",
              autosave_offer_->saved_at.c_str());
  ImGui::TextDisabled("%s", autosave_offer_->path.string().c_str());
  if (ImGui::Button("Restore")) {
    try {
      Layout layout = load_layout(autosave_offer_->path.string(), *doc_.mesh);
      doc_.editor.reset(doc_.mesh.get(), std::move(layout));
      if (!autosave_offer_->layout_path.empty()) doc_.layout_path = autosave_offer_->layout_path;
      save_field_ = doc_.layout_path;
      doc_.dirty = true;
      after_layout_replaced();
      status_ = "Restored the autosave (not yet saved to the layout file)";
    } catch (const std::exception& e) {
      report_error(std::string("Cannot restore the autosave: ") + e.what());
    }
    autosave_offer_.reset();
  }
  ImGui::SameLine();
  if (ImGui::Button("Discard")) autosave_offer_.reset();
  ImGui::End();
}

void App::draw_status_bar() {
  const ImGuiIO& io = ImGui::GetIO();
  const float height = ImGui::GetFrameHeightWithSpacing() + 4.0f;
  ImGui::SetNextWindowPos(ImVec2(0.0f, io.DisplaySize.y - height));
  ImGui::SetNextWindowSize(ImVec2(io.DisplaySize.x, height));
  ImGui::PushStyleVar(ImGuiStyleVar_WindowRounding, 0.0f);
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(10.0f, 4.0f));
  ImGui::Begin("##status", nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                   ImGuiWindowFlags_NoBringToFrontOnFocus);
  ImGui::TextColored(kDimColor, "[%s]", tool_name(tool_));
  ImGui::SameLine();
  ImGui::TextUnformatted(status_.empty() ? tool_hint(tool_) : status_.c_str());
  const std::string right = std::string(doc_.dirty ? "modified  " : "") +
                            std::to_string(int(std::lround(io.Framerate))) + " fps";
  ImGui::SameLine(io.DisplaySize.x - ImGui::CalcTextSize(right.c_str()).x - 14.0f);
  ImGui::TextColored(kDimColor, "%s", right.c_str());
  ImGui::End();
  ImGui::PopStyleVar(2);
}

}  // namespace qs::app
