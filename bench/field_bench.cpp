// Cross-field stage benchmark (issue #3): not a test. Times every sub-stage of the field
// (curvature + constraints, period jumps, assembly, factorizations, warm start, conflict
// passes, solve), one stand-alone CHOLMOD analysis + factorization + solve of the same field
// matrix for comparison, and the re-solve after node vertices moved (geometry update + solve,
// factorization reused). Without a layout only the layout-free parts are timed (geometry,
// curvature, reliable set, constraints), e.g. on the 70K-face bunny.
//
//   qs_field_bench --mesh M [--layout L [--moved-layout L2]] [--repeat N]
//
// --moved-layout: the same layout with nodes moved to other vertices (quadsketch-cli perturb):
// times CrossFieldSolver::update_layout (new period jumps, factorization reused). Run with
// OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 for the CPU-time ratio (one thread, no spinning).
//
// Each time is the median over N runs (default 5) in one process; ratios are taken against
// the stand-alone factorization measured in the same run (the machine is shared and noisy).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_util.h"
#include "core/base/allocator.h"
#include "core/base/spd_solver.h"
#include "core/field/cross_field.h"
#include "core/field/curvature.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh_io.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// CPU seconds of the whole process (all threads): with OMP_NUM_THREADS=1 and
// OPENBLAS_NUM_THREADS=1 this is the compute cost, insensitive to other load on the machine.
using qs::bench::cpu_seconds;
using qs::bench::median;

std::string cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown";
}

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

// Median of f() over n runs, in seconds.
double time_median(int n, const std::function<void()>& f) {
  std::vector<double> t;
  for (int i = 0; i < n; ++i) {
    const auto t0 = Clock::now();
    f();
    t.push_back(seconds_since(t0));
  }
  return median(t);
}

void row(const char* name, double s, double unit) {
  std::printf("  %-34s %9.2f ms  %7.2f x\n", name, 1e3 * s, unit > 0 ? s / unit : 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  qs::keep_freed_memory();  // as quadsketch-cli and the GUI (core/base/allocator.h)
  std::string mesh_path, layout_path, moved_path;
  int repeat = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--mesh" && i + 1 < argc)
      mesh_path = argv[++i];
    else if (a == "--layout" && i + 1 < argc)
      layout_path = argv[++i];
    else if (a == "--moved-layout" && i + 1 < argc)
      moved_path = argv[++i];
    else if (a == "--repeat" && i + 1 < argc)
      repeat = std::max(1, std::atoi(argv[++i]));
    else {
      std::fprintf(
          stderr, "usage: qs_field_bench --mesh M [--layout L [--moved-layout L2]] [--repeat N]\n");
      return 1;
    }
  }
  if (mesh_path.empty()) {
    std::fprintf(stderr, "qs_field_bench: --mesh is required\n");
    return 1;
  }
  try {
    qs::TriMesh mesh = qs::load_mesh(mesh_path);
    std::printf("machine: %s, %u hardware threads, load average %s\n", cpu_model().c_str(),
                std::thread::hardware_concurrency(), load_average().c_str());
    std::printf("mesh: %s (%zu vertices, %zu faces)\n", mesh_path.c_str(), mesh.n_vertices(),
                mesh.n_faces());
    std::printf("median of %d runs\n", repeat);

    qs::GeometryCache g;
    const double geometry_s = time_median(repeat, [&] { g = qs::build_geometry(mesh); });
    qs::Curvature curvature;
    const double curvature_s =
        time_median(repeat, [&] { curvature = qs::compute_curvature(mesh, g); });
    qs::ConstraintOptions copt;
    qs::FieldConstraints constraints;
    const double collect_s = time_median(
        repeat, [&] { constraints = qs::collect_constraints(mesh, g, nullptr, copt, &curvature); });

    if (layout_path.empty()) {
      std::printf("no layout: layout-free parts only (%d reliable faces, %zu constraints)\n",
                  curvature.reliable_faces, constraints.face.size());
      std::printf("  %-34s %9.2f ms\n", "geometry cache", 1e3 * geometry_s);
      std::printf("  %-34s %9.2f ms\n", "curvature + reliable set", 1e3 * curvature_s);
      std::printf("  %-34s %9.2f ms\n", "constraints (no layout)", 1e3 * collect_s);
      // The field matrix these constraints give (it does not depend on the layout).
      std::vector<Eigen::Triplet<double>> t;
      for (int e = 0; e < g.n_edges; ++e) {
        const int i = g.edge_face_i[e], j = g.edge_face_j[e];
        if (i < 0 || j < 0) continue;
        t.emplace_back(i, i, 1.0);
        t.emplace_back(j, j, 1.0);
        t.emplace_back(std::max(i, j), std::min(i, j), -1.0);
      }
      for (int f : constraints.face) t.emplace_back(f, f, 100.0);
      if (constraints.face.empty()) t.emplace_back(0, 0, 100.0);
      Eigen::SparseMatrix<double> A(g.n_faces, g.n_faces);
      A.setFromTriplets(t.begin(), t.end());
      std::vector<double> an, fa, cpu;
      for (int i = 0; i < repeat; ++i) {
        qs::SpdSolver s("bench");
        const double c0 = cpu_seconds();
        auto t0 = Clock::now();
        s.analyze(A);
        an.push_back(seconds_since(t0));
        t0 = Clock::now();
        s.factorize(A);
        fa.push_back(seconds_since(t0));
        cpu.push_back(cpu_seconds() - c0);
      }
      std::printf("  %-34s %9.2f ms\n", "field matrix: CHOLMOD analysis", 1e3 * median(an));
      std::printf("  %-34s %9.2f ms\n", "field matrix: CHOLMOD factorization", 1e3 * median(fa));
      std::printf("  %-34s %9.2f ms\n", "  (analysis + factorization, CPU)", 1e3 * median(cpu));
      return 0;
    }

    const qs::Layout layout = qs::load_layout(layout_path, mesh);
    const qs::ValidationResult validation = qs::validate_layout(mesh, layout);
    if (!validation.valid()) {
      std::fprintf(stderr, "qs_field_bench: invalid layout (%d errors)\n", validation.errors());
      return 2;
    }
    const qs::LayoutTopology topology = qs::build_topology(mesh, layout);
    std::printf("layout: %s (%zu nodes, %zu arcs)\n", layout_path.c_str(), layout.nodes.size(),
                layout.arcs.size());

    // The whole stage, as the pipeline runs it.
    std::vector<qs::CrossFieldTimings> runs;
    std::vector<double> totals, totals_cpu;
    std::unique_ptr<qs::CrossFieldSolver> solver;
    for (int i = 0; i < repeat; ++i) {
      solver.reset();
      const auto t0 = Clock::now();
      const double c0 = cpu_seconds();
      solver = std::make_unique<qs::CrossFieldSolver>(mesh, g, layout, topology);
      totals_cpu.push_back(cpu_seconds() - c0);
      totals.push_back(seconds_since(t0));
      runs.push_back(solver->field().timings);
    }
    auto med = [&](double qs::CrossFieldTimings::*m) {
      std::vector<double> v;
      for (const auto& t : runs) v.push_back(t.*m);
      return median(v);
    };
    const qs::CrossField& field = solver->field();
    const qs::CrossFieldTimings& last = field.timings;

    // One stand-alone CHOLMOD analysis + factorization + solve of the same matrix.
    const Eigen::SparseMatrix<double>& A = solver->matrix();
    const Eigen::VectorXd b = Eigen::VectorXd::Random(A.rows());
    double analyze_s = 0, factor_s = 0, solve_s = 0, unit_cpu = 0;
    {
      std::vector<double> an, fa, so, cpu;
      for (int i = 0; i < repeat; ++i) {
        qs::SpdSolver s("bench");
        const double c0 = cpu_seconds();
        auto t0 = Clock::now();
        s.analyze(A);
        an.push_back(seconds_since(t0));
        t0 = Clock::now();
        s.factorize(A);
        fa.push_back(seconds_since(t0));
        cpu.push_back(cpu_seconds() - c0);
        t0 = Clock::now();
        const Eigen::VectorXd x = s.solve(b);
        so.push_back(seconds_since(t0));
        if (!x.allFinite()) return 3;
      }
      analyze_s = median(an), factor_s = median(fa), solve_s = median(so);
      unit_cpu = median(cpu);
      if (std::getenv("QS_BENCH_VERBOSE")) {
        for (size_t i = 0; i < fa.size(); ++i)
          std::printf(
              "  run %zu: analysis %.2f ms, factorization %.2f ms; stage %.2f ms with %d "
              "factorizations taking %.2f ms\n",
              i, 1e3 * an[i], 1e3 * fa[i], 1e3 * totals[i], runs[i].factorizations,
              1e3 * runs[i].factorize_s);
      }
    }
    const double unit = analyze_s + factor_s;

    // Re-solve after node vertices moved: move every node vertex by 5% of the mean edge length
    // in its first face's plane, update the geometry (κ continued) and re-solve.
    qs::TriMesh moved = mesh;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> uni(-1, 1);
    for (const auto& n : layout.nodes) {
      const auto v = moved.vertex_handle(n.vertex);
      const qs::Vec3 d(uni(rng), uni(rng), uni(rng));
      moved.set_point(v, moved.point(v) + 0.05 * g.mean_edge_length * d);
    }
    qs::GeometryCache gm = g;
    const double update_s = time_median(repeat, [&] {
      gm = g;
      qs::update_geometry(moved, gm);
    });
    const double resolve_s = time_median(repeat, [&] { solver->solve(gm); });
    const int resolve_passes = solver->field().timings.rounding_passes;

    std::printf(
        "field: %d constraints (%d curvature, %d feature, %d boundary), %d clusters, "
        "%d dropped; matrix %ld x %ld, %ld non-zeros (lower)\n",
        static_cast<int>(field.constraints.face.size()),
        field.constraints.count(qs::ConstraintKind::Curvature),
        field.constraints.count(qs::ConstraintKind::Feature),
        field.constraints.count(qs::ConstraintKind::Boundary), field.clusters,
        field.dropped_clusters, static_cast<long>(A.rows()), static_cast<long>(A.cols()),
        static_cast<long>(A.nonZeros()));
    std::printf("setup: %d factorizations, %d solves, %d conflict passes, %d rounding passes\n",
                last.factorizations, last.solves, last.conflict_passes, last.rounding_passes);
    std::printf(
        "reference: one CHOLMOD analysis %.2f ms + factorization %.2f ms = %.2f ms "
        "(unit below); one solve %.2f ms\n",
        1e3 * analyze_s, 1e3 * factor_s, 1e3 * unit, 1e3 * solve_s);
    std::printf("  %-34s %9s     %9s\n", "stage", "time", "/ unit");
    row("geometry cache (not in the stage)", geometry_s, unit);
    row("curvature + constraints", med(&qs::CrossFieldTimings::curvature_s), unit);
    row("period jumps", med(&qs::CrossFieldTimings::period_jumps_s), unit);
    row("clusters + assembly", med(&qs::CrossFieldTimings::assemble_s), unit);
    row("factorizations (all)", med(&qs::CrossFieldTimings::factorize_s), unit);
    row("warm start (w/o factorization)", med(&qs::CrossFieldTimings::warm_start_s), unit);
    row("last setup solve + rounding", med(&qs::CrossFieldTimings::solve_s), unit);
    row("conflict passes (w/o factorization)", med(&qs::CrossFieldTimings::conflicts_s), unit);
    row("whole field stage", median(totals), unit);
    std::printf(
        "  %-34s %9.2f ms  %7.2f x  (CPU time / CPU time of one analysis + "
        "factorization, %.2f ms)\n",
        "whole field stage, CPU time", 1e3 * median(totals_cpu), median(totals_cpu) / unit_cpu,
        1e3 * unit_cpu);
    row("re-solve: update_geometry", update_s, unit);
    row("re-solve: solve (moved nodes)", resolve_s, unit);
    std::printf("  (re-solve rounding passes: %d)\n", resolve_passes);
    if (!moved_path.empty()) {
      const qs::Layout moved_layout = qs::load_layout(moved_path, mesh);
      if (!qs::validate_layout(mesh, moved_layout).valid()) {
        std::fprintf(stderr, "qs_field_bench: invalid moved layout\n");
        return 2;
      }
      const qs::LayoutTopology moved_topology = qs::build_topology(mesh, moved_layout);
      std::vector<double> pj, cpu;
      const double update_layout_s = time_median(repeat, [&] {
        const double c0 = cpu_seconds();
        solver->update_layout(mesh, g, moved_layout, moved_topology);
        cpu.push_back(cpu_seconds() - c0);
        pj.push_back(solver->field().timings.period_jumps_s);
      });
      row("re-solve: update_layout (moved)", update_layout_s, unit);
      std::printf("  %-34s %9.2f ms  %7.2f x  (CPU)\n", "  update_layout, CPU time",
                  1e3 * median(cpu), median(cpu) / unit_cpu);
      row("  of which period jumps", median(pj), unit);
      std::printf("  (update_layout: %d factorizations in total, unchanged)\n",
                  solver->field().timings.factorizations);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qs_field_bench: %s\n", e.what());
    return 2;
  }
  return 0;
}
