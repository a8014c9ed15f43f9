#include "core/base/solver_threads.h"

#include <dlfcn.h>

#include <atomic>
#include <cstdint>
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

thread_local std::uint64_t t_inline_regions = 0;
thread_local std::uint64_t t_forwarded_regions = 0;

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

std::uint64_t inline_parallel_regions_here() {
  return t_inline_regions;
}

std::uint64_t forwarded_parallel_regions_here() {
  return t_forwarded_regions;
}

}  // namespace qs

// libgomp's entry point of every `#pragma omp parallel` compiled by GCC ≥ 4.9 (CHOLMOD's
// included), defined here so that the dynamic linker binds CHOLMOD's calls to this definition
// first (an executable's symbols precede the libraries'). See solver_threads.h: a region that
// libgomp would run with a team of one thread runs inline, without the team's allocation and
// barrier; every other region goes on to libgomp unchanged.
extern "C" void GOMP_parallel(void (*fn)(void*), void* data, unsigned num_threads, unsigned flags) {
  using Parallel = void (*)(void (*)(void*), void*, unsigned, unsigned);
  using GetInt = int (*)();
  static const Parallel next = reinterpret_cast<Parallel>(dlsym(RTLD_NEXT, "GOMP_parallel"));
  static const GetInt max_active_levels =
      reinterpret_cast<GetInt>(dlsym(RTLD_DEFAULT, "omp_get_max_active_levels"));
  static const GetInt active_level =
      reinterpret_cast<GetInt>(dlsym(RTLD_DEFAULT, "omp_get_active_level"));
  // libgomp gives a region one thread when it asks for one (an `if` clause that is false
  // passes 1) or when the active nesting level has reached max-active-levels (0 in a thread
  // limited to one solver thread). Run inline, the region sees the same thread number (0)
  // and team size (1); only omp_get_level() reads one less.
  const bool one_thread = num_threads == 1 || next == nullptr ||
                          (max_active_levels != nullptr && active_level != nullptr &&
                           max_active_levels() <= active_level());
  if (one_thread) {
    ++qs::t_inline_regions;
    fn(data);
    return;
  }
  ++qs::t_forwarded_regions;
  next(fn, data, num_threads, flags);
}

// SuiteSparse's clock (libsuitesparseconfig). Debian's CHOLMOD is built with its timers: its
// supernodal factorization reads this clock before and after every dense BLAS call, only to add
// the differences to cholmod_common's CPU time statistics (CHOLMOD_CPU_GEMM_TIME and the like),
// which QuadSketch never reads, and the reads cost a measurable share of the node
// optimization's main thread. Defined here, as GOMP_parallel above, the dynamic
// linker binds CHOLMOD's calls to this definition: no clock is read and those statistics stay 0.
// Nothing else in the process calls it (CHOLMOD times nothing else with it; QuadSketch times
// with std::chrono).
extern "C" double SuiteSparse_time() {
  return 0.0;
}
