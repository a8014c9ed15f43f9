// The cross field the editor's job publishes for the glyph layer (Snapshot::field), and the
// pipeline options of the editor's Options panel reaching the job (app/gui/pipeline_job.cpp,
// GL-free). With the render library linked (QS_TEST_RENDER), also the glyph subsampling.
#include <gtest/gtest.h>

#include <cmath>

#include "app/gui/pipeline_job.h"
#include "tests/fixtures.h"
#include "tests/gui_job_fixture.h"
#ifdef QS_TEST_RENDER
#include "render/field_layer.h"
#endif

namespace qs::app {
namespace {

using test::Example;
using test::example;

// The initial solve only (no node optimization) with the given options.
SnapshotPtr solve_once(const Example& ex, WorkerOptions options) {
  options.max_steps = 1;
  options.node_optimization = false;
  options.publish_interval_ms = 0;
  return test::run_job(ex, options);
}

int count_kind(const FieldView& field, int kind) {
  int n = 0;
  for (char k : field.constraint_kind) n += k == kind;
  return n;
}

TEST(GuiField, SnapshotCarriesUnitInPlaneDirectionsAndConstraints) {
  const Example ex = example();
  // The smooth ellipsoid has no reliable curvature faces at the default thresholds; a 1°
  // sharp angle makes its edges features, so that there are constraints to check.
  WorkerOptions options;
  options.sharp_angle_deg = 1.0;
  const auto s = solve_once(ex, options);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  ASSERT_TRUE(s->field);
  const FieldView& field = *s->field;
  const TriMesh& mesh = s->exports ? s->exports->mesh : *ex.mesh;
  ASSERT_EQ(field.direction.size(), mesh.n_faces());
  for (const auto fh : mesh.faces()) {
    auto it = mesh.cfv_begin(fh);
    const Vec3 a = mesh.point(*it++), b = mesh.point(*it++), c = mesh.point(*it);
    const Vec3 n = OpenMesh::cross(b - a, c - a).normalized();
    const auto& d = field.direction[fh.idx()];
    const Vec3 dir(d[0], d[1], d[2]);
    ASSERT_NEAR(dir.norm(), 1.0, 1e-5) << "face " << fh.idx();
    ASSERT_NEAR(OpenMesh::dot(dir, n), 0.0, 1e-4) << "face " << fh.idx() << " leaves its plane";
  }
  ASSERT_EQ(field.constraint_direction.size(), field.constraint_faces.size());
  ASSERT_EQ(field.constraint_kind.size(), field.constraint_faces.size());
  EXPECT_GT(field.constraint_faces.size(), 0u);
  for (std::size_t k = 0; k < field.constraint_faces.size(); ++k) {
    EXPECT_GE(field.constraint_faces[k], 0);
    EXPECT_LT(field.constraint_faces[k], int(mesh.n_faces()));
    EXPECT_TRUE(field.constraint_kind[k] >= 0 && field.constraint_kind[k] <= 2);
    const auto& d = field.constraint_direction[k];
    EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), 1.0, 1e-5);
  }
}

TEST(GuiField, SnapshotMarksReleasedConstraintsAndWarns) {
  // The curvature clusters of this ellipsoid contradict the cube layout and are released
  // (tests/field_test.cpp): the editor shows them as released and warns in the Metrics panel.
  const auto in = test::cube_sphere(10, Vec3(2.0, 1.0, 0.75));
  const Example ex{std::make_shared<TriMesh>(in.mesh), in.layout};
  WorkerOptions whole;  // one cluster per connected region (the default splits them)
  whole.max_cluster_faces = 0;
  const auto s = solve_once(ex, whole);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  ASSERT_TRUE(s->field);
  const FieldView& field = *s->field;
  ASSERT_GT(field.constraint_faces.size(), 0u);
  ASSERT_EQ(field.constraint_in_force.size(), field.constraint_faces.size());
  int in_force = 0;
  for (char c : field.constraint_in_force) in_force += c != 0;
  EXPECT_LT(in_force, static_cast<int>(field.constraint_faces.size()));
  EXPECT_GT(field.dropped_clusters, 0);
  EXPECT_LE(field.dropped_clusters, field.clusters);
  EXPECT_NE(field.warning.find("released"), std::string::npos) << field.warning;
  // The panel's "Cluster size" (split curvature clusters) reaches the job: more in force.
  WorkerOptions split;
  split.max_cluster_faces = 10;
  const auto p = solve_once(ex, split);
  ASSERT_EQ(p->status, WorkerStatus::Finished) << p->message;
  ASSERT_TRUE(p->field);
  ASSERT_EQ(p->field->constraint_faces.size(), field.constraint_faces.size());
  int split_in_force = 0;
  for (char c : p->field->constraint_in_force) split_in_force += c != 0;
  EXPECT_GT(split_in_force, in_force + static_cast<int>(field.constraint_faces.size()) / 4);
  EXPECT_GT(p->field->clusters, field.clusters);
  // Without constraints (the bundled example at the default thresholds) there is no warning.
  const auto e = solve_once(example(), WorkerOptions{});
  ASSERT_TRUE(e->field);
  EXPECT_TRUE(e->field->constraint_faces.empty());
  EXPECT_TRUE(e->field->constraint_in_force.empty());
  EXPECT_TRUE(e->field->warning.empty()) << e->field->warning;
}

TEST(GuiField, PanelOptionsReachTheJob) {
  const Example ex = example();
  const auto aligned = solve_once(ex, WorkerOptions{});
  WorkerOptions no_align;
  no_align.align = false;
  const auto oblivious = solve_once(ex, no_align);
  ASSERT_TRUE(aligned->field && oblivious->field);
  // --no-align never has curvature constraints (the ellipsoid has none to drop at the default
  // thresholds either, so this half of the check is weak; the two below are not).
  ASSERT_EQ(oblivious->status, WorkerStatus::Finished) << oblivious->message;
  EXPECT_EQ(count_kind(*oblivious->field, 0), 0);
  // Anisotropy changes the energy that is minimized.
  WorkerOptions iso;
  iso.anisotropy = 1.0;
  const auto isotropic = solve_once(ex, iso);
  ASSERT_EQ(isotropic->status, WorkerStatus::Finished) << isotropic->message;
  EXPECT_TRUE(std::isfinite(isotropic->energy));
  EXPECT_GT(std::abs(isotropic->energy - aligned->energy), 1e-6 * aligned->energy);
  // A very low sharp angle turns the ellipsoid's creases between faces into features.
  WorkerOptions sharp;
  sharp.sharp_angle_deg = 1.0;
  const auto featured = solve_once(ex, sharp);
  ASSERT_TRUE(featured->field) << featured->message;
  EXPECT_GT(count_kind(*featured->field, 1), count_kind(*aligned->field, 1));
}

#ifdef QS_TEST_RENDER
TEST(GuiField, GlyphSamplingKeepsEveryFaceOfSmallMeshesAndBoundsLargeOnes) {
  // A 200 x 200 grid of face centroids on the unit square (area 1).
  std::vector<glm::vec3> centroids;
  for (int j = 0; j < 200; ++j)
    for (int i = 0; i < 200; ++i) centroids.emplace_back((i + 0.5f) / 200, (j + 0.5f) / 200, 0.0f);
  float arm = 0.0f;
  const auto all = render::sample_faces(centroids, 1.0, 50000, &arm);
  EXPECT_EQ(all.size(), centroids.size());
  EXPECT_GT(arm, 0.0f);
  const auto some = render::sample_faces(centroids, 1.0, 1000, &arm);
  // About 1000 cells of side 1/sqrt(1000) cover the square (partial cells at the border).
  EXPECT_GE(some.size(), 900u);
  EXPECT_LE(some.size(), 1100u);
  EXPECT_TRUE(std::is_sorted(some.begin(), some.end()));
  EXPECT_TRUE(std::adjacent_find(some.begin(), some.end()) == some.end());
  EXPECT_NEAR(arm, 0.38 / std::sqrt(1000.0), 1e-4);
  EXPECT_TRUE(render::sample_faces({}, 1.0, 100, &arm).empty());
  EXPECT_TRUE(render::sample_faces(centroids, 0.0, 100, &arm).empty());
}
#endif

}  // namespace
}  // namespace qs::app
