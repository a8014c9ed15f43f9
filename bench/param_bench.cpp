// Parameterization stage cost (issue #4): builds ParamSolver (cut graph, labels, constraint
// rows, exact elimination, reduced-matrix patterns, analysis, factorization, solve) and traces
// the layout's arcs on the result (extract_layout), on a mesh and layout, and compares the stage
// with one stand-alone CHOLMOD numeric factorization + solve of the same reduced matrix measured
// in the same run. Not a test.
//
//   qs_param_bench --mesh M --layout L [--repeat N]
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
#include "core/extract/tracing.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"

namespace {

using qs::bench::cpu_seconds;
using qs::bench::median;

}  // namespace

int main(int argc, char** argv) {
  std::string mesh_path, layout_path;
  int repeat = 3;
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
    qs::Pipeline p(std::move(mesh), std::move(layout), options);
    const qs::CrossField& field = p.compute_field();
    std::printf("faces %d, nodes %zu, arcs %zu\n", p.geometry().n_faces, p.layout().nodes.size(),
                p.layout().arcs.size());
    std::vector<double> stages, units, ratios;
    for (int r = 0; r < repeat; ++r) {
      const double c0 = cpu_seconds();
      const qs::ParamSolver solver(p.mesh(), p.geometry(), p.layout(), p.topology(),
                                   field.period_jump, field.theta, options.param);
      const double solve = cpu_seconds() - c0;
      const qs::Parameterization& res = solver.result();
      const double t0 = cpu_seconds();
      const qs::Extraction ex =
          qs::extract_layout(p.mesh(), p.geometry(), p.layout(), p.topology(), solver.labeling(),
                             field.period_jump, res.corner_uv);
      const double trace = cpu_seconds() - t0;
      const double stage = solve + trace;
      // The unit: the same reduced matrix, analyzed apart, then factorized and solved.
      qs::ReducedAssembly assembly(solver.cut_graph().corner_wedge, solver.cut_graph().wedges,
                                   solver.constraints().variables, solver.reduction().Z);
      Eigen::Matrix3d block = Eigen::Matrix3d::Identity() * 2 - Eigen::Matrix3d::Ones() / 2;
      for (int f = 0; f < p.geometry().n_faces; ++f) assembly.add_face(f, block, block);
      assembly.reduce();
      Eigen::SparseMatrix<double> A = assembly.A();
      for (int k = 0; k < A.cols(); ++k) A.coeffRef(k, k) += 1.0;  // SPD, same pattern
      Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> llt;
      double c1 = cpu_seconds();
      llt.analyzePattern(A);
      const double analyze = cpu_seconds() - c1;
      c1 = cpu_seconds();
      llt.factorize(A);
      const Eigen::VectorXd x = llt.solve(Eigen::VectorXd::Ones(A.rows()));
      const double unit = cpu_seconds() - c1;
      std::printf(
          "stage %.4f = solver %.4f (setup %.4f assemble %.4f analyze %.4f factorize %.4f "
          "solve %.4f wall) + trace %.4f; unit %.4f (analyze %.4f) ratio %.2f | unknowns %d "
          "nnz(A) %ld E %.12g foldovers %d structurally_equivalent %d%s\n",
          stage, solve, res.timings.setup_s, res.timings.assemble_s, res.timings.analyze_s,
          res.timings.factorize_s, res.timings.solve_s, trace, unit, analyze, stage / unit,
          res.unknowns, static_cast<long>(A.nonZeros()), res.energy, res.foldovers,
          ex.structurally_equivalent ? 1 : 0, x.allFinite() ? "" : " (unit solve failed)");
      stages.push_back(stage);
      units.push_back(unit);
      ratios.push_back(stage / unit);
    }
    std::printf("median of %d: stage %.4f s CPU, unit %.4f s CPU, ratio %.2f\n", repeat,
                median(stages), median(units), median(ratios));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qs_param_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
