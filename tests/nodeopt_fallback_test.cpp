// The node optimizer's fewest-fold-over fallback (NodeOptResult::
// fewest_foldovers_reverted): when the fold-over removal leaves fold-overs at the end of the
// descent, the accepted state with the fewest fold-overs is finished the same way and returned
// when it ends with fewer fold-overs (as many: lower final E).
//
// Case: the 8×8 cube-sphere ellipsoid with its cube layout displaced by four rings (seed 7),
// four descent steps without the hop polish. The accepted steps go 35 → 10 → 6 → 10 fold-overs,
// so the descent ends one accepted step past its fewest-fold state. Stiffening alone removes the
// fold-overs, with an iteration budget that decides what each state ends with.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/relocation.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Faces whose parametric triangle has non-positive signed area (counted here from the corner
// values, independently of Parameterization::foldovers).
int count_folds(const std::vector<std::array<double, 2>>& uv) {
  int folds = 0;
  for (size_t f = 0; 3 * f + 2 < uv.size(); ++f) {
    const auto& a = uv[3 * f];
    const auto& b = uv[3 * f + 1];
    const auto& c = uv[3 * f + 2];
    folds += (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) <= 0;
  }
  return folds;
}

using Positions = std::vector<std::array<double, 3>>;

Positions node_positions(const TriMesh& mesh, const Layout& layout) {
  Positions out;
  for (const auto& n : layout.nodes) {
    const Vec3 p = mesh.point(mesh.vertex_handle(n.vertex));
    out.push_back({p[0], p[1], p[2]});
  }
  return out;
}

struct OptimizedCase {
  NodeOptResult result;
  int min_accepted_folds = 0;   //!< fewest fold-overs over the initial and accepted steps
  int last_accepted_folds = 0;  //!< of the last accepted descent step (the final state)
  Positions fewest_positions;   //!< node positions of the (last) accepted state with the fewest
  //! The fold-over removal reports ("orientation" / "stiffening" steps): the first finishes the
  //! final state, the next ones (if any) the fallback state.
  std::vector<StepReport> removal;
};

OptimizedCase optimize_case(int stiffening_iterations) {
  const auto cs = test::cube_sphere(8, Vec3(1.3, 1, 0.75));
  const Layout start = test::displace_nodes(cs.mesh, cs.layout, 4, 7);
  NodeOptOptions no;
  no.descent.max_steps = 4;
  no.polish.enabled = false;  // no pre-polish state: only the fewest-fold-over fallback
  no.folds.orientation = false;
  no.folds.stiffen = true;
  no.tuning.stiffening.max_iterations = stiffening_iterations;
  OptimizedCase run;
  run.result = optimize_nodes(cs.mesh, start, PipelineOptions{}, no);
  run.min_accepted_folds = run.result.foldovers_init;
  for (const StepReport& s : run.result.reports) {
    if (s.phase == "initial" || (s.phase == "descent" && s.accepted)) {
      if (s.foldovers <= run.min_accepted_folds) {
        run.min_accepted_folds = s.foldovers;
        run.fewest_positions = s.node_positions;
      }
      run.last_accepted_folds = s.foldovers;
    }
    if (s.phase == "orientation" || s.phase == "stiffening") run.removal.push_back(s);
  }
  std::string steps;
  for (const StepReport& s : run.result.reports)
    steps += s.phase.substr(0, 4) + (s.accepted ? "+" : "-") + std::to_string(s.foldovers) + " ";
  std::printf(
      "[stat] stiffening %d iterations: fold-overs %d -> final %d (E %.6g), fewest accepted %d, "
      "last accepted %d, reverted %d; steps (phase, accepted, fold-overs): %s\n",
      stiffening_iterations, run.result.foldovers_init, run.result.foldovers_final,
      run.result.E_final, run.min_accepted_folds, run.last_accepted_folds,
      run.result.fewest_foldovers_reverted, steps.c_str());
  return run;
}

// The returned (mesh, layout) re-solved from scratch with the returned stiffening weights (or
// orientation constraints) gives the reported final fold-overs and E; the returned Pipeline is
// at that (mesh, layout) and holds the reported descent (or constrained) solve.
void expect_consistent(const NodeOptResult& r) {
  PipelineOptions options;
  options.param.face_weights = r.face_weights;
  if (r.orientation_constraints) options.param.orientation = r.orientation_options;
  Pipeline fresh(r.mesh, r.layout, options, false);
  fresh.compute_field();
  const Parameterization& p = fresh.compute_parameterization();
  EXPECT_EQ(count_folds(p.corner_uv), r.foldovers_final);
  const double E = unweighted_energy(fresh.mesh(), fresh.geometry(), fresh.field()->theta, p,
                                     PipelineOptions{}.param);
  EXPECT_NEAR(E, r.E_final, 1e-9 * r.E_final);

  ASSERT_TRUE(r.pipeline && r.pipeline->parameterization());
  EXPECT_EQ(node_positions(r.pipeline->mesh(), r.pipeline->layout()),
            node_positions(r.mesh, r.layout));
  for (auto v : r.mesh.vertices()) ASSERT_EQ(r.pipeline->mesh().point(v), r.mesh.point(v));
  const int pipeline_folds = count_folds(r.pipeline->parameterization()->corner_uv);
  EXPECT_EQ(pipeline_folds, r.orientation_constraints ? r.foldovers_final : r.foldovers_descent);
}

// Five stiffening iterations take the final state (10 fold-overs) down to 1, the fewest-fold
// state (6) down to 0: the fallback is taken and returns 0.
TEST(NodeOptFallback, FewestFoldStateWithFewerFoldOversIsReturned) {
  const OptimizedCase run = optimize_case(5);
  const NodeOptResult& r = run.result;
  ASSERT_TRUE(r.fewest_foldovers_reverted) << "the case must take the fallback";
  EXPECT_FALSE(r.polish_reverted);
  // The descent ended with more fold-overs than its fewest-fold state.
  ASSERT_GT(run.last_accepted_folds, run.min_accepted_folds);
  // What the removal left at the final state, then the fallback state's removal.
  ASSERT_EQ(run.removal.size(), 2u);
  const StepReport& at_end = run.removal[0];
  const StepReport& at_fewest = run.removal[1];
  EXPECT_GT(at_end.foldovers, 0) << "the fallback is only tried when fold-overs remain";
  // The header's rule: strictly fewer fold-overs, or as many at a lower final E.
  EXPECT_LE(r.foldovers_final, at_end.foldovers);
  EXPECT_TRUE(r.foldovers_final < at_end.foldovers ||
              (r.foldovers_final == at_end.foldovers && r.E_final < at_end.E));
  EXPECT_LT(r.foldovers_final, at_end.foldovers);  // this case: 0 against 1
  // The result is the fallback state's: its descent values and removal, its node positions.
  EXPECT_EQ(r.foldovers_descent, run.min_accepted_folds);
  EXPECT_EQ(r.foldovers_final, at_fewest.foldovers);
  EXPECT_EQ(r.E_final, at_fewest.E);
  EXPECT_FALSE(r.face_weights.empty()) << "stiffening's weights must come with the result";
  const Positions returned = node_positions(r.mesh, r.layout);
  EXPECT_EQ(returned, run.fewest_positions);
  EXPECT_EQ(returned, at_fewest.node_positions);
  EXPECT_NE(returned, at_end.node_positions);
  expect_consistent(r);
}

// One stiffening iteration takes the final state from 10 to 6 fold-overs and cannot improve the
// fewest-fold state (6): as many fold-overs, and the fallback state's E is lower, so it is
// returned (the header's tie rule).
TEST(NodeOptFallback, EqualFoldOversAtLowerEnergyIsReturned) {
  const OptimizedCase run = optimize_case(1);
  const NodeOptResult& r = run.result;
  ASSERT_TRUE(r.fewest_foldovers_reverted) << "the case must take the fallback";
  ASSERT_EQ(run.removal.size(), 2u);
  const StepReport& at_end = run.removal[0];
  EXPECT_GT(at_end.foldovers, 0);
  EXPECT_EQ(r.foldovers_final, at_end.foldovers);  // this case: the tie
  EXPECT_LT(r.E_final, at_end.E);
  EXPECT_EQ(r.foldovers_descent, run.min_accepted_folds);
  EXPECT_EQ(node_positions(r.mesh, r.layout), run.fewest_positions);
  EXPECT_NE(node_positions(r.mesh, r.layout), at_end.node_positions);
  expect_consistent(r);
}

// Two stiffening iterations take the final state from 10 to 4 fold-overs, the fewest-fold state
// stays at 6: the fallback is tried (a second removal report) but not taken, and the final
// state is returned.
TEST(NodeOptFallback, FallbackWithMoreFoldOversIsNotTaken) {
  const OptimizedCase run = optimize_case(2);
  const NodeOptResult& r = run.result;
  ASSERT_EQ(run.removal.size(), 2u) << "the fallback must have been tried";
  EXPECT_FALSE(r.fewest_foldovers_reverted);
  const StepReport& at_end = run.removal[0];
  const StepReport& at_fewest = run.removal[1];
  EXPECT_GT(at_fewest.foldovers, at_end.foldovers);
  EXPECT_EQ(r.foldovers_final, at_end.foldovers);
  EXPECT_EQ(r.foldovers_descent, run.last_accepted_folds);
  EXPECT_EQ(node_positions(r.mesh, r.layout), at_end.node_positions);
  expect_consistent(r);
}

}  // namespace
}  // namespace qs
