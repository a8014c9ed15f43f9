// Process-wide allocator policy for the applications (quadsketch-cli, quadsketch).
//
// Every solve of the pipeline allocates and frees factorizations of tens of megabytes (the
// parameterization factor of the 70K bunny: 3.9 M entries, 31 MB). glibc's malloc serves such
// blocks with fresh mmap()s above its mmap threshold and returns freed heap tops to the kernel
// above its trim threshold, so every solve page-faults its memory in again, and the kernel
// zeroes each page. Two solves on two threads of one process (NodeOptOptions::parallel_hops)
// also contend for the process's memory map while they fault. Keeping freed memory for reuse
// removes both: on the 70K bunny, `optimize` took 71 s instead of 84 s with parallel hops
// (the hop sweeps 12–13 s instead of 16–18 s each, kernel time 3.8 s instead of 16 s).
// The price is a resident size that does not shrink after a large solve (up to the trim
// threshold of free memory is kept).
#pragma once

namespace qs {

//! glibc: mallopt() with an mmap threshold of 32 MB (glibc's maximum; larger blocks still get
//! their own mmap), a trim threshold of 1 GB and a top pad of 256 MB. Leaves the allocator
//! alone when GLIBC_TUNABLES sets any glibc.malloc tunable (the user's choice wins) and on
//! other C libraries. \return true when the policy was applied.
bool keep_freed_memory();

}  // namespace qs
