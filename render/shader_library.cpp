#include "render/shader_library.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace qs::render {

namespace {

std::string disk_path(const std::string& name) {
#if !defined(NDEBUG) && defined(QS_SHADER_SOURCE_DIR)
  return std::string(QS_SHADER_SOURCE_DIR) + "/" + name;
#else
  (void)name;
  return {};
#endif
}

}  // namespace

bool shaders_from_disk() {
  const std::string probe = disk_path("mesh.vert");
  std::error_code ec;
  return !probe.empty() && std::filesystem::exists(probe, ec);
}

std::string shader_source(const std::string& name) {
  const std::string path = disk_path(name);
  std::error_code ec;
  if (!path.empty() && std::filesystem::exists(path, ec)) {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    if (in) return text.str();
  }
  if (const char* source = embedded_shader(name.c_str())) return source;
  throw std::runtime_error("unknown shader '" + name + "'");
}

}  // namespace qs::render
