// Node-optimization step cost (issue #5): per-step time of optimize_nodes against one
// parameterization factorization + solve measured in the same process. Not a test.
//
//   qs_nodeopt_bench MESH LAYOUT [STEPS=10] [REPEATS=3] [descent] [fresh] [parallel] [steps]
//
// default-malloc: glibc's allocator defaults instead of the applications' keep_freed_memory().
// descent: no hop polish and no fold-over removal after the descent (only the STEPS descent
// steps are timed in "optimize"); fresh: NodeOptOptions::Run::reuse_field off (a fresh Pipeline
// per trial with re-routed arcs); parallel: NodeOptOptions::Run::threads = 3 (the retry without
// switches beside its trial; otherwise 2); steps: print every step.
// Times are CPU seconds of the process (CLOCK_PROCESS_CPUTIME_ID: wall time is meaningless
// on a shared, overloaded machine); run with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1
// OMP_THREAD_LIMIT=1 so that no spinning helper thread is counted (Debian's CHOLMOD asks for 4
// OpenMP threads in its supernodal factorization whatever OMP_NUM_THREADS says); OMP_NUM_THREADS
// also sets the library's solver thread limit (set_solver_threads), which sizes OpenBLAS's pool. A
// step's time runs from one observer report to the next. Prints one line per repeat and a summary:
// the median over repeats of the fresh pipeline (field + parameterization setup and solve), of one
// parameterization re-solve (assembly + CHOLMOD numeric factorization + back-substitution on the
// same ParamSolver), of the median descent step, and their ratio; plus the optimizer's work
// counters.
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/base/allocator.h"
#include "core/base/solver_threads.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"

namespace {

double cpu_now() {
  return qs::bench::cpu_seconds();
}

// CPU time between consecutive reports of descent steps.
struct StepTimer : qs::Observer {
  double last = 0;
  std::vector<double> descent;
  bool verbose = false;
  void on_step(const qs::StepReport& r) override {
    const double now = cpu_now();
    if (r.phase == "descent") descent.push_back(now - last);
    if (verbose)
      std::printf("  step %d %s: E %.9g %s, fold-overs %d, moved %d, %.3f s CPU\n", r.step,
                  r.phase.c_str(), r.E, r.accepted ? "accepted" : "rejected", r.foldovers,
                  r.moved_nodes, now - last);
    last = now;
  }
};

using qs::bench::median;

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(
        stderr,
        "usage: %s MESH LAYOUT [STEPS=10] [REPEATS=3] [descent] [fresh] [parallel] [steps] "
        "[default-malloc] [split=N]\n",
        argv[0]);
    return 2;
  }
  // The library's own thread limit (core/base/solver_threads.h, default 2) resizes OpenBLAS's
  // pool whatever OPENBLAS_NUM_THREADS says, and an idle pool thread spins on CPU time: follow
  // OMP_NUM_THREADS so that one-thread runs count one thread.
  if (const char* threads = std::getenv("OMP_NUM_THREADS"))
    if (std::atoi(threads) > 0) qs::set_solver_threads(std::atoi(threads));
  try {
    const qs::TriMesh mesh = qs::load_mesh(argv[1]);
    const qs::Layout layout = qs::load_layout(argv[2], mesh);
    const int steps = argc > 3 ? std::atoi(argv[3]) : 10;
    const int repeats = argc > 4 ? std::atoi(argv[4]) : 3;
    // Flags after REPEATS: "descent" (no hop polish, no fold-over removal at the end), "fresh"
    // (NodeOptOptions::Run::reuse_field off: a fresh Pipeline per trial with re-routed arcs).
    // "steps": print every step.
    bool descent_only = false, fresh_trials = false, verbose = false, parallel = false;
    bool keep_memory = true;
    int max_cluster_faces = -1;  // split=N: CrossFieldOptions::max_cluster_faces
    for (int k = 5; k < argc; ++k) {
      if (std::string(argv[k]).rfind("split=", 0) == 0) max_cluster_faces = std::atoi(argv[k] + 6);
      keep_memory &= std::string(argv[k]) != "default-malloc";
      descent_only |= std::string(argv[k]) == "descent";
      fresh_trials |= std::string(argv[k]) == "fresh";
      parallel |= std::string(argv[k]) == "parallel";
      verbose |= std::string(argv[k]) == "steps";
    }
    // As quadsketch-cli and the GUI do (core/base/allocator.h); "default-malloc": glibc's
    // defaults (every solve page-faults its factorization in again).
    if (keep_memory) qs::keep_freed_memory();
    qs::PipelineOptions options;
    if (max_cluster_faces >= 0) options.field.max_cluster_faces = max_cluster_faces;
    std::vector<double> fresh, resolve, step, total, ratio;
    for (int rep = 0; rep < repeats; ++rep) {
      double t0 = cpu_now();
      qs::Pipeline p(mesh, layout, options);
      p.compute_field();
      p.compute_parameterization();
      fresh.push_back(cpu_now() - t0);
      // One more parameterization solve on the same solver: assembly + numeric factorization
      // + back-substitution (the symbolic analysis is kept).
      t0 = cpu_now();
      p.compute_parameterization();
      resolve.push_back(cpu_now() - t0);

      qs::NodeOptOptions no;
      no.descent.max_steps = steps;
      no.run.reuse_field = !fresh_trials;
      no.run.threads = parallel ? 3 : 2;
      if (descent_only) {
        no.polish.enabled = false;
        no.tuning.stall_gain = 0;  // all STEPS steps, as the 25-step target counts them
        no.folds.orientation = false;
        no.folds.stiffen = false;
      }
      qs::NodeOptStats stats;
      StepTimer timer;
      timer.verbose = verbose;
      t0 = timer.last = cpu_now();
      const auto wall0 = std::chrono::steady_clock::now();
      const qs::NodeOptResult r =
          qs::optimize_nodes(mesh, layout, options, no, &timer, nullptr, &stats);
      total.push_back(cpu_now() - t0);
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
      step.push_back(median(timer.descent));
      ratio.push_back(step.back() / resolve.back());
      std::printf(
          "repeat %d: fresh pipeline %.3f s, param re-solve %.3f s, median step %.3f s "
          "(%.1fx), optimize %.3f s CPU (%.3f s wall), steps %d (accepted %d), E %.6g -> %.6g, "
          "fresh pipelines %d, relayouts %d (%d beside their retry, %d with the parameterization "
          "set up beside the field), reused solves %d, gradient reuses %d, tabu steps %d\n",
          rep, fresh.back(), resolve.back(), step.back(), ratio.back(), total.back(), wall, r.steps,
          r.accepted, r.E_init, r.E_final, stats.fresh_pipelines, stats.relayouts,
          stats.parallel_retries, stats.prepared_param_solvers, stats.reused_solves,
          stats.gradient_reuses, stats.tabu_steps);
    }
    std::printf(
        "median: faces %zu, nodes %zu, fresh pipeline %.3f s, param re-solve %.3f s, median "
        "step %.3f s, step / re-solve %.1f, optimize %.3f s\n",
        static_cast<size_t>(mesh.n_faces()), layout.nodes.size(), median(fresh), median(resolve),
        median(step), median(ratio), median(total));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qs_nodeopt_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
