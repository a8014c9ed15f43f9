#include "core/base/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/base/errors.h"

namespace qs {

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& writer) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string tmpl = (dir / ("." + target.filename().string() + ".tmpXXXXXX")).string();
  const int fd = mkstemp(tmpl.data());
  if (fd < 0) {
    throw QsError("cannot create a temporary file in '" + dir.string() +
                  "': " + std::strerror(errno));
  }
  close(fd);
  try {
    {
      std::ofstream out(tmpl, std::ios::binary | std::ios::trunc);
      if (!out) throw QsError("cannot open '" + tmpl + "' for writing");
      writer(out);
      out.flush();
      if (!out) throw QsError("error while writing '" + tmpl + "'");
    }
    const int sync_fd = open(tmpl.c_str(), O_RDONLY);
    if (sync_fd >= 0) {
      fsync(sync_fd);
      close(sync_fd);
    }
    // mkstemp creates 0600 files; give the result the usual permissions.
    fs::permissions(tmpl, fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                              fs::perms::others_read);
    if (std::rename(tmpl.c_str(), path.c_str()) != 0) {
      throw QsError("cannot rename '" + tmpl + "' to '" + path + "': " + std::strerror(errno));
    }
  } catch (...) {
    std::remove(tmpl.c_str());
    throw;
  }
}

void write_file_atomic(const std::string& path, const std::string& content) {
  write_file_atomic(path, [&](std::ostream& out) { out << content; });
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInputError("cannot read '" + path + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace qs
