#include "core/base/metis_signals.h"

#include <dlfcn.h>

#include <csignal>

namespace {

thread_local int tl_guard_depth = 0;

}  // namespace

// glibc's SysV-semantics signal(): the handler is reset to the default action when a signal is
// delivered, and the signal is not blocked while its handler runs. Within a MetisSignalGuard,
// installing a SIGTERM handler is refused silently (the current one is returned as if it had
// been replaced), so GKlib's later restore call restores nothing either.
extern "C" __sighandler_t __sysv_signal(int sig, __sighandler_t handler) noexcept {
  struct sigaction action {
  }, previous{};
  if (tl_guard_depth > 0 && sig == SIGTERM) {
    if (sigaction(sig, nullptr, &previous) < 0) return SIG_ERR;
    return previous.sa_handler;
  }
  action.sa_handler = handler;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_NODEFER;
  if (sigaction(sig, &action, &previous) < 0) return SIG_ERR;
  return previous.sa_handler;
}

namespace qs {

MetisSignalGuard::MetisSignalGuard() {
  ++tl_guard_depth;
}

MetisSignalGuard::~MetisSignalGuard() {
  --tl_guard_depth;
}

bool metis_signal_guard_active() {
  // The definition the dynamic linker resolves for everyone (the executable's, when exported).
  void* bound = dlsym(RTLD_DEFAULT, "__sysv_signal");
  return bound == reinterpret_cast<void*>(&__sysv_signal);
}

}  // namespace qs
