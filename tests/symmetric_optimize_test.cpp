// Symmetric optimization (core/nodeopt/symmetric_step.h through core/engine/optimize.h): a
// mirrored layout on a mirror-symmetric mesh ends with its mirror pairs as mirror images and its
// plane nodes on the plane, fold-free, structurally equivalent and at a lower E; a pinned node's
// mirror stays its mirror image; an asymmetric layout and conflicting settings are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/base/errors.h"
#include "core/engine/optimize.h"
#include "core/layout/edge_loops.h"
#include "core/layout/layout_io.h"
#include "core/layout/routing.h"
#include "core/layout/symmetry.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/symmetric_step.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

const std::string kExample = test::assets_dir() + "/example/";

// The bundled ellipsoid (a mirror-symmetric tessellation) bent about x = 0 and sheared in y, so
// that the symmetric cube corners are no longer where E is lowest; still exactly symmetric about
// x = 0 (the bend and the shear only use x², y and z).
TriMesh bent_ellipsoid() {
  TriMesh mesh = load_mesh(kExample + "ellipsoid.obj");
  for (const auto vh : mesh.vertices()) {
    Vec3 p = mesh.point(vh);
    p[1] += 0.3 * p[0] * p[0];
    p[2] *= 1 + 0.15 * p[1];
    mesh.set_point(vh, p);
  }
  return mesh;
}

// The exact cube layout with an edge loop through an arc that crosses x = 0: four new nodes on
// the plane (each its own mirror) besides the four mirror pairs of cube corners.
Layout mirrored_layout(const TriMesh& mesh, const MirrorPlane& plane) {
  const Layout cube = load_layout(kExample + "ellipsoid_exact.layout.json", mesh);
  const SymmetryPairs pairs = find_mirror_pairs(mesh, cube, plane);
  int crossing = -1;
  for (int a = 0; a < int(cube.arcs.size()) && crossing < 0; ++a)
    if (pairs.arc_mirror[a] == a) crossing = cube.arcs[a].id;
  EXPECT_GE(crossing, 0);
  Layout layout = insert_edge_loop(mesh, cube, crossing).layout;
  route_layout(mesh, layout);
  return layout;
}

struct Outcome {
  OptimizeResult result;
  NodeSymmetryMeasure symmetry;
};

Outcome optimize_symmetric(const TriMesh& mesh, const Layout& layout) {
  OptimizeSettings settings;
  settings.nodes.symmetry = SymmetryAxis::X;
  Outcome out{optimize(mesh, layout, settings), {}};
  EXPECT_TRUE(out.result.symmetry);
  if (out.result.symmetry)
    out.symmetry = measure_node_symmetry(out.result.pipeline->mesh(), out.result.pipeline->layout(),
                                         *out.result.symmetry);
  return out;
}

TEST(SymmetricOptimize, MirrorPairsEndAsMirrorImagesAndPlaneNodesInThePlane) {
  const TriMesh mesh = bent_ellipsoid();
  const MirrorPlane plane = axis_plane(mesh, 0);
  const Layout layout = mirrored_layout(mesh, plane);
  ASSERT_TRUE(validate_layout(mesh, layout).valid());
  SymmetryPairOptions exact;
  exact.tolerance = 1e-9;
  exact.edge_lengths = 0.0;
  const SymmetryPairs start = match_mirror_pairs(mesh, layout, plane, exact);
  ASSERT_TRUE(start.symmetric()) << start.problem;

  const Outcome o = optimize_symmetric(mesh, layout);
  const OptimizeResult& r = o.result;
  ASSERT_TRUE(r.nodes);
  EXPECT_EQ(o.symmetry.pairs, 4);
  EXPECT_EQ(o.symmetry.plane_nodes, 4);
  EXPECT_LT(o.symmetry.max_pair_error, 1e-6);
  EXPECT_LT(o.symmetry.max_plane_error, 1e-6);
  EXPECT_EQ(r.pipeline->parameterization()->foldovers, 0);
  EXPECT_TRUE(r.pipeline->extract().structurally_equivalent);
  EXPECT_LT(r.nodes->E_final, r.nodes->E_init);
  // The nodes did move: the result is not the start kept as it was.
  double moved = 0;
  const Layout& out = r.pipeline->layout();
  ASSERT_EQ(out.nodes.size(), layout.nodes.size());
  for (std::size_t k = 0; k < layout.nodes.size(); ++k) {
    ASSERT_EQ(out.nodes[k].id, layout.nodes[k].id);
    const Vec3 a = mesh.point(OpenMesh::VertexHandle(layout.nodes[k].vertex));
    const Vec3 b = r.pipeline->mesh().point(OpenMesh::VertexHandle(out.nodes[k].vertex));
    moved = std::max(moved, (a - b).norm());
  }
  EXPECT_GT(moved, 0.05);  // the mean edge is 0.14
}

TEST(SymmetricOptimize, APinnedNodesMirrorStaysItsMirrorImage) {
  const TriMesh mesh = bent_ellipsoid();
  const MirrorPlane plane = axis_plane(mesh, 0);
  Layout layout = mirrored_layout(mesh, plane);
  const SymmetryPairs pairs = find_mirror_pairs(mesh, layout, plane);
  const auto position = [](const TriMesh& m, const Layout& l, int k) {
    return m.point(OpenMesh::VertexHandle(l.nodes[k].vertex));
  };
  // A node of a pair that moves when nothing is pinned.
  const Outcome free_run = optimize_symmetric(mesh, layout);
  int pinned = -1;
  for (int k = 0; k < int(layout.nodes.size()) && pinned < 0; ++k)
    if (pairs.node_mirror[k] != k &&
        (position(mesh, layout, k) -
         position(free_run.result.pipeline->mesh(), free_run.result.pipeline->layout(), k))
                .norm() > 0.01)
      pinned = k;
  ASSERT_GE(pinned, 0);
  layout.nodes[pinned].pinned = true;
  const int twin = pairs.node_mirror[pinned];

  const Outcome o = optimize_symmetric(mesh, layout);
  const TriMesh& m = o.result.pipeline->mesh();
  const Layout& out = o.result.pipeline->layout();
  const Vec3 at = m.point(OpenMesh::VertexHandle(out.nodes[pinned].vertex));
  EXPECT_LT((at - mesh.point(OpenMesh::VertexHandle(layout.nodes[pinned].vertex))).norm(), 1e-12);
  const Vec3 twin_at = m.point(OpenMesh::VertexHandle(out.nodes[twin].vertex));
  EXPECT_LT((plane.reflect(at) - twin_at).norm(), 1e-9);
  EXPECT_LT(o.symmetry.max_pair_error, 1e-6);
  EXPECT_LT(o.symmetry.max_plane_error, 1e-6);
  EXPECT_EQ(o.result.pipeline->parameterization()->foldovers, 0);
}

TEST(SymmetricOptimize, AnAsymmetricLayoutIsRefusedNamingItsFirstUnpairedNode) {
  const TriMesh mesh = load_mesh(kExample + "ellipsoid.obj");
  const Layout sketch = load_layout(kExample + "ellipsoid.layout.json", mesh);
  OptimizeSettings settings;
  settings.nodes.symmetry = SymmetryAxis::X;
  try {
    OptimizeRun run(mesh, sketch, settings);
    FAIL() << "an asymmetric layout was accepted";
  } catch (const InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not mirror symmetric"), std::string::npos) << what;
    EXPECT_NE(what.find("node 1 (vertex 758)"), std::string::npos) << what;
  }
}

TEST(SymmetricOptimize, SettingsThatMoveSingleNodesAreRefused) {
  OptimizeSettings s;
  s.nodes.symmetry = SymmetryAxis::Y;
  EXPECT_NO_THROW(validate_settings(s));
  OptimizeSettings discrete = s;
  discrete.nodes.method = NodeMethod::kDiscrete;
  EXPECT_THROW(validate_settings(discrete), InvalidInputError);
  OptimizeSettings separate = s;
  separate.nodes.separate_crowded = true;
  EXPECT_THROW(validate_settings(separate), InvalidInputError);
  OptimizeSettings fixed = s;
  fixed.nodes.enabled = false;
  EXPECT_THROW(validate_settings(fixed), InvalidInputError);
  OptimizeSettings plane;
  plane.nodes.symmetry_plane = MirrorPlane{Vec3(2, 0, 0), 0.0};  // not a unit normal
  EXPECT_THROW(validate_settings(plane), InvalidInputError);
  // The node optimizer refuses a pairing of the wrong size.
  const auto in = test::cube_sphere(4);
  NodeOptOptions no;
  auto wrong = std::make_shared<NodeSymmetry>();
  wrong->node_mirror = {0, 1};
  no.moves.symmetry = wrong;
  EXPECT_THROW(optimize_nodes(in.mesh, in.layout, PipelineOptions{}, no), InvalidInputError);
}

// The engine's settings reach the node optimizer: its thread count, and the orientation options
// of the fold-over removal through PipelineOptions (not enabled while nodes move).
TEST(OptimizeSettings, ThreadsAndOrientationOptionsReachTheOptimizer) {
  OptimizeSettings s;
  EXPECT_EQ(node_options(s).run.threads, NodeOptOptions{}.run.threads);
  s.nodes.threads = 1;
  s.folds.sectors = SectorFrame::kField;
  s.folds.untangle = false;
  EXPECT_EQ(node_options(s).run.threads, 1);
  const PipelineOptions moving = pipeline_options(s);
  EXPECT_FALSE(moving.param.orientation.enabled);
  EXPECT_EQ(moving.param.orientation.sector_frame, SectorFrame::kField);
  EXPECT_FALSE(moving.param.orientation.untangle);
  s.nodes.threads = 0;
  EXPECT_THROW(validate_settings(s), InvalidInputError);
}

}  // namespace
}  // namespace qs
