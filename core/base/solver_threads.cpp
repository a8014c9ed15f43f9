#include "core/base/solver_threads.h"

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>

namespace qs {

namespace {

constexpr int kDefaultThreads = 1;

std::atomic<int> g_threads{kDefaultThreads};
std::atomic<int> g_version{1};        // bumped by every set_solver_threads
std::atomic<bool> g_explicit{false};  // set_solver_threads(n > 0) was called
thread_local int t_applied_version = 0;

// The libraries are linked through CHOLMOD (libgomp, libblas → OpenBLAS on Debian), not by
// qs_core itself, so their entry points are looked up instead of linked: a build with another
// BLAS or without OpenMP still works, and the lookup finds nothing.
template <typename Fn>
Fn lookup(const char* name) {
  return reinterpret_cast<Fn>(dlsym(RTLD_DEFAULT, name));
}

void set_openblas_threads(int n) {
  using SetThreads = void (*)(int);
  static const SetThreads set = lookup<SetThreads>("openblas_set_num_threads");
  if (set) set(n);
}

}  // namespace

void set_solver_threads(int n) {
  const int threads = n <= 0 ? kDefaultThreads : n;
  g_threads.store(threads);
  g_explicit.store(n > 0);
  g_version.fetch_add(1);
  set_openblas_threads(threads);
  limit_solver_threads_here();
}

int solver_threads() {
  return g_threads.load();
}

void limit_solver_threads_here() {
  const int version = g_version.load();
  if (t_applied_version == version) return;
  t_applied_version = version;
  using SetInt = void (*)(int);
  static const SetInt set_dynamic = lookup<SetInt>("omp_set_dynamic");
  static const SetInt set_max_active_levels = lookup<SetInt>("omp_set_max_active_levels");
  static const SetInt set_num_threads = lookup<SetInt>("omp_set_num_threads");
  const int threads = g_threads.load();
  if (set_num_threads) set_num_threads(threads);
  if (threads <= 1) {
    if (set_max_active_levels) set_max_active_levels(0);
  } else {
    if (set_max_active_levels) set_max_active_levels(1);
    if (set_dynamic) set_dynamic(1);
  }
  // The default leaves an OPENBLAS_NUM_THREADS of the environment alone.
  static std::atomic<bool> blas_applied{false};
  if (!blas_applied.exchange(true) && (g_explicit.load() || !std::getenv("OPENBLAS_NUM_THREADS")))
    set_openblas_threads(threads);
}

}  // namespace qs
