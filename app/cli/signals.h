// SIGINT/SIGTERM handling of quadsketch-cli (issue #10): the handler only sets an atomic flag;
// long jobs poll it through a qs::Observer (or cancellation_point()) and throw qs::Cancelled,
// which with_report turns into report.json "status": "cancelled" and main() into exit code
// 128 + signal (130 for SIGINT, 143 for SIGTERM). A second signal kills at once (default
// action). Stages that never poll are covered by a CancelWatchdog.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

#include "core/base/progress.h"

namespace qs::cli {

//! Installs the SIGINT and SIGTERM handlers (once; later calls do nothing).
void install_signal_handlers();

//! Gives SIGINT/SIGTERM back their default action (immediate termination), for commands that
//! do not poll for cancellation; their outputs are written atomically, so nothing tears.
void restore_default_signal_handling();

//! The signal received (SIGINT, SIGTERM), or 0. Async-signal-safe to call.
int received_signal();

//! True once SIGINT or SIGTERM arrived.
inline bool cancel_requested() {
  return received_signal() != 0;
}

//! Throws qs::Cancelled when a signal arrived.
void cancellation_point();

//! Exit code for a cancelled run: 128 + signal, or 1 when no signal was received.
int cancelled_exit_code();

//! "SIGINT", "SIGTERM", or "signal N".
std::string signal_name(int signo);

//! Observer whose should_cancel() is true once a signal arrived (for the pipeline stages).
class SignalObserver : public Observer {
 public:
  bool should_cancel() const override { return cancel_requested(); }
};

//! For tests: forgets a received signal (handlers stay installed).
void reset_received_signal_for_tests();

//! Guards a command that writes into \p out_dir. When a signal arrives and the main thread has
//! not left the guarded scope within \p grace (because it is inside a stage that does not poll
//! for cancellation), the watchdog writes out_dir/report.json with "status": "cancelled",
//! removes the temporary files of unfinished atomic writes (".<name>.tmpXXXXXX") and ends the
//! process with 128 + signal. Every output is written atomically (rename), so each one is then
//! either its old or its new complete version.
class CancelWatchdog {
 public:
  explicit CancelWatchdog(std::string out_dir,
                          std::chrono::milliseconds grace = std::chrono::milliseconds(2000));
  ~CancelWatchdog();
  CancelWatchdog(const CancelWatchdog&) = delete;
  CancelWatchdog& operator=(const CancelWatchdog&) = delete;

 private:
  void watch();

  std::string out_dir_;
  std::chrono::milliseconds grace_;
  std::mutex mutex_;
  std::condition_variable cv_;
  bool done_ = false;  // guarded by mutex_
  std::thread thread_;
};

//! Removes the leftover temporary files of write_file_atomic (".<name>.tmpXXXXXX") in \p dir;
//! returns how many were removed.
int remove_atomic_write_leftovers(const std::string& dir);

}  // namespace qs::cli
