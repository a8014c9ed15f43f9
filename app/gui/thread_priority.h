// Scheduling priority of the editor's solver threads. The UI thread and the GL driver's
// rasterizer threads (llvmpipe) must win the CPU over the optimization, or a running job
// starves the frame loop on machines with few cores; the solver still gets every idle cycle.
#pragma once

namespace qs::app {

//! Linux: sets the nice value of the calling thread to \p nice (0..19; a larger value is a
//! lower priority) unless it is already at least that, and does the same for the process's
//! other threads except the main (UI) thread and Mesa's rasterizer threads ("llvmpipe-N").
//! Those others are the math libraries' pools (OpenBLAS, OpenMP) that the solver keeps busy.
//! Threads the calling thread creates later inherit its value. Returns the number of threads
//! changed; 0 on other systems or when \p nice <= 0.
int lower_solver_thread_priority(int nice);

//! Nice value of the thread \p tid (Linux; 0 elsewhere or on error). For tests.
int thread_nice(int tid);

//! Kernel id of the calling thread (Linux gettid; 0 elsewhere).
int current_thread_id();

}  // namespace qs::app
