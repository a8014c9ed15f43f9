// View: the camera (turntable or trackball, perspective or orthographic, axis views,
// framing), the layers' settings and the colour legend.
#include "app/gui/actions.h"
#include "app/gui/panels.h"
#include "render/renderer.h"

namespace qs::app {

namespace {

void color_swatch(const char* id, const glm::vec3& color) {
  ImGui::ColorButton(id, ImVec4(color.r, color.g, color.b, 1.0f),
                     ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoPicker,
                     ImVec2(ImGui::GetFontSize(), ImGui::GetFontSize()));
}

void draw_camera(AppContext& ctx) {
  render::Camera& camera = ctx.camera;
  int mode = camera.orbit_mode() == render::OrbitMode::Turntable ? 0 : 1;
  ImGui::SetNextItemWidth(8.0f * ImGui::GetFontSize());
  if (ImGui::Combo("Orbit", &mode, "Turntable\0Trackball\0"))
    camera.set_orbit_mode(mode == 0 ? render::OrbitMode::Turntable : render::OrbitMode::Trackball);
  tooltip(
      "Turntable: left drag turns the scene about the vertical (world +y up) and tilts it, "
      "never rolling. Trackball: free rotation, as a ball under the cursor.");
  ImGui::SameLine();
  bool ortho = camera.orthographic();
  if (ImGui::Checkbox("Ortho", &ortho)) camera.set_orthographic(ortho);
  tooltip("Orthographic projection (numpad 5 toggles)");
  struct ViewButton {
    const char* label;
    render::AxisView view;
    const char* tip;
  };
  // The numpad's views and, below them, their opposites (Ctrl).
  const ViewButton views[] = {
      {"Front", render::AxisView::Front, "Look along -z (numpad 1)"},
      {"Right", render::AxisView::Right, "Look along -x (numpad 3)"},
      {"Top", render::AxisView::Top, "Look down -y (numpad 7)"},
      {"Back", render::AxisView::Back, "Look along +z (Ctrl+numpad 1)"},
      {"Left", render::AxisView::Left, "Look along +x (Ctrl+numpad 3)"},
      {"Bottom", render::AxisView::Bottom, "Look up +y (Ctrl+numpad 7)"},
  };
  const float column = 4.5f * ImGui::GetFontSize();
  for (int i = 0; i < 6; ++i) {
    if (i % 3 != 0) ImGui::SameLine(float(i % 3) * column + ImGui::GetStyle().WindowPadding.x);
    if (ImGui::Button(views[i].label, ImVec2(column - 6.0f, 0.0f)))
      camera.set_axis_view(views[i].view);
    tooltip(views[i].tip);
  }
  if (ImGui::Button("Frame all")) camera.frame_all();
  tooltip("The whole mesh in view, same direction (Home)");
  ImGui::SameLine();
  if (ImGui::Button("Frame selected")) frame_selected(ctx);
  tooltip("The selected node or arc (or the highlighted problem) in view (numpad . or F)");
  ImGui::SameLine();
  if (ImGui::Button("Reset")) camera.reset();
  tooltip("The home view: three-quarters from above, everything in view (R)");
}

void draw_legend() {
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

// The natural cross field of the bare mesh and its singularities (before Run).
void draw_field_hints(AppContext& ctx) {
  FieldHints& hints = ctx.editor.field_hints;
  ImGui::Checkbox("Field hints", &hints.enabled);
  tooltip(
      "The smoothest cross field of the bare mesh, following its curvature, sharp edges and "
      "boundary with its singularities free: faint crosses, and rings where irregular nodes "
      "belong (coloured like nodes: valence 3 / valence 5). Computed once per mesh in the "
      "background.");
  if (!hints.enabled) return;
  ImGui::SameLine();
  if (hints.computing()) {
    text_colored(kDimColor, "computing...");
  } else if (!hints.error().empty()) {
    text_colored(kErrorColor, "failed: " + hints.error());
  } else if (hints.field()) {
    const int three = hints.count(1), five = hints.count(-1);
    const int other = int(hints.field()->singularities.size()) - three - five;
    color_swatch("valence 3", render::GuideColors::singularity(1));
    ImGui::SameLine();
    text(std::to_string(three));
    ImGui::SameLine();
    color_swatch("valence 5", render::GuideColors::singularity(-1));
    ImGui::SameLine();
    text(std::to_string(five) + (other > 0 ? " (+" + std::to_string(other) + " other)" : ""));
    const std::size_t hidden =
        hints.raw_field()->singularities.size() - hints.field()->singularities.size();
    if (hidden > 0) {
      ImGui::SameLine();
      text_colored(kDimColor, std::to_string(hidden / 2) + " close pairs hidden");
    }
  }
  // Applied when the slider is released: each change recomputes the pairing.
  float percent = static_cast<float>(hints.scale() * 100.0);
  ImGui::SetNextItemWidth(ImGui::GetFontSize() * 10);
  ImGui::SliderFloat("Hint scale", &percent, 0.0f, static_cast<float>(FieldHints::kMaxScale * 100),
                     "%.1f %% of the size");
  if (ImGui::IsItemDeactivatedAfterEdit()) hints.set_scale(percent / 100.0);
  tooltip(
      "About the size of the patches you intend. A singularity and one of opposite index closer "
      "than this (along the surface, as a percentage of the model's bounding-box diagonal) "
      "cancel: a layout with patches of that size needs no irregular nodes for them. 0 shows "
      "every singularity of the field.");
}

}  // namespace

void draw_view_panel(AppContext& ctx) {
  if (!ImGui::CollapsingHeader("View", ImGuiTreeNodeFlags_DefaultOpen)) return;
  draw_camera(ctx);
  if (!ctx.renderer) return;
  render::Renderer& renderer = *ctx.renderer;
  ImGui::Separator();
  ImGui::PushID("mesh_layer");
  renderer.mesh_layer().ui();
  ImGui::PopID();
  ImGui::Separator();
  ImGui::PushID("layout_layer");
  renderer.layout_layer().ui();
  ImGui::PopID();
  ImGui::Separator();
  ImGui::PushID("field_layer");
  renderer.field_layer().ui();
  ImGui::PopID();
  draw_field_hints(ctx);
  draw_legend();
#ifndef NDEBUG
  if (ImGui::Button("Reload shaders")) {
    ctx.ui.shader_log.clear();
    renderer.reload_shaders(&ctx.ui.shader_log);
  }
  if (!ctx.ui.shader_log.empty()) ImGui::TextColored(kErrorColor, "%s", ctx.ui.shader_log.c_str());
  ImGui::SameLine();
  ImGui::Checkbox("ImGui demo", &ctx.ui.show_demo);
#endif
}

}  // namespace qs::app
