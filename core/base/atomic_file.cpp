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
#include <ostream>
#include <set>
#include <sstream>
#include <streambuf>
#include <system_error>

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

// A stream buffer that writes to a file descriptor and keeps the errno of the first failed
// write (std::ofstream loses it), so that a full disk is reported as such.
class DescriptorBuffer : public std::streambuf {
 public:
  explicit DescriptorBuffer(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof buffer_); }
  //! errno of the first failed write, 0 while every write succeeded.
  int error() const { return error_; }

 protected:
  int_type overflow(int_type ch) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    if (error_ != 0) return false;
    const char* data = pbase();
    size_t left = static_cast<size_t>(pptr() - pbase());
    while (left > 0) {
      const ssize_t written = ::write(fd_, data, left);
      if (written < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        return false;
      }
      data += written;
      left -= static_cast<size_t>(written);
    }
    setp(buffer_, buffer_ + sizeof buffer_);
    return true;
  }

  int fd_;
  int error_ = 0;
  char buffer_[1 << 16];
};

}  // namespace

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& writer) {
  namespace fs = std::filesystem;
  PendingWrites& pending = pending_writes();
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  std::string tmpl = (dir / ("." + target.filename().string() + ".tmpXXXXXX")).string();
  int fd = -1;
  {
    std::unique_lock lock(pending.mutex);
    if (pending.stopped) wait_for_process_exit(lock);
    fd = mkstemp(tmpl.data());
    if (fd < 0) {
      throw QsError("cannot write '" + path + "': cannot create a file in '" + dir.string() +
                    "': " + std::strerror(errno));
    }
    pending.temp_paths.insert(tmpl);
  }
  const auto fail = [&](int error) {
    throw QsError("cannot write '" + path + "': " + std::strerror(error));
  };
  try {
    // mkstemp creates 0600 files; give the result the usual permissions. Through the
    // descriptor, which stays valid when a stop removes the name.
    fchmod(fd, 0644);
    DescriptorBuffer buffer(fd);
    std::ostream out(&buffer);
    writer(out);
    out.flush();
    if (buffer.error() != 0) fail(buffer.error());
    if (!out) throw QsError("cannot write '" + path + "': the output stream failed");
    // Some file systems report a full disk or an I/O error only here.
    if (fsync(fd) != 0 && errno != EINVAL) fail(errno);
    const int closed = close(fd);
    fd = -1;
    if (closed != 0 && errno != EINTR) fail(errno);
    std::unique_lock lock(pending.mutex);
    if (pending.stopped) wait_for_process_exit(lock);
    if (std::rename(tmpl.c_str(), path.c_str()) != 0) {
      throw QsError("cannot write '" + path + "': cannot rename the temporary file '" + tmpl +
                    "' to it: " + std::strerror(errno));
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

void require_writable_folder(const std::string& dir) {
  namespace fs = std::filesystem;
  const std::string shown = dir.empty() ? std::string(".") : dir;
  const auto refuse = [&](const std::string& why) {
    throw InvalidInputError("cannot write into the folder '" + shown + "': " + why);
  };
  std::error_code ec;
  if (!dir.empty()) fs::create_directories(dir, ec);
  if (ec) refuse(ec.message());
  if (!fs::is_directory(shown, ec)) refuse("it is not a folder");
  // A probe named like write_file_atomic's temporary files, so that a leftover (the process
  // killed between the two calls) is cleaned up like theirs.
  std::string probe = (fs::path(shown) / ".write_probe.tmpXXXXXX").string();
  const int fd = mkstemp(probe.data());
  if (fd < 0) refuse(std::strerror(errno));
  close(fd);
  std::remove(probe.c_str());
}

void require_writable_file(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw InvalidInputError("cannot write '" + path + "': it is a folder");
  require_writable_folder(fs::path(path).parent_path().string());
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidInputError("cannot read '" + path + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace qs
