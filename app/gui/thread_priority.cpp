#include "app/gui/thread_priority.h"

#if defined(__linux__)
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <string>
#endif

namespace qs::app {

#if defined(__linux__)

int current_thread_id() {
  return int(::syscall(SYS_gettid));
}

int thread_nice(int tid) {
  errno = 0;
  const int value = ::getpriority(PRIO_PROCESS, id_t(tid));
  return errno == 0 ? value : 0;
}

namespace {

// Raises (never lowers) the nice value of one thread; true when changed.
bool renice(int tid, int nice) {
  errno = 0;
  const int current = ::getpriority(PRIO_PROCESS, id_t(tid));
  if (errno != 0 || current >= nice) return false;
  return ::setpriority(PRIO_PROCESS, id_t(tid), nice) == 0;
}

}  // namespace

int lower_solver_thread_priority(int nice) {
  if (nice <= 0) return 0;
  if (nice > 19) nice = 19;
  int changed = renice(current_thread_id(), nice) ? 1 : 0;
  const int main_tid = int(::getpid());
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task", ec)) {
    const std::string name = entry.path().filename().string();
    int tid = 0;
    try {
      tid = std::stoi(name);
    } catch (...) {
      continue;
    }
    if (tid == main_tid || tid == current_thread_id()) continue;
    std::ifstream comm(entry.path() / "comm");
    std::string thread_name;
    std::getline(comm, thread_name);
    if (thread_name.rfind("llvmpipe", 0) == 0) continue;  // the GL rasterizer works for the UI
    if (renice(tid, nice)) ++changed;
  }
  return changed;
}

#else

int current_thread_id() {
  return 0;
}

int thread_nice(int) {
  return 0;
}

int lower_solver_thread_priority(int) {
  return 0;
}

#endif

}  // namespace qs::app
