// The file browser window (Ctrl+O, Ctrl+Shift+S): places and recent files on the left, the
// folder's subfolders and matching files on the right, a file name field at the bottom (Enter
// opens or saves). Saving over another existing file asks first.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <cstdio>
#include <filesystem>

#include "app/gui/actions.h"
#include "app/gui/panels.h"

namespace qs::app {

namespace fs = std::filesystem;

namespace {

std::string size_text(std::uintmax_t bytes) {
  char out[32];
  if (bytes >= 1024 * 1024)
    std::snprintf(out, sizeof(out), "%.1f MB", double(bytes) / (1024.0 * 1024.0));
  else if (bytes >= 1024)
    std::snprintf(out, sizeof(out), "%.1f KB", double(bytes) / 1024.0);
  else
    std::snprintf(out, sizeof(out), "%d B", int(bytes));
  return out;
}

// Accepting the chosen file: saving over another existing file waits for a confirmation.
void accept(AppContext& ctx) {
  FileBrowser& browser = ctx.ui.browser;
  const std::string path = browser.chosen_path();
  std::error_code ec;
  if (browser.mode() == BrowserMode::Save && !path.empty() && fs::is_regular_file(path, ec) &&
      path != ctx.editor.doc.layout_path && browser.confirm_replace != path) {
    browser.confirm_replace = path;
    return;
  }
  browser.confirm_replace.clear();
  accept_browser(ctx);
}

void places(AppContext& ctx) {
  FileBrowser& browser = ctx.ui.browser;
  Editor& editor = ctx.editor;
  ImGui::TextDisabled("Places");
  const std::string home = home_folder();
  if (ImGui::Selectable("Home")) browser.navigate(home);
  std::error_code ec;
  if (fs::is_directory(fs::path(home) / "Documents", ec) && ImGui::Selectable("Documents"))
    browser.navigate((fs::path(home) / "Documents").string());
  if (!editor.doc.mesh_path.empty() && ImGui::Selectable("Mesh folder"))
    browser.navigate(fs::path(editor.doc.mesh_path).parent_path().string());
  if (!editor.recent.last_save().empty() && ImGui::Selectable("Last saved"))
    browser.navigate(fs::path(editor.recent.last_save()).parent_path().string());
  ImGui::Spacing();
  ImGui::TextDisabled("Recent");
  const auto recent_list = [&](const std::vector<std::string>& files) {
    for (const auto& f : files) {
      ImGui::PushID(f.c_str());
      if (ImGui::Selectable(file_name(f).c_str())) {
        browser.navigate(fs::path(f).parent_path().string());
        browser.set_file_name(fs::path(f).filename().string());
      }
      tooltip(f);
      ImGui::PopID();
    }
  };
  if (browser.mode() == BrowserMode::Open) recent_list(editor.recent.meshes());
  recent_list(editor.recent.layouts());
}

}  // namespace

void draw_file_browser(AppContext& ctx) {
  FileBrowser& browser = ctx.ui.browser;
  if (!browser.is_open()) return;
  const ImGuiIO& io = ImGui::GetIO();
  const float em = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x * 0.5f, io.DisplaySize.y * 0.45f),
                          ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(48.0f * em, io.DisplaySize.x - 20.0f),
                                  std::min(30.0f * em, io.DisplaySize.y - 80.0f)),
                           ImGuiCond_Appearing);
  const bool save = browser.mode() == BrowserMode::Save;
  bool open = true;
  ImGui::SetNextWindowBgAlpha(1.0f);  // opaque: the listing reads better than the scene
  ImGui::Begin(save ? "Save layout as###browser" : "Open mesh or layout###browser", &open,
               ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings);

  // Folder row: up, the folder path (Enter goes there), filter, hidden files.
  if (ImGui::Button("Up")) browser.up();
  tooltip("The parent folder");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-17.0f * em);
  if (ImGui::InputText("##folder", &browser.folder_field, ImGuiInputTextFlags_EnterReturnsTrue))
    browser.navigate(browser.folder_field);
  tooltip("Type a folder and press Enter");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(11.0f * em);
  const auto& filters = browser.filters();
  if (ImGui::BeginCombo("##filter", filters[browser.filter()].label.c_str())) {
    for (int i = 0; i < int(filters.size()); ++i)
      if (ImGui::Selectable(filters[i].label.c_str(), i == browser.filter())) browser.set_filter(i);
    ImGui::EndCombo();
  }
  tooltip("Which files are listed");
  ImGui::SameLine();
  if (ImGui::Checkbox("Hidden", &browser.show_hidden)) browser.refresh();

  // Places and recent files | the folder's content.
  const float footer = 2.0f * ImGui::GetFrameHeightWithSpacing() + 4.0f;
  ImGui::BeginChild("places", ImVec2(11.0f * em, -footer), true);
  places(ctx);
  ImGui::EndChild();
  ImGui::SameLine();
  ImGui::BeginChild("entries", ImVec2(0.0f, -footer), true);
  const std::vector<BrowserEntry> entries = browser.entries();  // navigation replaces them
  for (const auto& e : entries) {
    ImGui::PushID(e.name.c_str());
    const std::string label = (e.directory ? "[dir]  " : "       ") + e.name;
    const bool selected = !e.directory && e.name == browser.file_name;
    if (ImGui::Selectable(label.c_str(), selected, ImGuiSelectableFlags_AllowDoubleClick)) {
      browser.select(e);
      if (!e.directory && ImGui::IsMouseDoubleClicked(0)) accept(ctx);
    }
    if (!e.directory) {
      ImGui::SameLine(ImGui::GetWindowContentRegionMax().x - 5.0f * em);
      ImGui::TextDisabled("%s", size_text(e.size).c_str());
    }
    ImGui::PopID();
  }
  if (entries.empty()) ImGui::TextDisabled("(no matching files)");
  ImGui::EndChild();

  // File name, OK / Cancel.
  ImGui::SetNextItemWidth(-12.0f * em);
  // A name set from outside (a click on a file) gets a fresh field, which keeps the keyboard.
  if (ImGui::IsWindowAppearing() || ctx.ui.browser_name_version != browser.name_version())
    ImGui::SetKeyboardFocusHere();
  ctx.ui.browser_name_version = browser.name_version();
  ImGui::PushID(browser.name_version());
  const bool enter =
      ImGui::InputTextWithHint("##name", save ? "file name (.layout.json)" : "file name",
                               &browser.file_name, ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::PopID();
  tooltip("A name in this folder or a full path; Enter " + std::string(save ? "saves" : "opens"));
  ImGui::SameLine();
  if (ImGui::Button(save ? "Save" : "Open", ImVec2(5.5f * em, 0)) || enter) accept(ctx);
  ImGui::SameLine();
  if (ImGui::Button("Cancel", ImVec2(-1, 0))) browser.close();
  if (!browser.confirm_replace.empty()) {
    text_colored(kWarningColor,
                 file_name(browser.confirm_replace) + " exists: Save again to replace it.");
  } else if (!browser.error().empty()) {
    text_colored(kErrorColor, browser.error());
  } else {
    ImGui::TextDisabled("%s", browser.chosen_path().c_str());
  }
  // Esc closes it (while the window has the keyboard).
  if (ImGui::IsWindowFocused(ImGuiFocusedFlags_RootAndChildWindows) &&
      ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape)))
    open = false;
  ImGui::End();
  if (!open) browser.close();
}

}  // namespace qs::app
