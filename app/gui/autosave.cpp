#include "app/gui/autosave.h"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <nlohmann/json.hpp>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/layout/layout_io.h"

namespace qs::app {

namespace fs = std::filesystem;

namespace {

std::string absolute_string(const std::string& path) {
  if (path.empty()) return {};
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(path, ec), ec);
  return ec ? path : p.string();
}

}  // namespace

fs::path autosave_dir() {
  if (const char* dir = std::getenv("QS_AUTOSAVE_DIR"); dir && *dir) return dir;
  if (const char* cache = std::getenv("XDG_CACHE_HOME"); cache && *cache)
    return fs::path(cache) / "quadsketch";
  if (const char* home = std::getenv("HOME"); home && *home)
    return fs::path(home) / ".cache" / "quadsketch";
  return fs::temp_directory_path() / "quadsketch";
}

fs::path autosave_path() {
  return autosave_dir() / "autosave.layout.json";
}

void write_autosave(const Layout& layout, const TriMesh* mesh, const std::string& mesh_path,
                    const std::string& layout_path) {
  fs::create_directories(autosave_dir());
  const std::time_t now = std::time(nullptr);
  char stamp[64] = "";
  std::strftime(stamp, sizeof(stamp), "%Y-%m-%d %H:%M:%S", std::localtime(&now));
  const nlohmann::json meta = {{"mesh", absolute_string(mesh_path)},
                               {"layout", absolute_string(layout_path)},
                               {"saved_at", stamp}};
  // One file, one atomic write: the layout JSON with the "autosave" block as its first key
  // (the layout reader ignores unknown keys), so a killed process can never leave a layout
  // paired with another session's description.
  std::string text = layout_to_json(layout, mesh);
  const std::size_t brace = text.find('{');
  if (brace == std::string::npos) throw QsError("autosave: unexpected layout serialization");
  text.insert(brace + 1, "\n  \"autosave\": " + meta.dump() + ",");
  write_file_atomic(autosave_path().string(), text);
}

std::optional<AutosaveOffer> find_autosave() {
  try {
    std::error_code ec;
    const fs::path autosave = autosave_path();
    if (!fs::exists(autosave, ec)) return std::nullopt;
    const auto document = nlohmann::json::parse(read_file(autosave.string()));
    if (!document.is_object() || !document.contains("autosave")) return std::nullopt;
    const auto& meta = document.at("autosave");
    AutosaveOffer offer;
    offer.path = autosave;
    offer.mesh_path = meta.value("mesh", std::string());
    offer.layout_path = meta.value("layout", std::string());
    offer.saved_at = meta.value("saved_at", std::string());
    if (!offer.layout_path.empty() && fs::exists(offer.layout_path, ec) &&
        fs::last_write_time(autosave, ec) <= fs::last_write_time(offer.layout_path, ec))
      return std::nullopt;  // saved after the last autosave
    return offer;
  } catch (const std::exception&) {
    return std::nullopt;  // a corrupt autosave is not worth an error at start-up
  }
}

std::optional<AutosaveOffer> find_autosave(const std::string& mesh_path) {
  auto offer = find_autosave();
  if (offer && offer->mesh_path != absolute_string(mesh_path)) return std::nullopt;
  return offer;
}

void remove_autosave() {
  std::error_code ec;
  fs::remove(autosave_path(), ec);
}

std::string set_autosave_aside() {
  std::error_code ec;
  const fs::path from = autosave_path();
  if (!fs::exists(from, ec)) return {};
  const fs::path to = autosave_dir() / "autosave.previous.layout.json";
  fs::rename(from, to, ec);
  return ec ? std::string() : to.string();
}

}  // namespace qs::app
