#include "app/gui/input.h"

#include <imgui.h>

#include <algorithm>

#include "app/gui/actions.h"

namespace qs::app {

MouseInput read_mouse() {
  const ImGuiIO& io = ImGui::GetIO();
  MouseInput in;
  in.position = {io.MousePos.x, io.MousePos.y};
  in.position_valid = ImGui::IsMousePosValid();
  in.over_ui = io.WantCaptureMouse;
  in.left_clicked = ImGui::IsMouseClicked(ImGuiMouseButton_Left);
  in.left_down = ImGui::IsMouseDown(ImGuiMouseButton_Left);
  in.pan_clicked = ImGui::IsMouseClicked(ImGuiMouseButton_Right) ||
                   ImGui::IsMouseClicked(ImGuiMouseButton_Middle);
  in.pan_down =
      ImGui::IsMouseDown(ImGuiMouseButton_Right) || ImGui::IsMouseDown(ImGuiMouseButton_Middle);
  in.wheel = io.MouseWheel;
  in.delta = {io.MouseDelta.x, io.MouseDelta.y};
  return in;
}

void handle_keys(std::vector<std::pair<int, int>>& presses, AppContext& ctx) {
  std::vector<std::pair<int, int>> keys;
  keys.swap(presses);
  if (ImGui::GetIO().WantTextInput) return;  // typing into a text field
  for (const auto& [key, mods] : keys) perform(key_binding(key, mods), ctx);
}

void open_dropped(std::vector<std::string>& files, AppContext& ctx) {
  if (files.empty()) return;
  std::vector<std::string> list;
  list.swap(files);
  std::stable_partition(list.begin(), list.end(),
                        [](const std::string& f) { return lower_extension(f) != ".json"; });
  for (const auto& f : list) {
    if (ctx.editor.open_file(f)) {
      if (is_mesh_file(f))
        ctx.ui.mesh_field = f;
      else
        ctx.ui.layout_field = f;
    }
  }
}

}  // namespace qs::app
