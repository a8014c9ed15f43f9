// Micro-benchmarks of the hot kernels (issue #9) on the synthetic cube_sphere(40) fixture:
// geometry cache build, cross-field re-solve, parameterization re-solve with an existing
// ParamSolver, arc tracing. Not a test; run through scripts/bench.sh or directly.
#include <benchmark/benchmark.h>

#include <memory>

#include "core/extract/tracing.h"
#include "core/field/cross_field.h"
#include "core/mesh/geometry.h"
#include "core/param/parameterization.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace {

//! One pipeline on cube_sphere(40) with field and parameterization solved, built once.
struct Fixture {
  std::unique_ptr<qs::Pipeline> pipeline;
  std::unique_ptr<qs::ParamSolver> param_solver;

  static Fixture& get() {
    static Fixture fixture;
    return fixture;
  }

 private:
  Fixture() {
    qs::test::MeshAndLayout ml = qs::test::cube_sphere(40);
    pipeline = std::make_unique<qs::Pipeline>(std::move(ml.mesh), std::move(ml.layout));
    pipeline->compute_parameterization();
    const qs::CrossField& field = *pipeline->field();
    param_solver = std::make_unique<qs::ParamSolver>(pipeline->mesh(), pipeline->geometry(),
                                                     pipeline->layout(), pipeline->topology(),
                                                     field.period_jump, field.theta);
    param_solver->solve(pipeline->mesh(), pipeline->geometry(), field.theta);
  }
};

void BM_GeometryCacheBuild(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  for (auto _ : state) {
    qs::GeometryCache g = qs::build_geometry(f.pipeline->mesh());
    benchmark::DoNotOptimize(g);
  }
  state.counters["faces"] = static_cast<double>(f.pipeline->mesh().n_faces());
}
BENCHMARK(BM_GeometryCacheBuild)->Unit(benchmark::kMillisecond);

void BM_CrossFieldSolve(benchmark::State& state) {
  Fixture& f = Fixture::get();
  for (auto _ : state) {
    const qs::CrossField& field = f.pipeline->compute_field();  // re-solve, same factorization
    benchmark::DoNotOptimize(field.theta.data());
  }
}
BENCHMARK(BM_CrossFieldSolve)->Unit(benchmark::kMillisecond);

void BM_CrossFieldSetup(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  const qs::Pipeline& p = *f.pipeline;
  for (auto _ : state) {
    qs::CrossFieldSolver solver(p.mesh(), p.geometry(), p.layout(), p.topology());
    benchmark::DoNotOptimize(solver.field().theta.data());
  }
}
BENCHMARK(BM_CrossFieldSetup)->Unit(benchmark::kMillisecond);

void BM_ParamSolve(benchmark::State& state) {
  Fixture& f = Fixture::get();
  const qs::Pipeline& p = *f.pipeline;
  const std::vector<double>& theta = p.field()->theta;
  for (auto _ : state) {
    const qs::Parameterization& r = f.param_solver->solve(p.mesh(), p.geometry(), theta);
    benchmark::DoNotOptimize(r.corner_uv.data());
  }
  const qs::ParamTimings& t = f.param_solver->result().timings;
  state.counters["unknowns"] = f.param_solver->result().unknowns;
  state.counters["assemble_ms"] = 1e3 * t.assemble_s;
  state.counters["factorize_ms"] = 1e3 * t.factorize_s;
  state.counters["solve_ms"] = 1e3 * t.solve_s;
}
BENCHMARK(BM_ParamSolve)->Unit(benchmark::kMillisecond);

void BM_ExtractLayout(benchmark::State& state) {
  const Fixture& f = Fixture::get();
  const qs::Pipeline& p = *f.pipeline;
  for (auto _ : state) {
    qs::Extraction ex = qs::extract_layout(p.mesh(), p.geometry(), p.layout(), p.topology(),
                                           f.param_solver->labeling(), p.field()->period_jump,
                                           f.param_solver->result().corner_uv);
    benchmark::DoNotOptimize(ex);
  }
}
BENCHMARK(BM_ExtractLayout)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
