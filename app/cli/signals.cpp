#include "app/cli/signals.h"

#include <atomic>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <system_error>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"

namespace qs::cli {

namespace {

// A lock-free atomic may be written from a signal handler ([support.signal]).
std::atomic<int> g_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);
std::atomic<bool> g_installed{false};

extern "C" void qs_on_signal(int signo) {
  int expected = 0;
  g_signal.compare_exchange_strong(expected, signo);
}

}  // namespace

void install_signal_handlers() {
  if (g_installed.exchange(true)) return;
  struct sigaction action {};
  action.sa_handler = qs_on_signal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: a second signal takes the default action (the user insists).
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

void restore_default_signal_handling() {
  struct sigaction action {};
  action.sa_handler = SIG_DFL;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A signal that arrived during start-up is honoured now.
  if (const int signo = received_signal()) std::raise(signo);
}

int received_signal() {
  return g_signal.load(std::memory_order_relaxed);
}

void cancellation_point() {
  if (cancel_requested()) throw Cancelled();
}

int cancelled_exit_code() {
  const int signo = received_signal();
  return signo ? 128 + signo : 1;
}

std::string signal_name(int signo) {
  if (signo == SIGINT) return "SIGINT";
  if (signo == SIGTERM) return "SIGTERM";
  return "signal " + std::to_string(signo);
}

void reset_received_signal_for_tests() {
  g_signal.store(0);
}

int remove_atomic_write_leftovers(const std::string& dir) {
  namespace fs = std::filesystem;
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // write_file_atomic's template: "." + file name + ".tmpXXXXXX".
    const auto tmp = name.rfind(".tmp");
    if (name.size() < 12 || name[0] != '.' || tmp == std::string::npos || tmp == 0 ||
        tmp + 10 != name.size())
      continue;
    std::error_code rm_ec;
    if (fs::remove(it->path(), rm_ec)) ++removed;
  }
  return removed;
}

CancelWatchdog::CancelWatchdog(std::string out_dir, std::chrono::milliseconds grace)
    : out_dir_(std::move(out_dir)), grace_(grace), thread_([this] { watch(); }) {}

CancelWatchdog::~CancelWatchdog() {
  {
    std::lock_guard lock(mutex_);
    done_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void CancelWatchdog::watch() {
  using namespace std::chrono_literals;
  std::unique_lock lock(mutex_);
  // The handler cannot notify a condition variable (not async-signal-safe): poll the flag.
  while (!done_ && !cancel_requested()) cv_.wait_for(lock, 20ms);
  if (done_) return;
  if (cv_.wait_for(lock, grace_, [this] { return done_; })) return;
  // The main thread is inside a stage that does not poll: stop the process here.
  const int signo = received_signal();
  const nlohmann::json report = {
      {"status", "cancelled"},
      {"signal", signal_name(signo)},
      {"message", "interrupted by " + signal_name(signo) +
                      " during a stage that cannot stop early; the outputs of this folder are "
                      "each either their previous or their complete new version"}};
  try {
    write_file_atomic((std::filesystem::path(out_dir_) / "report.json").string(),
                      report.dump(2) + "\n");
  } catch (...) {
  }
  // The main thread may be inside a write: its temporary file goes, and it cannot start
  // another one before the exit below.
  stop_atomic_writes_for_exit();
  remove_atomic_write_leftovers(out_dir_);
  std::cerr << "error: cancelled (" << signal_name(signo) << ")" << std::endl;
  std::_Exit(128 + signo);
}

}  // namespace qs::cli
