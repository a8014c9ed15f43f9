// Threads of the math libraries under the solvers: OpenBLAS's thread pool (dense kernels of
// CHOLMOD's supernodal factorization) and the OpenMP regions inside CHOLMOD.
//
// Debian's CHOLMOD (SuiteSparse 5.12) is built with CHOLMOD_OMP_NUM_THREADS = 4: each supernode
// of a factorization opens parallel regions with 4 threads whatever OMP_NUM_THREADS says. On
// small and medium systems (all of a node-optimization step's solves) waking and parking those
// threads costs far more than the arithmetic: on the bundled example `optimize` spent 1.3 s in
// the kernel (futex / sched_yield) for 0.4 s of user time. Only OMP_THREAD_LIMIT in the
// environment caps such a clause, and libgomp reads it before main(), so the cap here works per
// thread instead: OpenMP's per-thread settings are applied by limit_solver_threads_here() in
// every thread that calls CHOLMOD (SpdSolver does it).
//
// Such a capped region still costs libgomp a team: an allocation, a barrier and a futex wake
// per region, and CHOLMOD opens up to three regions per supernode, millions in a node
// optimization of a large model (docs/benchmarks.md, "Design measurements"). solver_threads.cpp
// therefore defines libgomp's GOMP_parallel itself; the dynamic linker binds CHOLMOD's calls to
// it first. A region that libgomp would give one thread (it asks for one, or the thread's
// max-active-levels is reached) runs inline in the calling thread, with the same thread number
// and team size; every other region is passed on to libgomp unchanged.
#pragma once

#include <cstdint>

namespace qs {

//! Sets how many threads the math libraries may use, process-wide (n ≥ 1; 0 restores the
//! default, 1). OpenBLAS's pool is resized at once (when the library is OpenBLAS); the OpenMP
//! part takes effect in each solver thread at its next limit_solver_threads_here().
//! The default is 1: on two cores more threads gave the same wall time for much more CPU
//! (OpenBLAS's and libgomp's idle threads spin; docs/benchmarks.md). Without a set_solver_threads
//! call an OPENBLAS_NUM_THREADS of the environment is kept.
void set_solver_threads(int n);

//! The current limit (≥ 1).
int solver_threads();

//! Applies the limit to the calling thread's OpenMP settings: with 1 thread, parallel regions
//! run serially (max active levels 0); with more, libgomp's dynamic adjustment is switched on,
//! so a region gets at most as many threads as the machine has idle cores (never CHOLMOD's 4
//! on 2 cores). A no-op after the first call in a thread until the limit changes. Safe when
//! OpenMP or OpenBLAS is absent (looked up at run time).
void limit_solver_threads_here();

//! OpenMP parallel regions the calling thread ran inline (one thread, see above), and those it
//! passed on to libgomp, since the thread started. For tests and diagnostics.
std::uint64_t inline_parallel_regions_here();
std::uint64_t forwarded_parallel_regions_here();

}  // namespace qs
