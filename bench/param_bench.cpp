// Parameterization stage cost (issue #4): builds ParamSolver (cut graph, labels, constraint
// rows, exact elimination, reduced-matrix patterns, analysis, factorization, solve) and traces
// the layout's arcs on the result (extract_layout), on a mesh and layout, and compares the stage
// with one stand-alone CHOLMOD numeric factorization + solve of the same reduced matrix measured
// in the same run (through SpdSolver reading the upper triangle, as the stage does: the first
// factorization after its own analysis, like the stage's). Not a test.
//
//   qs_param_bench --mesh M --layout L [--repeat N] [--detail] [--one-thread]
//                  [--one-thread-trace] [--default-malloc] [--no-vertex-order]
//
// The stage runs with the Pipeline's parameterization options: on meshes of at least 10 000
// faces they carry the vertex order the Pipeline computed on its second thread beside the field
// (PipelineOptions::order_vertices; its time is printed, it is not part of the stage), so the
// stage's analysis is symbolic only. The unit keeps CHOLMOD's own AMD analysis (not timed) and
// so its ordering. --no-vertex-order: AMD in the stage too.
//
// The allocator keeps freed memory for reuse, as quadsketch-cli and the GUI do
// (keep_freed_memory, core/base/allocator.h); --default-malloc keeps glibc's defaults, under
// which every solve page-faults its factorization in again (that slows the unit more than the
// stage).
//
// Stage and unit are measured in process CPU seconds and in wall seconds. The stage labels the
// layout beside the cut graph and analyzes the reduced matrix beside the energy assembly on a
// second thread (ParamOptions::second_thread; --one-thread turns it off), and traces half of
// the arcs of large layouts on a second thread (TraceOptions::second_thread_arcs;
// --one-thread-trace turns it off), so its wall time is the one a user waits on two cores, and
// its CPU time counts both threads.
// --detail adds, per repeat, the setup's parts (cut graph, labels, elimination, reduced-matrix
// patterns) and CHOLMOD's symbolic analysis of the reduced matrix with its orderings: the
// default (AMD, METIS when AMD fills a lot), AMD only, METIS only, and AMD on the wedge quotient
// graph (grouped_amd_ordering, used by ParamOptions::wedge_ordering) with nnz(L) and the numeric
// factorization + solve time of each (best of 3), and the unit's factorization + solve (best of
// 3) reading the upper and the lower triangle.
//
// Run with OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 OMP_THREAD_LIMIT=1 for CPU times that a
// loaded machine does not inflate (Debian's CHOLMOD starts 4 OpenMP threads otherwise, and
// their spinning is counted in the unit). Prints one line per repeat (CPU seconds; the parts in
// parentheses are wall seconds) and the medians.
#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/base/allocator.h"
#include "core/base/spd_solver.h"
#include "core/extract/tracing.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"

namespace {

using qs::bench::cpu_seconds;
using qs::bench::median;
using qs::bench::wall_seconds;

// Eigen's supernodal LLᵀ with an analysis from a given ordering (as SpdSolver's).
class Llt : public Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> {
 public:
  Llt() { cholmod().print = 0; }
  void analyze_given(const Eigen::SparseMatrix<double>& A, std::vector<int>& perm) {
    cholmod_sparse a = Eigen::viewAsCholmod(A.selfadjointView<Eigen::Lower>());
    cholmod().nmethods = 1;
    cholmod().method[0].ordering = CHOLMOD_GIVEN;
    m_cholmodFactor = cholmod_analyze_p(&a, perm.data(), nullptr, 0, &cholmod());
    m_isInitialized = true;
    m_info = m_cholmodFactor ? Eigen::Success : Eigen::NumericalIssue;
    m_analysisIsOk = m_cholmodFactor != nullptr;
    m_factorizationIsOk = false;
  }
};

// One analysis variant: nmethods/ordering (CHOLMOD's), or a given permutation. Prints the
// analysis CPU time, nnz(L) and flops of the chosen ordering, and the factorization + solve CPU
// time.
void analysis_variant(const char* name, const Eigen::SparseMatrix<double>& A, int nmethods,
                      int ordering, std::vector<int>* perm, double extra_s) {
  Llt llt;
  double c0 = cpu_seconds();
  if (perm) {
    llt.analyze_given(A, *perm);
  } else {
    llt.cholmod().nmethods = nmethods;
    if (nmethods == 1) llt.cholmod().method[0].ordering = ordering;
    llt.analyzePattern(A);
  }
  const double analyze = cpu_seconds() - c0 + extra_s;
  const cholmod_common& c = llt.cholmod();
  const double lnz = c.lnz, fl = c.fl;
  const int chosen = perm ? CHOLMOD_GIVEN : c.method[c.selected].ordering;
  // Best of 3: the factorization time of an ordering, with less load noise.
  double unit = 1e30;
  Eigen::VectorXd x;
  for (int k = 0; k < 3; ++k) {
    c0 = cpu_seconds();
    llt.factorize(A);
    x = llt.solve(Eigen::VectorXd::Ones(A.rows()));
    unit = std::min(unit, cpu_seconds() - c0);
  }
  std::printf("  %-14s analyze %.4f (ordering %d) nnz(L) %.0f flops %.3g factorize+solve %.4f%s\n",
              name, analyze, chosen, lnz, fl, unit, x.allFinite() ? "" : " (failed)");
}

}  // namespace

int main(int argc, char** argv) {
  std::string mesh_path, layout_path;
  int repeat = 3;
  bool detail = false;
  bool second_thread = true;
  bool keep_memory = true;
  bool vertex_order = true;
  qs::TraceOptions trace_options;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--detail")) detail = true;
    if (!std::strcmp(argv[i], "--one-thread")) second_thread = false;
    if (!std::strcmp(argv[i], "--one-thread-trace")) trace_options.second_thread_arcs = 0;
    if (!std::strcmp(argv[i], "--default-malloc")) keep_memory = false;
    if (!std::strcmp(argv[i], "--no-vertex-order")) vertex_order = false;
  }
  // As quadsketch-cli and the GUI do (core/base/allocator.h): freed blocks are reused instead
  // of being page-faulted in again by every solve. --default-malloc: glibc's defaults.
  if (keep_memory) qs::keep_freed_memory();
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--mesh"))
      mesh_path = argv[i + 1];
    else if (!std::strcmp(argv[i], "--layout"))
      layout_path = argv[i + 1];
    else if (!std::strcmp(argv[i], "--repeat"))
      repeat = std::max(1, std::atoi(argv[i + 1]));
  }
  if (mesh_path.empty() || layout_path.empty()) {
    std::fprintf(stderr, "usage: qs_param_bench --mesh M --layout L [--repeat N]\n");
    return 2;
  }
  try {
    qs::TriMesh mesh = qs::load_mesh(mesh_path);
    qs::Layout layout = qs::load_layout(layout_path, mesh);
    qs::PipelineOptions options;
    options.field.constraints.sharp_angle_deg = 35;  // the CLI's default
    options.param.second_thread = second_thread;
    options.order_vertices = vertex_order;
    qs::Pipeline p(std::move(mesh), std::move(layout), options);
    const qs::CrossField& field = p.compute_field();
    // The pipeline's parameterization options: with its vertex order, when it computed one
    // beside the field (PipelineOptions::order_vertices).
    options.param = p.options().param;
    std::printf("faces %d, nodes %zu, arcs %zu\n", p.geometry().n_faces, p.layout().nodes.size(),
                p.layout().arcs.size());
    if (options.param.vertex_order) {
      const double c0 = cpu_seconds();
      const std::vector<int> order = qs::vertex_nested_dissection(p.geometry());
      std::printf(
          "vertex order (nested dissection of the mesh's vertices, computed by the pipeline on "
          "its second thread beside the field, not part of the stage): %.4f s CPU\n",
          cpu_seconds() - c0);
    } else {
      std::printf("no vertex order: AMD on each reduced matrix\n");
    }
    std::vector<double> stages, units, ratios, stages_wall, units_wall, ratios_wall;
    for (int r = 0; r < repeat; ++r) {
      const double c0 = cpu_seconds(), w0 = wall_seconds();
      const qs::ParamSolver solver(p.mesh(), p.geometry(), p.layout(), p.topology(),
                                   field.period_jump, field.theta, options.param);
      const double solve = cpu_seconds() - c0;
      const qs::Parameterization& res = solver.result();
      const double t0 = cpu_seconds(), tw0 = wall_seconds();
      const qs::Extraction ex =
          qs::extract_layout(p.mesh(), p.geometry(), p.layout(), p.topology(), solver.labeling(),
                             field.period_jump, res.corner_uv, trace_options);
      const double trace = cpu_seconds() - t0, trace_wall = wall_seconds() - tw0;
      const double stage = solve + trace;
      const double stage_wall = wall_seconds() - w0;
      // The unit: the same reduced matrix, analyzed apart, then factorized and solved.
      qs::ReducedAssembly assembly(solver.cut_graph().corner_wedge, solver.cut_graph().wedges,
                                   solver.constraints().variables, solver.reduction().Z);
      Eigen::Matrix3d block = Eigen::Matrix3d::Identity() * 2 - Eigen::Matrix3d::Ones() / 2;
      for (int f = 0; f < p.geometry().n_faces; ++f) assembly.add_face(f, block, block);
      assembly.reduce();
      Eigen::SparseMatrix<double> A = assembly.A();
      for (int k = 0; k < A.cols(); ++k) A.coeffRef(k, k) += 1.0;  // SPD, same pattern
      // Read as the stage reads it (SpdSolver, upper triangle: one permuted transpose less).
      qs::SpdSolver llt = qs::full_storage_solver("unit");
      double c1 = cpu_seconds();
      llt.analyze(A);
      const double analyze = cpu_seconds() - c1;
      c1 = cpu_seconds();
      const double w1 = wall_seconds();
      llt.factorize(A);
      const Eigen::VectorXd x = llt.solve(Eigen::VectorXd(Eigen::VectorXd::Ones(A.rows())));
      const double unit = cpu_seconds() - c1;
      const double unit_wall = wall_seconds() - w1;
      if (detail) {  // the same with the lower triangle (Eigen's default view)
        Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> lower;
        lower.analyzePattern(A);
        double best = 1e30;
        for (int k = 0; k < 3; ++k) {
          const double c2 = cpu_seconds();
          lower.factorize(A);
          const Eigen::VectorXd xl = lower.solve(Eigen::VectorXd::Ones(A.rows()));
          best = std::min(best, cpu_seconds() - c2);
        }
        double best_upper = 1e30;
        for (int k = 0; k < 3; ++k) {
          const double c2 = cpu_seconds();
          llt.factorize(A);
          const Eigen::VectorXd xu = llt.solve(Eigen::VectorXd(Eigen::VectorXd::Ones(A.rows())));
          best_upper = std::min(best_upper, cpu_seconds() - c2);
        }
        std::printf("  unit factorize+solve, best of 3: upper triangle %.4f, lower %.4f\n",
                    best_upper, best);
      }
      const qs::SpdSolverStats& order_stats = solver.linear_solver().stats();
      std::printf(
          "stage %.4f = solver %.4f (setup %.4f assemble %.4f analyze %.4f factorize %.4f "
          "solve %.4f wall) + trace %.4f; unit %.4f (analyze %.4f) ratio %.2f | unknowns %d "
          "nnz(A) %ld nnz(L) %.0f (%s) E %.12g foldovers %d structurally_equivalent %d%s\n",
          stage, solve, res.timings.setup_s, res.timings.assemble_s, res.timings.analyze_s,
          res.timings.factorize_s, res.timings.solve_s, trace, unit, analyze, stage / unit,
          res.unknowns, static_cast<long>(A.nonZeros()), order_stats.factor_nonzeros,
          order_stats.rejected_hints    ? "vertex order rejected"
          : order_stats.hinted_analyses ? "vertex order"
                                        : "CHOLMOD's ordering",
          res.energy, res.foldovers, ex.structurally_equivalent ? 1 : 0,
          x.allFinite() ? "" : " (unit solve failed)");
      if (detail) {
        std::vector<char> singular(p.geometry().n_vertices, 0);
        for (int n = 0; n < p.topology().num_nodes; ++n)
          if (p.topology().valence[n] != 4) singular[p.layout().nodes[n].vertex] = 1;
        double d0 = cpu_seconds();
        const qs::CutGraph cut =
            qs::build_cut_graph(p.mesh(), p.geometry(), field.period_jump, singular);
        const double t_cut = cpu_seconds() - d0;
        d0 = cpu_seconds();
        const qs::Labeling labels = qs::label_layout(p.mesh(), p.geometry(), p.layout(),
                                                     p.topology(), field.period_jump, field.theta);
        const double t_label = cpu_seconds() - d0;
        d0 = cpu_seconds();
        const qs::Reduction red = qs::eliminate_constraints(solver.constraints());
        const double t_elim = cpu_seconds() - d0;
        d0 = cpu_seconds();
        const qs::ReducedAssembly patterns(cut.corner_wedge, cut.wedges,
                                           solver.constraints().variables, red.Z);
        const double t_patterns = cpu_seconds() - d0;
        std::printf(
            "  setup parts (CPU): cut graph %.4f labels %.4f elimination %.4f patterns %.4f "
            "(rows %zu, wedges %d)\n",
            t_cut, t_label, t_elim, t_patterns, solver.constraints().rows.size(), cut.wedges);
        analysis_variant("default", A, 0, 0, nullptr, 0);
        analysis_variant("AMD", A, 1, CHOLMOD_AMD, nullptr, 0);
        analysis_variant("METIS", A, 1, CHOLMOD_METIS, nullptr, 0);
        d0 = cpu_seconds();
        const std::vector<int> group = qs::parameterization_groups(
            solver.cut_graph().wedges, solver.reduction().free_index, static_cast<int>(A.cols()));
        std::vector<int> order = qs::grouped_amd_ordering(A, group);
        const double t_order = cpu_seconds() - d0;
        std::printf("  wedge-grouped AMD ordering %.4f s CPU\n", t_order);
        analysis_variant("wedge AMD", A, 0, 0, &order, t_order);
      }
      std::printf("  wall: stage %.4f (trace %.4f), unit %.4f, ratio %.2f\n", stage_wall,
                  trace_wall, unit_wall, stage_wall / unit_wall);
      stages.push_back(stage);
      units.push_back(unit);
      ratios.push_back(stage / unit);
      stages_wall.push_back(stage_wall);
      units_wall.push_back(unit_wall);
      ratios_wall.push_back(stage_wall / unit_wall);
    }
    std::printf("median of %d: stage %.4f s CPU, unit %.4f s CPU, ratio %.2f\n", repeat,
                median(stages), median(units), median(ratios));
    std::printf("median of %d: stage %.4f s wall, unit %.4f s wall, ratio %.2f\n", repeat,
                median(stages_wall), median(units_wall), median(ratios_wall));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qs_param_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
