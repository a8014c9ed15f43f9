#include "app/gui/recent_files.h"

#include <algorithm>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"

namespace qs::app {

namespace fs = std::filesystem;

fs::path RecentFiles::default_path() {
  if (const char* config = std::getenv("XDG_CONFIG_HOME"); config && *config)
    return fs::path(config) / "quadsketch" / "recent.json";
  if (const char* home = std::getenv("HOME"); home && *home)
    return fs::path(home) / ".config" / "quadsketch" / "recent.json";
  return {};
}

void RecentFiles::load(const fs::path& path) {
  path_ = path;
  meshes_.clear();
  layouts_.clear();
  last_save_.clear();
  try {
    std::error_code ec;
    if (path.empty() || !fs::exists(path, ec)) return;
    const auto json = nlohmann::json::parse(read_file(path.string()));
    for (const auto& m : json.value("meshes", nlohmann::json::array()))
      if (m.is_string()) meshes_.push_back(m.get<std::string>());
    for (const auto& l : json.value("layouts", nlohmann::json::array()))
      if (l.is_string()) layouts_.push_back(l.get<std::string>());
    if (json.contains("last_save") && json.at("last_save").is_string())
      last_save_ = json.at("last_save").get<std::string>();
  } catch (const std::exception&) {
    meshes_.clear();  // corrupt file: start over, it is only a convenience
    layouts_.clear();
  }
}

bool RecentFiles::save() const {
  if (path_.empty()) return false;
  try {
    fs::create_directories(path_.parent_path());
    const nlohmann::json json = {
        {"meshes", meshes_}, {"layouts", layouts_}, {"last_save", last_save_}};
    write_file_atomic(path_.string(), json.dump(2) + "\n");
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

void RecentFiles::add(std::vector<std::string>& list, const std::string& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  const std::string entry = ec ? path : absolute.lexically_normal().string();
  std::erase(list, entry);
  list.insert(list.begin(), entry);
  if (list.size() > max_entries) list.resize(max_entries);
}

void RecentFiles::set_last_save(const std::string& path) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(path, ec);
  last_save_ = ec ? path : absolute.lexically_normal().string();
}

void RecentFiles::add_mesh(const std::string& path) {
  add(meshes_, path);
}
void RecentFiles::add_layout(const std::string& path) {
  add(layouts_, path);
}

}  // namespace qs::app
