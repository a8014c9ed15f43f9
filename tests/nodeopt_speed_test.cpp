// Work reuse of the node optimization (issue #5): the Pipeline continued after node
// moves (Pipeline(mesh, layout, previous): field solver copy + update_layout), the copy-on-write
// SpdSolver with its ordering hint, and the cached routing obstacles of re-routing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <queue>
#include <random>

#include "core/base/errors.h"
#include "core/base/spd_solver.h"
#include "core/layout/layout_io.h"
#include "core/layout/routing.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/relocation.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// SPD test matrix: a grid Laplacian (n × n vertices, 5-point stencil) plus `shift` on the
// diagonal (both triangles stored, compressed).
Eigen::SparseMatrix<double> grid_laplacian(int n, double shift) {
  std::vector<Eigen::Triplet<double>> t;
  auto id = [n](int i, int j) { return i * n + j; };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double diag = shift;
      for (const auto& [di, dj] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int a = i + di, b = j + dj;
        if (a < 0 || b < 0 || a >= n || b >= n) continue;
        t.emplace_back(id(i, j), id(a, b), -1.0);
        diag += 1.0;
      }
      t.emplace_back(id(i, j), id(i, j), diag);
    }
  Eigen::SparseMatrix<double> A(n * n, n * n);
  A.setFromTriplets(t.begin(), t.end());
  A.makeCompressed();
  return A;
}

Eigen::VectorXd random_rhs(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Eigen::VectorXd b(n);
  for (int k = 0; k < n; ++k) b(k) = u(rng);
  return b;
}

TEST(SpdSolverReuse, CopiesShareTheFactorizationUntilOneFactorizesAgain) {
  const auto A = grid_laplacian(20, 0.1);
  const auto A2 = grid_laplacian(20, 2.0);  // same pattern, other values
  const Eigen::VectorXd b = random_rhs(static_cast<int>(A.rows()), 1);
  SpdSolver first("first");
  first.factorize(A);
  const Eigen::VectorXd x = first.solve(b);
  SpdSolver copy = first;  // shares the factorization: no CHOLMOD work
  EXPECT_TRUE(copy.factorized());
  EXPECT_EQ((copy.solve(b) - x).norm(), 0.0);
  copy.factorize(A2);  // copy-on-write: the copy gets its own factor, analysis kept
  EXPECT_EQ(copy.stats().analyses, first.stats().analyses) << "the analysis was redone";
  const Eigen::VectorXd x2 = copy.solve(b);
  EXPECT_LT((A2 * x2 - b).norm(), 1e-10 * b.norm());
  EXPECT_GT((x2 - x).norm(), 1e-3 * x.norm()) << "the copy did not factorize A2";
  // The original still solves with its factorization of A.
  EXPECT_EQ((first.solve(b) - x).norm(), 0.0);
}

TEST(SpdSolverReuse, OrderingHintGivesTheSameSolution) {
  const auto A = grid_laplacian(30, 0.05);
  // Another pattern of the same size: a few couplings added.
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < A.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, k); it; ++it)
      t.emplace_back(static_cast<int>(it.row()), static_cast<int>(it.col()), it.value());
  for (int k = 0; k + 31 < A.rows(); k += 97) {
    t.emplace_back(k, k + 31, -0.1);
    t.emplace_back(k + 31, k, -0.1);
    t.emplace_back(k, k, 0.1);
    t.emplace_back(k + 31, k + 31, 0.1);
  }
  Eigen::SparseMatrix<double> B(A.rows(), A.cols());
  B.setFromTriplets(t.begin(), t.end());
  B.makeCompressed();
  const Eigen::VectorXd b = random_rhs(static_cast<int>(A.rows()), 2);

  SpdSolver first("first"), hinted("hinted"), reference("reference");
  first.factorize(A);
  const std::vector<int> ordering = first.ordering();
  ASSERT_EQ(ordering.size(), static_cast<size_t>(A.rows()));
  EXPECT_TRUE(std::is_permutation(ordering.begin(), ordering.end(),
                                  [&] {
                                    std::vector<int> id(ordering.size());
                                    for (size_t k = 0; k < id.size(); ++k)
                                      id[k] = static_cast<int>(k);
                                    return id;
                                  }()
                                      .begin()));
  hinted.set_ordering_hint(ordering);
  hinted.factorize(B);
  EXPECT_EQ(hinted.stats().hinted_analyses, 1);
  reference.factorize(B);
  EXPECT_EQ(reference.stats().hinted_analyses, 0);
  const Eigen::VectorXd xh = hinted.solve(b), xr = reference.solve(b);
  EXPECT_LT((B * xh - b).norm(), 1e-10 * b.norm());
  EXPECT_LT((xh - xr).norm(), 1e-9 * xr.norm());
  // A hint of the wrong size or not a permutation is not used.
  SpdSolver bad("bad");
  bad.set_ordering_hint({0, 0, 1});
  bad.factorize(B);
  EXPECT_EQ(bad.stats().hinted_analyses, 0);
  SpdSolver small("small");
  small.set_ordering_hint({1, 0});
  small.factorize(B);
  EXPECT_EQ(small.stats().hinted_analyses, 0);
  EXPECT_LT((B * small.solve(b) - b).norm(), 1e-10 * b.norm());
}

using Example = test::MeshAndLayout;
using test::ellipsoid_example;

// Moves every unpinned node `rings` rings away (re-routed), as a node optimization trial does.
Layout moved_layout(const TriMesh& mesh, Layout layout, int rings, unsigned seed) {
  std::mt19937 rng(seed);
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n) {
    if (layout.nodes[n].pinned) continue;
    auto cand = test::ring_vertices(mesh, layout.nodes[n].vertex, rings);
    std::shuffle(cand.begin(), cand.end(), rng);
    for (int w : cand) {
      if (forbidden_relocation_vertices(mesh, layout, n)[w]) continue;
      if (move_node_and_reroute(mesh, layout, n, w)) break;
    }
  }
  return layout;
}

double energy(const Pipeline& p, const PipelineOptions& options) {
  return unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, *p.parameterization(),
                           options.param);
}

// Same layout and positions: the continued Pipeline reproduces the field and the
// parameterization (the copied field solver re-solves with the same data).
TEST(Relayout, UnchangedLayoutReproducesTheSolve) {
  const Example ex = ellipsoid_example();
  const PipelineOptions options;
  Pipeline first(ex.mesh, ex.layout, options);
  first.compute_field();
  first.compute_parameterization();
  Pipeline again(ex.mesh, ex.layout, first);
  again.compute_field();
  const Parameterization& r = again.compute_parameterization();
  const auto& t0 = first.field()->theta;
  const auto& t1 = again.field()->theta;
  ASSERT_EQ(t0.size(), t1.size());
  double dt = 0;
  for (size_t f = 0; f < t0.size(); ++f) dt = std::max(dt, std::abs(t0[f] - t1[f]));
  EXPECT_LT(dt, 1e-9);
  const auto& uv0 = first.parameterization()->corner_uv;
  double scale = 0, du = 0;
  for (size_t c = 0; c < uv0.size(); ++c)
    for (int k = 0; k < 2; ++k) {
      scale = std::max(scale, std::abs(uv0[c][k]));
      du = std::max(du, std::abs(uv0[c][k] - r.corner_uv[c][k]));
    }
  EXPECT_LT(du, 1e-9 * scale);
  EXPECT_EQ(r.foldovers, first.parameterization()->foldovers);
}

// Nodes moved two rings (arcs re-routed), vertex positions unchanged: the continued Pipeline
// (copied field solver, update_layout with every constraint back in force, its own drop passes)
// reproduces a fresh Pipeline: the same singularities, θ and E. The previous Pipeline is left
// as it was.
TEST(Relayout, MovedNodesGiveTheFreshFieldTopology) {
  const Example ex = ellipsoid_example();
  const PipelineOptions options;
  Pipeline first(ex.mesh, ex.layout, options);
  first.compute_field();
  first.compute_parameterization();
  const std::vector<double> theta_before = first.field()->theta;
  const double E_before = energy(first, options);
  for (unsigned seed : {1u, 2u, 3u}) {
    const Layout moved = moved_layout(ex.mesh, ex.layout, 2, seed);
    int switched = 0;
    for (size_t n = 0; n < moved.nodes.size(); ++n)
      switched += moved.nodes[n].vertex != ex.layout.nodes[n].vertex;
    ASSERT_GT(switched, 0);
    Pipeline fresh(ex.mesh, moved, options);
    fresh.compute_field();
    fresh.compute_parameterization();
    Pipeline continued(ex.mesh, moved, first);
    continued.compute_field();
    continued.compute_parameterization();
    // θ equal modulo quarter turns (the constraint set is the first geometry's, equal here).
    const test::FieldGap gap = test::field_gap(fresh, continued);
    ASSERT_TRUE(gap.same_singularities) << "seed " << seed;
    const double worst = gap.max_theta;
    const double Ef = energy(fresh, options), Ec = energy(continued, options);
    std::printf(
        "[stat] relayout seed %u: %d nodes switched, max |dθ| %.3g rad, E %.9g vs fresh "
        "%.9g, fold-overs %d vs %d\n",
        seed, switched, worst, Ec, Ef, continued.parameterization()->foldovers,
        fresh.parameterization()->foldovers);
    EXPECT_LT(worst, 1e-8) << "seed " << seed;
    EXPECT_NEAR(Ec, Ef, 1e-9 * Ef) << "seed " << seed;
    EXPECT_EQ(continued.parameterization()->foldovers, fresh.parameterization()->foldovers);
  }
  // The previous Pipeline is unchanged and still re-solves in place.
  EXPECT_EQ(first.field()->theta, theta_before);
  EXPECT_EQ(energy(first, options), E_before);
  first.update_positions(ex.mesh);
  first.compute_field();
  first.compute_parameterization();
  EXPECT_NEAR(energy(first, options), E_before, 1e-9 * E_before);
  // Another mesh size is refused.
  EXPECT_THROW(Pipeline(test::cube_sphere(4).mesh, test::cube_sphere(4).layout, first),
               InvalidInputError);
}

// The cached obstacles of move_node_and_reroute give the same re-routed layouts as rebuilding
// them per move, the same forbidden vertices (relocation_forbidden, vertex by vertex, against
// the #V array built from the layout), and stay equal to obstacles_of_layout.
TEST(Relayout, CachedObstaclesMatchRebuiltOnes) {
  const Example ex = ellipsoid_example();
  Layout slow = ex.layout, fast = ex.layout;
  LayoutObstacles cache = make_layout_obstacles(ex.mesh, fast);
  const RerouteContext context = make_reroute_context(ex.mesh, ex.layout);
  std::mt19937 rng(7);
  int moves = 0, kept = 0;
  for (int round = 0; round < 6; ++round)
    for (int n = 0; n < static_cast<int>(slow.nodes.size()); ++n) {
      const auto forbidden_slow = forbidden_relocation_vertices(ex.mesh, slow, n);
      for (int v = 0; v < static_cast<int>(forbidden_slow.size()); ++v)
        ASSERT_EQ(relocation_forbidden(fast, n, cache, v), forbidden_slow[v] != 0)
            << "round " << round << " node " << n << " vertex " << v;
      auto cand = test::ring_vertices(ex.mesh, slow.nodes[n].vertex, 1 + round % 2);
      std::shuffle(cand.begin(), cand.end(), rng);
      for (int w : cand) {
        if (forbidden_slow[w]) continue;
        ++moves;
        const bool a = move_node_and_reroute(ex.mesh, slow, n, w, {}, &context);
        const bool b = move_node_and_reroute(ex.mesh, fast, n, w, {}, &context, &cache);
        ASSERT_EQ(a, b);
        if (!a) continue;
        ++kept;
        for (size_t k = 0; k < slow.arcs.size(); ++k)
          ASSERT_EQ(slow.arcs[k].path, fast.arcs[k].path);
        const RoutingObstacles rebuilt = obstacles_of_layout(ex.mesh, fast);
        ASSERT_EQ(rebuilt.vertex_blocked, cache.routing.vertex_blocked);
        ASSERT_EQ(rebuilt.edge_blocked, cache.routing.edge_blocked);
        break;
      }
    }
  std::printf("[stat] cached obstacles: %d moves tried, %d kept\n", moves, kept);
  EXPECT_GT(kept, 10);
}

// \p steps descent steps, nothing after them (no hop polish, no fold-over removal).
NodeOptOptions descent_only(int steps) {
  NodeOptOptions no;
  no.descent.max_steps = steps;
  no.polish.enabled = false;
  no.folds.orientation = false;
  no.folds.stiffen = false;
  return no;
}

struct StepRecorder : Observer {
  std::vector<StepReport> steps;
  void on_step(const StepReport& r) override { steps.push_back(r); }
};

// The optimizer's Pipelines carry one vertex order of the mesh after the initial solve
// (optimize_nodes), which keeps CHOLMOD's ordering on a mesh this small; the descent re-lays
// out with it.
TEST(Relayout, OptimizerPipelinesCarryTheVertexOrder) {
  const Example ex = ellipsoid_example();
  const PipelineOptions options;
  const NodeOptOptions no = descent_only(6);
  NodeOptStats stats;
  const NodeOptResult a = optimize_nodes(ex.mesh, ex.layout, options, no, nullptr, nullptr, &stats);
  EXPECT_GT(stats.relayouts, 0);
  ASSERT_TRUE(a.pipeline);
  ASSERT_TRUE(a.pipeline->options().param.vertex_order);
  EXPECT_EQ(a.pipeline->options().param.vertex_order->size(), ex.mesh.n_vertices());
  Pipeline fresh(ex.mesh, ex.layout, options);
  fresh.compute_field();
  const Parameterization& p = fresh.compute_parameterization();
  const double E =
      unweighted_energy(fresh.mesh(), fresh.geometry(), fresh.field()->theta, p, options.param);
  EXPECT_NEAR(a.E_init, E, 1e-12 * E);
}

// The optimizer with continued Pipelines: on the bundled example the descent accepts and
// rejects the same steps as with a fresh Pipeline per trial and ends at nearly the same E
// (the continued field keeps the start geometry's constraint set, a fresh one recomputes the
// curvature on the relocated vertices: a difference far below the steps' changes of E).
TEST(Relayout, OptimizerMatchesFreshTrialsOnExample) {
  const Example ex = ellipsoid_example();
  const PipelineOptions options;
  NodeOptOptions no = descent_only(10);
  no.run.reuse_field = true;  // the continued path (the default), against fresh pipelines
  StepRecorder with_reuse, without;
  NodeOptStats stats_reuse, stats_fresh;
  const NodeOptResult a =
      optimize_nodes(ex.mesh, ex.layout, options, no, &with_reuse, nullptr, &stats_reuse);
  no.run.reuse_field = false;
  const NodeOptResult b =
      optimize_nodes(ex.mesh, ex.layout, options, no, &without, nullptr, &stats_fresh);
  std::printf(
      "[stat] example: E %.9g -> %.9g (relayouts %d) vs fresh trials %.9g -> %.9g "
      "(fresh pipelines %d)\n",
      a.E_init, a.E_descent, stats_reuse.relayouts, b.E_init, b.E_descent,
      stats_fresh.fresh_pipelines);
  EXPECT_GT(stats_reuse.relayouts, 0);
  EXPECT_EQ(stats_reuse.fresh_pipelines, 1);  // only the start
  EXPECT_EQ(stats_fresh.relayouts, 0);
  EXPECT_EQ(a.E_init, b.E_init);
  ASSERT_EQ(with_reuse.steps.size(), without.steps.size());
  for (size_t k = 0; k < with_reuse.steps.size(); ++k) {
    EXPECT_EQ(with_reuse.steps[k].accepted, without.steps[k].accepted) << "step " << k;
    EXPECT_NEAR(with_reuse.steps[k].E, without.steps[k].E, 1e-3 * without.steps[k].E)
        << "step " << k;
  }
  EXPECT_NEAR(a.E_descent, b.E_descent, 1e-3 * b.E_descent);
  EXPECT_EQ(a.foldovers_descent, b.foldovers_descent);
}

}  // namespace
}  // namespace qs
