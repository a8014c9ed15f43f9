// Window input to the editor: the mouse as ImGui sees it to the tools and the camera, key
// presses to their actions (actions.h), dropped files to open.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "app/gui/context.h"

namespace qs::app {

//! This frame's mouse (after ImGui::NewFrame).
MouseInput read_mouse();
//! Performs the actions of the key presses (key, mods); none while a text field has the
//! keyboard. Clears \p presses.
void handle_keys(std::vector<std::pair<int, int>>& presses, AppContext& ctx);
//! Opens dropped files: meshes first, so that a mesh and a layout dropped together both
//! apply. Clears \p files.
void open_dropped(std::vector<std::string>& files, AppContext& ctx);

}  // namespace qs::app
