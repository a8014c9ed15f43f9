// Keyboard shortcuts and the actions behind them (GL-free): the key map (Blender-like view
// keys on the numpad), and the actions the menus, keys and scripts share.
//
//   Ctrl+Z undo, Ctrl+Shift+Z / Ctrl+Y redo, Ctrl+O open, Ctrl+S save, Ctrl+Shift+S save as;
//   1-9 and 0 tools, Delete / Backspace delete the selection, P pins it, Esc cancels;
//   numpad 1 / 3 / 7 front / right / top view (Ctrl: back / left / bottom), numpad 5
//   perspective / orthographic, numpad 4 / 6 / 8 / 2 turn the view by 15 degrees, numpad .
//   and F frame the selection, Home frames everything, R resets the view.
#pragma once

#include <string>
#include <vector>

#include "app/gui/context.h"

namespace qs::app {

enum class Action {
  None,
  Undo,
  Redo,
  Open,
  Save,
  SaveAs,
  SetTool,
  DeleteSelection,
  TogglePin,
  Escape,
  FrameSelected,
  FrameAll,
  ResetView,
  ViewFront,
  ViewBack,
  ViewRight,
  ViewLeft,
  ViewTop,
  ViewBottom,
  ToggleOrthographic,
  OrbitLeft,
  OrbitRight,
  OrbitUp,
  OrbitDown,
};

struct KeyBinding {
  Action action = Action::None;
  int tool = -1;  //!< Action::SetTool: index of the tool
};

//! The action of GLFW key \p key with modifier bits \p mods (GLFW_MOD_*).
KeyBinding key_binding(int key, int mods);
//! GLFW key code of a script key name: "A".."Z", "0".."9", "KP_0".."KP_9", "KP_DECIMAL",
//! "HOME", "DELETE", "BACKSPACE", "ESCAPE", "ENTER"; -1 when unknown.
int key_from_name(const std::string& name);

//! Performs \p binding (Action::None does nothing).
void perform(const KeyBinding& binding, AppContext& ctx);

//! Brings mesh \p vertices into view (from the side their faces look to).
void focus_vertices(AppContext& ctx, const std::vector<int>& vertices);
//! The selection (node, arc or highlighted issue) into view; everything when none.
void frame_selected(AppContext& ctx);
//! Opens the file browser for opening a mesh or a layout.
void open_dialog(AppContext& ctx);
//! Opens the file browser for saving the layout (at Editor::save_path).
void save_as_dialog(AppContext& ctx);
//! Ctrl+S: saves to the layout's file, or asks for a name (save_as_dialog).
void save_or_ask(AppContext& ctx);
//! The file chosen in the browser: opened or saved. False when that failed (the browser
//! stays open).
bool accept_browser(AppContext& ctx);
//! Camera bounds of the mesh; with \p reset also the home view (immediately or animated).
void fit_camera_to_mesh(AppContext& ctx, bool reset, bool immediate);

}  // namespace qs::app
