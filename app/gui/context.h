// What the panels, the keyboard actions and the automation act on: the editor state, the
// tools, the camera and the panels' own state. Everything but the renderer is GL-free.
#pragma once

#include <string>

#include "app/gui/editor.h"
#include "app/gui/file_browser.h"
#include "app/gui/tools.h"
#include "render/camera.h"
#include "render/picking.h"

namespace qs::render {
class Renderer;
}

namespace qs::app {

//! State of the panels that outlives a frame (ImGui keeps the rest).
struct UiState {
  std::string mesh_field;    //!< Files panel: mesh path field
  std::string layout_field;  //!< Files panel: layout path field
  FileBrowser browser;
  int browser_name_version = -1;  //!< FileBrowser::name_version() the name field shows
  //! The UI font has the glyphs beyond ASCII (DejaVu Sans); false: ImGui's default font, and
  //! text is shown in ASCII (ui_text()).
  bool unicode = true;
  bool show_demo = false;
  std::string shader_log;
};

struct AppContext {
  Editor& editor;
  Tools& tools;
  render::Camera& camera;
  const render::SurfacePicker& picker;
  UiState& ui;
  render::Renderer* renderer = nullptr;  //!< null without a window (tests)
};

}  // namespace qs::app
