// Recently opened files, kept in ~/.config/quadsketch/recent.json (absence is fine).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace qs::app {

class RecentFiles {
 public:
  //! $XDG_CONFIG_HOME/quadsketch/recent.json or ~/.config/quadsketch/recent.json.
  static std::filesystem::path default_path();

  //! Reads the list; a missing or corrupt file gives empty lists. Never throws.
  void load(const std::filesystem::path& path = default_path());
  //! Writes the list atomically; returns false (and keeps going) when it cannot.
  bool save() const;

  void add_mesh(const std::string& path);
  void add_layout(const std::string& path);
  const std::vector<std::string>& meshes() const { return meshes_; }
  const std::vector<std::string>& layouts() const { return layouts_; }
  //! The file the last layout was saved to ("" before the first save).
  const std::string& last_save() const { return last_save_; }
  void set_last_save(const std::string& path);

  std::size_t max_entries = 10;

 private:
  void add(std::vector<std::string>& list, const std::string& path);
  std::filesystem::path path_;
  std::vector<std::string> meshes_;
  std::vector<std::string> layouts_;
  std::string last_save_;
};

}  // namespace qs::app
