// Process-wide allocator policy for the applications (quadsketch-cli, quadsketch).
//
// Every solve of the pipeline allocates and frees factorizations of tens of megabytes (the
// parameterization factor of the 70K bunny: 3.9 M entries, 31 MB). glibc's malloc serves such
// blocks with fresh mmap()s above its mmap threshold and returns freed heap tops to the kernel
// above its trim threshold, so every solve page-faults its memory in again, and the kernel
// zeroes each page. Two solves on two threads of one process (NodeOptOptions::Run::threads)
// also contend for the process's memory map while they fault. Keeping freed memory for reuse
// removes both. The price is a resident size that does not shrink after a large solve (up to
// the trim threshold of free memory is kept, per malloc arena). glibc gives threads up to 8
// arenas per core; the policy allows one per hardware thread, so the kept memory does not
// multiply with the solver threads that come and go. Time and peak memory with and without it:
// docs/benchmarks.md, "Design measurements".
#pragma once

#include <cstddef>

namespace qs {

//! glibc: mallopt() with an mmap threshold of 32 MB (glibc's maximum; larger blocks still get
//! their own mmap), a trim threshold of 1 GB, a top pad of kept_memory_top_pad() and at most
//! kept_memory_arena_limit() arenas. Leaves the allocator alone when GLIBC_TUNABLES sets any
//! glibc.malloc tunable (the user's choice wins) and on other C libraries. \return true when the
//! policy was applied.
bool keep_freed_memory();

//! The policy's top pad in bytes: 256 MB, or 1/64 of the address-space or data limit
//! (getrlimit RLIMIT_AS, RLIMIT_DATA; `ulimit -v`, `ulimit -d`) when that is smaller, since
//! the pad counts against the limit.
std::size_t kept_memory_top_pad();

//! The policy's arena count: one per hardware thread, at least 2.
int kept_memory_arena_limit();

}  // namespace qs
