// The editor's ImGui panels, one file each (panel_*.cpp), and the helpers they share
// (ui.cpp). Panels read and change the AppContext; none calls OpenGL.
#pragma once

#include <imgui.h>

#include <string>

#include "app/gui/context.h"

namespace qs::app {

// ui.cpp
//! ImGui's style and the UI font at \p scale (DejaVu Sans with the glyphs the messages use,
//! or ImGui's built-in font and ASCII text when its file is missing). Returns whether the
//! Unicode font was loaded.
bool setup_style_and_fonts(float scale);
//! Every panel of one frame.
void draw_ui(AppContext& ctx);

// Shared look.
inline const ImVec4 kErrorColor(1.0f, 0.42f, 0.38f, 1.0f);
inline const ImVec4 kWarningColor(1.0f, 0.80f, 0.35f, 1.0f);
inline const ImVec4 kOkColor(0.45f, 0.85f, 0.50f, 1.0f);
inline const ImVec4 kDimColor(0.62f, 0.65f, 0.70f, 1.0f);
//! Text through ui_text() (ASCII when the font lacks the glyphs).
void text(const std::string& s);
void text_colored(const ImVec4& color, const std::string& s);
void text_wrapped(const std::string& s);
//! A tooltip for the last item when it is hovered (wrapped at ~30 characters' width).
void tooltip(const std::string& s);
//! A "(?)" after the last item with \p s as its tooltip.
void help_marker(const std::string& s);
//! "name.ext" of a path, "(none)" when empty.
std::string file_name(const std::string& path);

// The side panel's sections, in their order.
void draw_files_panel(AppContext& ctx);       // panel_files.cpp
void draw_sketch_panel(AppContext& ctx);      // panel_sketch.cpp
void draw_layout_panel(AppContext& ctx);      // panel_layout.cpp (with the validation)
void draw_pipeline_panel(AppContext& ctx);    // panel_pipeline.cpp
void draw_pipeline_options(AppContext& ctx);  // panel_pipeline_options.cpp (inside the above)
void draw_quads_panel(AppContext& ctx);       // panel_quads.cpp
void draw_view_panel(AppContext& ctx);        // panel_view.cpp
// Windows over the scene.
void draw_metrics_panel(AppContext& ctx);    // panel_metrics.cpp
void draw_status_bar(AppContext& ctx);       // panel_status.cpp
void draw_error_panel(AppContext& ctx);      // panel_dialogs.cpp
void draw_autosave_prompt(AppContext& ctx);  // panel_dialogs.cpp
void draw_file_browser(AppContext& ctx);     // panel_file_browser.cpp
//! Height of the status bar in pixels (the side panel ends above it).
float status_bar_height();

}  // namespace qs::app
