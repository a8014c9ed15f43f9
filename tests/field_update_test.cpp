// CrossFieldSolver::update_layout when the constraint set changed: a node
// optimization trial moves nodes to other vertices and relocates them, the curvature's
// reliable set changes, and the continued solver sets up again with the constructor's steps.
// Its drop passes tolerate as many mismatching edges (principal matching of the field ≠ period
// jump) as the previous solve left, where a fresh construction drops until a pass stops
// helping. These tests check that the changed-set path is really taken, that the continued
// field stays within the previous residual with the layout's singularities, and that it does
// no more drop passes or factorizations than a fresh construction — strictly fewer where the
// previous solve left a residual (a fresh construction then pays for a pass that cannot help).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "core/field/cross_field.h"
#include "core/import/cage.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/relocation.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Interior edges where the field's rounded step (principal matching) differs from the period
// jump: the count the drop passes compare with their tolerance (count_mismatches).
int mismatches(const GeometryCache& g, const CrossField& field) {
  const std::vector<int> matching = principal_matching(g, field.theta);
  int bad = 0;
  for (int e = 0; e < g.n_edges; ++e)
    if (g.edge_face_i[e] >= 0 && g.edge_face_j[e] >= 0) bad += matching[e] != field.period_jump[e];
  return bad;
}

bool same_constraint_set(const FieldConstraints& a, const FieldConstraints& b) {
  return a.face == b.face && a.kind == b.kind;
}

// A node optimization trial: every unpinned node switches to a random neighbour vertex (arcs
// re-routed), and each node's new vertex and the vertices of its one-ring are relocated
// `fraction` of the way towards one of their neighbours (the descent's continuous relocation
// moves the node vertices; moving their neighbours too changes the curvature more).
struct Trial {
  TriMesh mesh;
  Layout layout;
};

Trial make_trial(const TriMesh& mesh, const Layout& layout, double fraction, unsigned seed) {
  Trial t{mesh, layout};
  std::mt19937 rng(seed);
  for (int n = 0; n < static_cast<int>(t.layout.nodes.size()); ++n) {
    if (t.layout.nodes[n].pinned) continue;
    std::vector<int> cand = test::ring_vertices(mesh, t.layout.nodes[n].vertex, 1);
    std::shuffle(cand.begin(), cand.end(), rng);
    for (int w : cand) {
      if (forbidden_relocation_vertices(mesh, t.layout, n)[w]) continue;
      if (move_node_and_reroute(mesh, t.layout, n, w)) break;
    }
  }
  for (const LayoutNode& node : t.layout.nodes) {
    std::vector<int> around = test::ring_vertices(mesh, node.vertex, 1);
    around.push_back(node.vertex);
    for (int v : around) {
      const auto vh = mesh.vertex_handle(v);
      std::vector<int> nb;
      for (auto w : mesh.vv_range(vh)) nb.push_back(w.idx());
      const int w = nb[std::uniform_int_distribution<int>(0, static_cast<int>(nb.size()) - 1)(rng)];
      const Vec3 p = mesh.point(vh);
      t.mesh.set_point(vh, p + fraction * (mesh.point(mesh.vertex_handle(w)) - p));
    }
  }
  return t;
}

struct CaseCounts {
  int residual = 0;      //!< mismatching edges the first solve's smoothest field left
  int changed = 0;       //!< trials whose constraint set differs from the previous solve's
  int fewer_passes = 0;  //!< of them, trials with fewer drop passes than a fresh construction
};

// Builds the solver for (mesh, layout), then continues a copy of it for each trial and compares
// the continued field with a fresh construction at the trial's geometry and layout.
void check_continued_updates(const std::string& name, const test::MeshAndLayout& in,
                             const std::vector<std::pair<double, unsigned>>& trials,
                             CaseCounts& counts) {
  const GeometryCache g0 = build_geometry(in.mesh);
  const LayoutTopology t0 = build_topology(in.mesh, in.layout);
  const CrossFieldSolver first(in.mesh, g0, in.layout, t0);
  // The smoothest field's mismatches (the returned field is repaired where it turns by more
  // than 45°: mismatches(g0, first.field()) is 0).
  const int residual = first.residual_mismatches();
  counts.residual = residual;
  std::printf("[stat] %s: %d faces, %zu constraints in %d clusters (%d dropped), residual %d\n",
              name.c_str(), g0.n_faces, first.field().constraints.face.size(),
              first.field().clusters, first.field().dropped_clusters, residual);
  for (const auto& [fraction, seed] : trials) {
    const Trial trial = make_trial(in.mesh, in.layout, fraction, seed);
    ASSERT_TRUE(validate_layout(trial.mesh, trial.layout).valid());
    // The geometry continued from the previous one (κ continued), as Pipeline(mesh, layout,
    // previous) does.
    GeometryCache g1 = g0;
    update_geometry(trial.mesh, g1);
    const LayoutTopology t1 = build_topology(trial.mesh, trial.layout);

    CrossFieldSolver continued = first;  // shares the factorizations, as a trial's copy does
    const CrossFieldTimings before = continued.field().timings;
    const CrossField& fc = continued.update_layout(trial.mesh, g1, trial.layout, t1);
    const int factorizations = fc.timings.factorizations - before.factorizations;
    const int passes = fc.timings.conflict_passes - before.conflict_passes;

    const CrossFieldSolver fresh(trial.mesh, g1, trial.layout, t1);
    const CrossField& ff = fresh.field();

    const bool changed = !same_constraint_set(fc.constraints, first.field().constraints);
    const int m_continued = mismatches(g1, fc), m_fresh = mismatches(g1, ff);
    const test::FieldIndexCheck ic =
        test::check_field_indices(trial.mesh, g1, trial.layout, t1, fc.theta);
    std::printf(
        "[stat] %s, trial %.2f/%u: constraint set %s (%zu -> %zu faces); continued: %d "
        "mismatches, %d drop passes, %d factorizations, %d clusters dropped, %d wrong indices "
        "(%d spurious); fresh: %d mismatches, %d drop passes, %d factorizations\n",
        name.c_str(), fraction, seed, changed ? "changed" : "same",
        first.field().constraints.face.size(), fc.constraints.face.size(), m_continued, passes,
        factorizations, fc.dropped_clusters, ic.wrong, ic.spurious, m_fresh,
        ff.timings.conflict_passes, ff.timings.factorizations);
    // The changed-set path: the trial's constraints differ from the previous solve's, and are
    // those a fresh construction collects at this geometry.
    EXPECT_TRUE(changed) << name << " trial " << fraction << "/" << seed
                         << ": same constraint set, the set-up-again path was not taken";
    EXPECT_TRUE(same_constraint_set(fc.constraints, ff.constraints));
    if (!changed) continue;
    ++counts.changed;
    // Set up again: at least the one numeric factorization of the new matrix.
    EXPECT_GE(factorizations, 1);
    // The passes stop once no more edges mismatch than the previous solve left.
    EXPECT_LE(m_continued, residual) << name << " trial " << fraction << "/" << seed;
    // No more work than a fresh construction (which also orders and factorizes its reference
    // field in layout-field mode; the continued solver keeps that).
    EXPECT_LE(passes, ff.timings.conflict_passes);
    EXPECT_LE(factorizations, ff.timings.factorizations);
    counts.fewer_passes += passes < ff.timings.conflict_passes;
    // The active constraint count is consistent with the drops.
    EXPECT_EQ(fc.active_constraints,
              static_cast<int>(fc.constraints.face.size()) - fc.dropped_constraints);
    // The layout's singularities: every node vertex has its index (4 − valence)/4 measured on
    // the field alone; other vertices can only be off next to a steep edge (a ±1/4 pair each).
    EXPECT_EQ(ic.wrong - ic.spurious, 0) << (ic.examples.empty() ? "" : ic.examples[0]);
    EXPECT_LE(ic.spurious, 2 * m_continued) << (ic.examples.empty() ? "" : ic.examples[0]);
  }
}

// The bundled example (no shared data): relocations of 0.45 edge change the curvature
// constraint set. The previous solve leaves no mismatch, so the continued field must have none.
TEST(FieldUpdate, ChangedConstraintSetOnBundledExample) {
  const test::MeshAndLayout ex = test::ellipsoid_example();
  CaseCounts c;
  check_continued_updates("example", ex, {{0.45, 2u}, {0.45, 3u}}, c);
  EXPECT_EQ(c.changed, 2);
}

// The 70K bunny with a cage layout (issue #4; 162 clusters): the first solve's drop passes
// leave one mismatching edge that no pass removes (residual 1). In each trial the constraint set
// changes; the continued solver's first drop pass reaches the residual and it stops there, where
// a fresh construction (tolerance 0) tries a second pass that does not help and is undone
// (measured: continued 1 pass, 2 factorizations, 1 mismatch; fresh 2 passes, 4 factorizations,
// 2 mismatches — the undo does not restore the field exactly). With tolerance 0 in
// update_layout, or the tolerance ignored in the drop passes, the continued update does the
// fresh construction's passes and ends with 2 mismatches: this test fails (checked with a
// modified copy of cross_field.cpp linked into the test).
TEST(FieldUpdate, ChangedConstraintSetToleratesPreviousResidualOnBunny) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent (real-mesh test)";
  const TriMesh mesh = load_mesh(dir + "/bunny.off");
  CageOptions co;
  co.resolution = 8;
  const CageResult cage = cage_layout(mesh, co);
  ASSERT_TRUE(validate_layout(mesh, cage.layout).valid());
  CaseCounts c;
  check_continued_updates("bunny cage", {mesh, cage.layout}, {{0.05, 1u}, {0.2, 2u}}, c);
  EXPECT_GT(c.residual, 0) << "the case must leave a residual mismatch for the tolerance to matter";
  EXPECT_EQ(c.changed, 2);
  EXPECT_EQ(c.fewer_passes, 2) << "the tolerance saved no drop pass";
}

}  // namespace
}  // namespace qs
