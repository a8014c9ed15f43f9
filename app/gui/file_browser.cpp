#include "app/gui/file_browser.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>

namespace qs::app {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

const std::vector<BrowserFilter>& open_filters() {
  static const std::vector<BrowserFilter> filters = {
      {"Meshes and layouts", {".obj", ".off", ".ply", ".stl", ".json"}},
      {"Meshes (.obj .off .ply .stl)", {".obj", ".off", ".ply", ".stl"}},
      {"Layouts (.json)", {".json"}},
      {"All files", {}},
  };
  return filters;
}

const std::vector<BrowserFilter>& save_filters() {
  static const std::vector<BrowserFilter> filters = {
      {"Layouts (.json)", {".json"}},
      {"All files", {}},
  };
  return filters;
}

}  // namespace

std::string home_folder() {
  if (const char* home = std::getenv("HOME"); home && *home) return home;
  std::error_code ec;
  return fs::current_path(ec).string();
}

void FileBrowser::open(BrowserMode mode, const std::string& start) {
  mode_ = mode;
  filter_ = 0;
  set_file_name("");
  confirm_replace.clear();
  error_.clear();
  open_ = true;
  std::error_code ec;
  fs::path folder;
  if (!start.empty()) {
    const fs::path p = fs::absolute(start, ec);
    if (fs::is_directory(p, ec)) {
      folder = p;
    } else {
      folder = p.parent_path();
      if (mode == BrowserMode::Save) set_file_name(p.filename().string());
    }
  }
  if (folder.empty() || !fs::is_directory(folder, ec)) folder = home_folder();
  if (!navigate(folder.string())) navigate(home_folder());
}

const std::vector<BrowserFilter>& FileBrowser::filters() const {
  return mode_ == BrowserMode::Save ? save_filters() : open_filters();
}

void FileBrowser::set_filter(int index) {
  filter_ = std::clamp(index, 0, int(filters().size()) - 1);
  refresh();
}

bool FileBrowser::passes(const std::string& name) const {
  const auto& extensions = filters()[filter_].extensions;
  if (extensions.empty()) return true;
  const std::string l = lower(name);
  for (const auto& ext : extensions)
    if (ends_with(l, ext)) return true;
  return false;
}

bool FileBrowser::navigate(const std::string& folder) {
  std::error_code ec;
  const fs::path dir = fs::weakly_canonical(fs::absolute(folder, ec), ec);
  if (ec || !fs::is_directory(dir, ec)) {
    error_ = "Not a folder: " + folder;
    return false;
  }
  std::vector<BrowserEntry> entries;
  fs::directory_iterator it(dir, fs::directory_options::skip_permission_denied, ec);
  if (ec) {
    error_ = "Cannot read " + dir.string() + ": " + ec.message();
    return false;
  }
  for (; it != fs::directory_iterator(); it.increment(ec)) {
    if (ec) break;
    BrowserEntry e;
    e.name = it->path().filename().string();
    if (!show_hidden && !e.name.empty() && e.name[0] == '.') continue;
    std::error_code entry_ec;
    e.directory = it->is_directory(entry_ec);
    if (!e.directory) {
      if (!passes(e.name)) continue;
      e.size = it->file_size(entry_ec);
    }
    entries.push_back(std::move(e));
  }
  std::sort(entries.begin(), entries.end(), [](const BrowserEntry& a, const BrowserEntry& b) {
    if (a.directory != b.directory) return a.directory;
    return lower(a.name) < lower(b.name);
  });
  folder_ = dir.string();
  folder_field = folder_;
  entries_ = std::move(entries);
  error_.clear();
  return true;
}

bool FileBrowser::up() {
  const fs::path parent = fs::path(folder_).parent_path();
  if (parent.empty() || parent == fs::path(folder_)) return false;
  return navigate(parent.string());
}

void FileBrowser::refresh() {
  if (!folder_.empty()) navigate(folder_);
}

void FileBrowser::set_file_name(const std::string& name) {
  file_name = name;
  ++name_version_;
}

void FileBrowser::select(const BrowserEntry& entry) {
  if (entry.directory)
    navigate((fs::path(folder_) / entry.name).string());
  else
    set_file_name(entry.name);
}

std::string FileBrowser::chosen_path() const {
  if (file_name.empty()) return {};
  fs::path p(file_name);
  if (p.is_relative()) p = fs::path(folder_) / p;
  std::string out = p.lexically_normal().string();
  if (mode_ == BrowserMode::Save && fs::path(out).extension().empty()) out += ".layout.json";
  return out;
}

}  // namespace qs::app
