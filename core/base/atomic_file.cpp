#include "core/base/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>

#include "core/base/errors.h"

namespace qs {

namespace {

// The temporary files of the writes in progress, so that a thread ending the process can
// remove them (stop_atomic_writes_for_exit); creating, renaming and removing them happens
// under the mutex, so no temporary file appears after the stop.
struct PendingWrites {
  std::mutex mutex;
  std::condition_variable never_notified;
  bool stopped = false;              // guarded by mutex
  std::set<std::string> temp_paths;  // guarded by mutex
};

PendingWrites& pending_writes() {
  static PendingWrites pending;
  return pending;
}

//! Parks the calling thread for good: the writes were stopped because the process is ending.
[[noreturn]] void wait_for_process_exit(std::unique_lock<std::mutex>& lock) {
  for (;;) pending_writes().never_notified.wait(lock);
}

}  // namespace

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& writer) {
  namespace fs = std::filesystem;
  PendingWrites& pending = pending_writes();
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string tmpl = (dir / ("." + target.filename().string() + ".tmpXXXXXX")).string();
  std::ofstream out;
  int fd = -1;
  {
    std::unique_lock lock(pending.mutex);
    if (pending.stopped) wait_for_process_exit(lock);
    fd = mkstemp(tmpl.data());
    if (fd < 0) {
      throw QsError("cannot create a temporary file in '" + dir.string() +
                    "': " + std::strerror(errno));
    }
    pending.temp_paths.insert(tmpl);
    // Opened under the lock: opening by name after a stop would create the file again.
    out.open(tmpl, std::ios::binary | std::ios::trunc);
  }
  try {
    if (!out) throw QsError("cannot open '" + tmpl + "' for writing");
    // mkstemp creates 0600 files; give the result the usual permissions. Through the
    // descriptor, which stays valid when a stop removes the name.
    fchmod(fd, 0644);
    writer(out);
    out.flush();
    if (!out) throw QsError("error while writing '" + tmpl + "'");
    out.close();
    fsync(fd);
    close(fd);
    fd = -1;
    std::unique_lock lock(pending.mutex);
    if (pending.stopped) wait_for_process_exit(lock);
    if (std::rename(tmpl.c_str(), path.c_str()) != 0) {
      throw QsError("cannot rename '" + tmpl + "' to '" + path + "': " + std::strerror(errno));
    }
    pending.temp_paths.erase(tmpl);
  } catch (...) {
    if (fd >= 0) close(fd);
    std::lock_guard lock(pending.mutex);  // the try block's lock was released on unwinding
    std::remove(tmpl.c_str());
    pending.temp_paths.erase(tmpl);
    throw;
  }
}

int stop_atomic_writes_for_exit() {
  PendingWrites& pending = pending_writes();
  std::lock_guard lock(pending.mutex);
  pending.stopped = true;
  int removed = 0;
  for (const std::string& tmp : pending.temp_paths) removed += (std::remove(tmp.c_str()) == 0);
  pending.temp_paths.clear();
  return removed;
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
