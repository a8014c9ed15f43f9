// The panels' frame: style and fonts, the side panel and the windows over the scene, the
// helpers every panel uses.
#include <filesystem>

#include "app/gui/panels.h"
#include "app/gui/ui_text.h"

namespace qs::app {

namespace {

// A calm, neutral theme: dark translucent panels over the grey viewport, blue accents.
void apply_style(float scale) {
  ImGui::StyleColorsDark();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 6.0f;
  style.FrameRounding = 4.0f;
  style.GrabRounding = 4.0f;
  style.ScrollbarRounding = 6.0f;
  style.WindowBorderSize = 0.0f;
  style.FramePadding = ImVec2(6.0f, 4.0f);
  style.ItemSpacing = ImVec2(8.0f, 6.0f);
  style.WindowPadding = ImVec2(10.0f, 10.0f);
  ImVec4* c = style.Colors;
  c[ImGuiCol_WindowBg] = ImVec4(0.11f, 0.12f, 0.14f, 0.94f);
  c[ImGuiCol_TitleBg] = ImVec4(0.13f, 0.15f, 0.18f, 1.0f);
  c[ImGuiCol_TitleBgActive] = ImVec4(0.16f, 0.22f, 0.30f, 1.0f);
  c[ImGuiCol_Header] = ImVec4(0.20f, 0.27f, 0.36f, 0.80f);
  c[ImGuiCol_HeaderHovered] = ImVec4(0.26f, 0.36f, 0.50f, 0.90f);
  c[ImGuiCol_HeaderActive] = ImVec4(0.30f, 0.42f, 0.58f, 1.00f);
  c[ImGuiCol_FrameBg] = ImVec4(0.18f, 0.20f, 0.23f, 1.0f);
  c[ImGuiCol_Button] = ImVec4(0.22f, 0.30f, 0.40f, 1.0f);
  c[ImGuiCol_ButtonHovered] = ImVec4(0.28f, 0.40f, 0.55f, 1.0f);
  c[ImGuiCol_ButtonActive] = ImVec4(0.32f, 0.46f, 0.64f, 1.0f);
  style.ScaleAllSizes(scale);
}

// The characters beyond Latin-1 that messages and labels use: Greek, punctuation, super- and
// subscripts, letter-like symbols, arrows, mathematical operators, technical signs, shapes.
const ImWchar kGlyphRanges[] = {
    0x0020, 0x00FF, 0x0370, 0x03FF, 0x2000, 0x206F, 0x2070, 0x209F, 0x2100, 0x214F,
    0x2190, 0x21FF, 0x2200, 0x22FF, 0x2300, 0x23FF, 0x25A0, 0x25FF, 0,
};

void draw_side_panel(AppContext& ctx) {
  const ImGuiIO& io = ImGui::GetIO();
  const float width = 22.0f * ImGui::GetFontSize();
  const float bottom = status_bar_height();
  ImGui::SetNextWindowPos(ImVec2(10.0f, 10.0f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(width, io.DisplaySize.y - bottom - 20.0f),
                           ImGuiCond_FirstUseEver);
  ImGui::Begin("QuadSketch");
  // Centre the scene in the part of the window the panel leaves free.
  ctx.camera.set_view_offset(ImGui::IsWindowCollapsed()
                                 ? 0.0f
                                 : 0.5f * (ImGui::GetWindowPos().x + ImGui::GetWindowWidth()));
  draw_files_panel(ctx);
  draw_sketch_panel(ctx);
  draw_layout_panel(ctx);
  draw_pipeline_panel(ctx);
  draw_quads_panel(ctx);
  draw_view_panel(ctx);
  ImGui::End();
}

}  // namespace

bool setup_style_and_fonts(float scale) {
  ImGuiIO& io = ImGui::GetIO();
  apply_style(scale);
  const char* font = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
  std::error_code ec;
  bool unicode = false;
  if (std::filesystem::exists(font, ec))
    unicode = io.Fonts->AddFontFromFileTTF(font, 15.0f * scale, nullptr, kGlyphRanges) != nullptr;
  if (!unicode) {
    ImFontConfig config;
    config.SizePixels = 13.0f * scale;
    io.Fonts->AddFontDefault(&config);
  }
  set_unicode_text(unicode);
  return unicode;
}

void draw_ui(AppContext& ctx) {
  draw_side_panel(ctx);
  draw_metrics_panel(ctx);
  draw_error_panel(ctx);
  draw_autosave_prompt(ctx);
  draw_file_browser(ctx);
  draw_status_bar(ctx);
  if (ctx.ui.show_demo) ImGui::ShowDemoWindow(&ctx.ui.show_demo);
}

void text(const std::string& s) {
  ImGui::TextUnformatted(ui_text(s).c_str());
}

void text_colored(const ImVec4& color, const std::string& s) {
  ImGui::PushStyleColor(ImGuiCol_Text, color);
  text(s);
  ImGui::PopStyleColor();
}

void text_wrapped(const std::string& s) {
  ImGui::PushTextWrapPos(0.0f);
  text(s);
  ImGui::PopTextWrapPos();
}

void tooltip(const std::string& s) {
  if (!ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) return;
  ImGui::BeginTooltip();
  ImGui::PushTextWrapPos(ImGui::GetFontSize() * 30.0f);
  ImGui::TextUnformatted(ui_text(s).c_str());
  ImGui::PopTextWrapPos();
  ImGui::EndTooltip();
}

void help_marker(const std::string& s) {
  ImGui::SameLine();
  ImGui::TextDisabled("(?)");
  tooltip(s);
}

std::string file_name(const std::string& path) {
  return path.empty() ? std::string("(none)") : std::filesystem::path(path).filename().string();
}

}  // namespace qs::app
