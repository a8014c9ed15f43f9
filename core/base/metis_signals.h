// METIS and signals. GKlib (under METIS) installs, for the duration of every METIS call, a
// SIGTERM and a SIGABRT handler that longjmp()s into a buffer of the calling thread (its
// gk_sigtrap / gk_sigthrow, with the buffers in thread-local storage). The dispositions are
// process-wide: a SIGTERM that arrives meanwhile runs that handler in whichever thread the
// kernel picks, usually the main thread, which has no buffer, and the process crashes (the CLI
// exited with SIGSEGV instead of "cancelled" when signalled while the Pipeline ordered the
// mesh's vertices on its second thread). The CLI's own handlers, which only record the signal
// (app/cli/signals.cpp), are also replaced meanwhile.
//
// QuadSketch calls METIS only through SpdSolver (CHOLMOD's orderings) and
// nested_dissection_ordering. Those calls run inside a MetisSignalGuard: in its scope, in its
// thread, GKlib's attempts to install a SIGTERM handler are ignored, so the process keeps its
// own handler and a SIGTERM is recorded as at any other time. GKlib installs handlers with
// glibc's __sysv_signal; this library defines that function (exported from the executables by
// qs_core's link options), which behaves as glibc's everywhere else. SIGABRT keeps GKlib's
// handling (its out-of-memory path).
#pragma once

namespace qs {

//! While alive, GKlib's SIGTERM handler is not installed by METIS calls on this thread (see
//! above). Nests.
class MetisSignalGuard {
 public:
  MetisSignalGuard();
  ~MetisSignalGuard();
  MetisSignalGuard(const MetisSignalGuard&) = delete;
  MetisSignalGuard& operator=(const MetisSignalGuard&) = delete;
};

//! Whether the interposed __sysv_signal is the one the process uses (the dynamic linker bound
//! METIS's calls to it): false when an executable was linked without qs_core's link options.
bool metis_signal_guard_active();

}  // namespace qs
