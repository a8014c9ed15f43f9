#include "core/base/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "core/base/errors.h"

namespace qs {
namespace {

// Closes a file descriptor when it goes out of scope.
class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

// "a directory", "a FIFO (named pipe)", ... for a file that is not regular.
const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  return "a special file";
}

[[noreturn]] void refuse_kind(const std::string& path, mode_t mode) {
  throw InvalidInputError(path + ": cannot open file: it is " + kind_of(mode) +
                          ", not a regular file");
}

[[noreturn]] void refuse_size(const std::string& path, std::uintmax_t size,
                              std::uintmax_t max_bytes, bool at_least) {
  throw InvalidInputError(path + ": file too large: " + (at_least ? "more than " : "") +
                          std::to_string(at_least ? max_bytes : size) + " bytes (the limit is " +
                          std::to_string(max_bytes) + " bytes)");
}

}  // namespace

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes) {
  // stat first: opening some devices has side effects, and this needs no descriptor.
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) {
    const int error = errno;
    if (error == ENOENT) throw InvalidInputError(path + ": cannot open file");
    throw InvalidInputError(path + ": cannot open file (" + std::strerror(error) + ")");
  }
  if (!S_ISREG(info.st_mode)) refuse_kind(path, info.st_mode);
  if (static_cast<std::uintmax_t>(info.st_size) > max_bytes) {
    refuse_size(path, static_cast<std::uintmax_t>(info.st_size), max_bytes, false);
  }

  // O_NONBLOCK: should the path have become a FIFO meanwhile, open must not wait for a writer.
  const FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
  if (fd.get() < 0) {
    const int error = errno;
    if (error == ENOENT) throw InvalidInputError(path + ": cannot open file");
    throw InvalidInputError(path + ": cannot open file (" + std::strerror(error) + ")");
  }
  if (::fstat(fd.get(), &info) != 0) {
    throw InvalidInputError(path + ": cannot open file (" + std::strerror(errno) + ")");
  }
  if (!S_ISREG(info.st_mode)) refuse_kind(path, info.st_mode);
  const auto size = static_cast<std::uintmax_t>(info.st_size);
  if (size > max_bytes) refuse_size(path, size, max_bytes, false);

  std::string bytes;
  bytes.resize(static_cast<std::size_t>(size));
  std::size_t filled = 0;
  for (;;) {
    if (filled == bytes.size()) {
      // The file may have grown since fstat: keep reading, within the limit.
      if (filled >= max_bytes) {
        char probe = 0;
        const ssize_t n = ::read(fd.get(), &probe, 1);
        if (n > 0) refuse_size(path, filled, max_bytes, true);
        if (n == 0) break;
        if (errno == EINTR) continue;
        throw InvalidInputError(path + ": cannot read file (" + std::strerror(errno) + ")");
      }
      const std::uintmax_t room = max_bytes - filled;
      bytes.resize(filled + static_cast<std::size_t>(room < 65536 ? room : 65536));
    }
    const ssize_t n = ::read(fd.get(), bytes.data() + filled, bytes.size() - filled);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InvalidInputError(path + ": cannot read file (" + std::strerror(errno) + ")");
    }
    filled += static_cast<std::size_t>(n);
  }
  bytes.resize(filled);
  return bytes;
}

}  // namespace qs
