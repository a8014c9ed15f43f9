// Mirror symmetry (core/layout/symmetry.h): plane fitting on symmetric meshes (also turned off
// their axes and with noise), reflection of surface points, mirror pairs of a mirrored sketch,
// the error naming the first unpaired node or arc, and the symmetrized node targets.
#include "core/layout/symmetry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/base/errors.h"
#include "core/layout/routing.h"
#include "core/layout/validate.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

double diagonal(const TriMesh& mesh) {
  Vec3 lo = mesh.point(OpenMesh::VertexHandle(0)), hi = lo;
  for (const auto vh : mesh.vertices()) {
    lo.minimize(mesh.point(vh));
    hi.maximize(mesh.point(vh));
  }
  return (hi - lo).norm();
}

// The ellipsoid of the bundled example's kind (three different radii), symmetric about x, y
// and z = 0, with a symmetric tessellation (k even).
test::MeshAndLayout ellipsoid() {
  return test::cube_sphere(8, Vec3(1.6, 1.0, 0.7));
}

// Rotation by \p angle (radians) about the unit axis \p axis, then a shift.
void move_rigidly(TriMesh& mesh, Vec3 axis, double angle, const Vec3& shift) {
  axis.normalize();
  const double c = std::cos(angle), s = std::sin(angle);
  for (const auto vh : mesh.vertices()) {
    const Vec3 p = mesh.point(vh);
    const Vec3 r = p * c + OpenMesh::cross(axis, p) * s + axis * OpenMesh::dot(axis, p) * (1 - c);
    mesh.set_point(vh, r + shift);
  }
}

Vec3 vertex(const TriMesh& mesh, int v) {
  return mesh.point(OpenMesh::VertexHandle(v));
}

// A vertex of \p mesh nearest to \p p.
int nearest_vertex(const TriMesh& mesh, const Vec3& p) {
  int best = -1;
  double best_d = 1e300;
  for (const auto vh : mesh.vertices())
    if (const double d = (mesh.point(vh) - p).sqrnorm(); d < best_d) {
      best_d = d;
      best = vh.idx();
    }
  return best;
}

// True when no node and no arc uses vertex \p v.
bool free_vertex(const Layout& layout, int v) {
  for (const auto& n : layout.nodes)
    if (n.vertex == v) return false;
  for (const auto& a : layout.arcs)
    for (int w : a.path)
      if (w == v) return false;
  return true;
}

TEST(Symmetry, AxisPlanesOfASymmetricEllipsoidHaveNoResidual) {
  const auto ex = ellipsoid();
  const ClosestPointTree tree(ex.mesh);
  for (int axis = 0; axis < 3; ++axis) {
    const SymmetryFit fit = mirror_plane(ex.mesh, tree, SymmetryAxis(axis));
    EXPECT_NEAR(fit.plane.normal[axis], 1.0, 0.0);
    EXPECT_NEAR(fit.plane.offset, 0.0, 1e-12);
    EXPECT_LT(fit.relative, 1e-12) << "axis " << axis;
  }
  // A plane that is no mirror plane has a clear residual.
  const SymmetryFit tilted =
      measure_symmetry(ex.mesh, tree, MirrorPlane{Vec3(1, 1, 0).normalize(), 0.0});
  EXPECT_GT(tilted.relative, 1e-2);
}

TEST(Symmetry, FitFindsTheMirrorPlaneOfAMovedEllipsoid) {
  auto ex = ellipsoid();
  const Vec3 axis(0.3, -0.5, 0.8);
  const double angle = 0.7;
  const Vec3 shift(0.4, -1.3, 2.2);
  move_rigidly(ex.mesh, axis, angle, shift);
  const ClosestPointTree tree(ex.mesh);
  const SymmetryFit fit = fit_mirror_plane(ex.mesh, tree);
  EXPECT_LT(fit.relative, 1e-9);
  // The plane is one of the ellipsoid's three, moved along: through the shifted centre with a
  // normal along a rotated coordinate axis.
  EXPECT_NEAR(fit.plane.signed_distance(shift), 0.0, 1e-9);
  TriMesh frame;  // the rotated coordinate axes
  for (const Vec3& e : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}) frame.add_vertex(e);
  move_rigidly(frame, axis, angle, Vec3(0, 0, 0));
  double best = 0.0;
  for (const auto vh : frame.vertices())
    best = std::max(best, std::abs(OpenMesh::dot(frame.point(vh), fit.plane.normal)));
  EXPECT_NEAR(best, 1.0, 1e-9);
}

// A cube's vertex samples have an isotropic covariance: its principal axes say nothing, and
// turned off the coordinate axes the closest-point iterations must find a mirror plane.
TEST(Symmetry, FitRefinesToAMirrorPlaneOfATurnedCube) {
  auto ex = test::cube_sphere(6, Vec3(1, 1, 1), /*project=*/false);
  move_rigidly(ex.mesh, Vec3(1, 2, 3), 0.25, Vec3(0.1, 0.2, -0.3));
  const ClosestPointTree tree(ex.mesh);
  const SymmetryFit fit = fit_mirror_plane(ex.mesh, tree);
  EXPECT_LT(fit.relative, 1e-6) << describe_plane(fit.plane);
  // Check it independently: every vertex's reflection lies on the surface.
  double worst = 0.0;
  for (const auto vh : ex.mesh.vertices())
    worst = std::max(worst, tree.closest(fit.plane.reflect(ex.mesh.point(vh))).distance);
  EXPECT_LT(worst / diagonal(ex.mesh), 1e-5);
}

TEST(Symmetry, FitReportsTheResidualOfANoisyMesh) {
  auto ex = ellipsoid();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double noise = 1e-3 * diagonal(ex.mesh);
  for (const auto vh : ex.mesh.vertices())
    ex.mesh.set_point(vh, ex.mesh.point(vh) + noise * Vec3(u(rng), u(rng), u(rng)));
  const ClosestPointTree tree(ex.mesh);
  const SymmetryFit fit = fit_mirror_plane(ex.mesh, tree);
  EXPECT_GT(fit.relative, 1e-5);  // the noise shows
  EXPECT_LT(fit.relative, 3e-3);
  EXPECT_GT(fit.max, fit.rms);
  // Still one of the three planes, near the origin.
  double best = 0.0;
  for (int a = 0; a < 3; ++a) best = std::max(best, std::abs(fit.plane.normal[a]));
  EXPECT_GT(best, 1.0 - 1e-3);
  EXPECT_LT(std::abs(fit.plane.offset), 1e-2 * diagonal(ex.mesh));
}

TEST(Symmetry, ReflectedSurfacePointsAreMirrorImagesOnTheSurface) {
  const auto ex = ellipsoid();
  const ClosestPointTree tree(ex.mesh);
  const MirrorPlane plane = axis_plane(ex.mesh, 0);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> face(0, int(ex.mesh.n_faces()) - 1);
  std::uniform_real_distribution<double> w(0.05, 1.0);
  for (int k = 0; k < 200; ++k) {
    SurfacePoint p;
    p.face = face(rng);
    const double a = w(rng), b = w(rng), c = w(rng);
    p.bary = {a / (a + b + c), b / (a + b + c), c / (a + b + c)};
    const ProjectedPoint r = reflect_surface_point(ex.mesh, tree, plane, p);
    const Vec3 x = surface_point_position(ex.mesh, p);
    EXPECT_LT(r.distance, 1e-12);
    EXPECT_LT((r.position - plane.reflect(x)).norm(), 1e-12);
    const ProjectedPoint back = reflect_surface_point(ex.mesh, tree, plane, r.point);
    EXPECT_LT((back.position - x).norm(), 1e-12);
  }
}

TEST(Symmetry, CubeLayoutPairsWithItselfAboutEachAxisPlane) {
  const auto ex = ellipsoid();
  for (int axis = 0; axis < 3; ++axis) {
    const MirrorPlane plane = axis_plane(ex.mesh, axis);
    SymmetryPairOptions options;
    options.tolerance = 1e-6;
    options.edge_lengths = 0.0;
    const SymmetryPairs pairs = find_mirror_pairs(ex.mesh, ex.layout, plane, options);
    EXPECT_LT(pairs.node_error, 1e-12);
    EXPECT_LT(pairs.arc_error, 1e-12);
    for (int i = 0; i < int(ex.layout.nodes.size()); ++i) {
      const int j = pairs.node_mirror[i];
      ASSERT_GE(j, 0);
      EXPECT_NE(j, i);  // the corners are off every axis plane
      EXPECT_LT((plane.reflect(vertex(ex.mesh, ex.layout.nodes[i].vertex)) -
                 vertex(ex.mesh, ex.layout.nodes[j].vertex))
                    .norm(),
                1e-12);
    }
    // The 4 cube edges parallel to the axis cross the plane: each is its own mirror.
    int own = 0;
    for (int a = 0; a < int(ex.layout.arcs.size()); ++a) own += pairs.arc_mirror[a] == a;
    EXPECT_EQ(own, 4);
  }
}

// A sketch on one side of x = 0 and on the plane, completed by its mirror image: the mirror
// nodes by mirror_vertex, the mirror arcs by mirror_path.
struct MirroredSketch {
  test::MeshAndLayout ex;
  MirrorPlane plane;
  Layout half, full;
  std::vector<int> mirror_of_node;  // per node index of `full`: expected mirror index
};

MirroredSketch mirrored_sketch() {
  MirroredSketch s;
  s.ex = ellipsoid();
  const TriMesh& mesh = s.ex.mesh;
  const ClosestPointTree tree(mesh);
  s.plane = axis_plane(mesh, 0);
  // A valence-3 node on the +x side of the front (+z) and two nodes on the plane x = 0, top
  // and bottom, joined to it; a node on the plane at the back; mirrored, a ring around the
  // mesh crossed by the plane.
  const int side = nearest_vertex(mesh, Vec3(1.0, 0.0, 0.6));
  const int top = nearest_vertex(mesh, Vec3(0.0, 1.0, 0.0));
  const int bottom = nearest_vertex(mesh, Vec3(0.0, -1.0, 0.0));
  EXPECT_EQ(mirror_vertex(mesh, tree, s.plane, top), top);
  EXPECT_EQ(mirror_vertex(mesh, tree, s.plane, bottom), bottom);
  Layout& h = s.half;
  h.nodes = {test::make_node(0, side), test::make_node(1, top), test::make_node(2, bottom)};
  auto add_arc = [&](Layout& layout, int id, int from, int to) {
    const RoutingObstacles obstacles = obstacles_of_layout(mesh, layout);
    const auto path = shortest_path(mesh, layout.nodes[layout.node_index(from)].vertex,
                                    layout.nodes[layout.node_index(to)].vertex, obstacles);
    EXPECT_GE(path.size(), 2u);
    layout.arcs.push_back(test::make_arc(id, from, to, path));
  };
  add_arc(h, 0, 0, 1);
  add_arc(h, 1, 0, 2);
  // Mirror: node 3 = mirror of node 0; arcs 2, 3 = mirrors of arcs 0, 1.
  s.full = h;
  const int mirror_side = mirror_vertex(mesh, tree, s.plane, side);
  EXPECT_NE(mirror_side, side);
  s.full.nodes.push_back(test::make_node(3, mirror_side));
  for (int a = 0; a < 2; ++a) {
    const LayoutArc& arc = h.arcs[a];
    const RoutingObstacles obstacles = obstacles_of_layout(mesh, s.full);
    const auto path = mirror_path(mesh, tree, s.plane, arc.path, obstacles, mirror_side);
    EXPECT_EQ(path.size(), arc.path.size());  // a symmetric tessellation: the exact image
    s.full.arcs.push_back(test::make_arc(2 + a, 3, arc.to, path));
  }
  s.mirror_of_node = {3, 1, 2, 0};
  return s;
}

TEST(Symmetry, AMirroredSketchIsASymmetricLayout) {
  const MirroredSketch s = mirrored_sketch();
  EXPECT_TRUE(validate_layout(s.ex.mesh, s.full).valid());
  SymmetryPairOptions options;
  options.tolerance = 1e-6;
  options.edge_lengths = 0.0;
  const SymmetryPairs pairs = find_mirror_pairs(s.ex.mesh, s.full, s.plane, options);
  EXPECT_EQ(pairs.node_mirror, s.mirror_of_node);
  EXPECT_EQ(pairs.arc_mirror, (std::vector<int>{2, 3, 0, 1}));
  EXPECT_LT(pairs.node_error, 1e-6);
  EXPECT_LT(pairs.arc_error, 1e-6);
  // The half sketch alone is not symmetric: the first node without a mirror is named.
  const SymmetryPairs half = match_mirror_pairs(s.ex.mesh, s.half, s.plane, options);
  EXPECT_FALSE(half.symmetric());
  EXPECT_EQ(half.first_unpaired_node, 0);
  EXPECT_EQ(half.node_mirror[1], 1);  // the plane nodes pair with themselves
  EXPECT_EQ(half.node_mirror[2], 2);
}

TEST(Symmetry, AnAsymmetricLayoutIsRefusedNamingTheFirstUnpairedNodeOrArc) {
  MirroredSketch s = mirrored_sketch();
  SymmetryPairOptions options;
  options.tolerance = 1e-6;
  options.edge_lengths = 0.0;
  // Node 3 moved one vertex over: nodes 0 and 3 lose their pairing.
  Layout moved = s.full;
  const int v = moved.nodes[3].vertex;
  int other = -1;
  for (const auto wh : s.ex.mesh.vv_range(OpenMesh::VertexHandle(v)))
    if (free_vertex(moved, wh.idx())) {
      other = wh.idx();
      break;
    }
  ASSERT_GE(other, 0);
  moved.nodes[3].vertex = other;
  try {
    find_mirror_pairs(s.ex.mesh, moved, s.plane, options);
    FAIL() << "an asymmetric layout was accepted";
  } catch (const InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not mirror symmetric"), std::string::npos) << what;
    EXPECT_NE(what.find("node 0 (vertex"), std::string::npos) << what;
  }
  // By default the tolerance is at least 1.5 mean edge lengths, as in the editor's mirrored
  // sketching: a node one vertex off its mirror image still pairs (on this mesh 1 % of the
  // diagonal is less than one edge).
  double mean_edge = 0.0;
  for (const auto eh : s.ex.mesh.edges()) mean_edge += s.ex.mesh.calc_edge_length(eh);
  mean_edge /= double(s.ex.mesh.n_edges());
  Vec3 lo = s.ex.mesh.point(*s.ex.mesh.vertices_begin()), hi = lo;
  for (const auto vh : s.ex.mesh.vertices()) {
    lo.minimize(s.ex.mesh.point(vh));
    hi.maximize(s.ex.mesh.point(vh));
  }
  ASSERT_LT(0.01 * (hi - lo).norm(), mean_edge);
  const SymmetryPairs near = match_mirror_pairs(s.ex.mesh, moved, s.plane);
  EXPECT_LT(near.first_unpaired_node, 0) << near.problem;
  EXPECT_EQ(near.node_mirror, s.mirror_of_node);
  // Every node pairs but one arc runs elsewhere: arc 3 takes another route to node 2.
  Layout rerouted = s.full;
  rerouted.arcs.pop_back();
  const int from = rerouted.nodes[3].vertex, to = rerouted.nodes[2].vertex;
  RoutingObstacles obstacles = obstacles_of_layout(s.ex.mesh, rerouted);
  // Block the mirror route so that the new one differs.
  for (std::size_t k = 1; k + 1 < s.full.arcs[3].path.size(); ++k)
    obstacles.vertex_blocked[s.full.arcs[3].path[k]] = 1;
  rerouted.arcs.push_back(test::make_arc(3, 3, 2, shortest_path(s.ex.mesh, from, to, obstacles)));
  ASSERT_GE(rerouted.arcs.back().path.size(), 2u);
  const SymmetryPairs pairs = match_mirror_pairs(s.ex.mesh, rerouted, s.plane, options);
  EXPECT_TRUE(pairs.first_unpaired_node < 0);
  EXPECT_FALSE(pairs.symmetric());
  try {
    find_mirror_pairs(s.ex.mesh, rerouted, s.plane, options);
    FAIL() << "an asymmetric layout was accepted";
  } catch (const InvalidInputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("arc 1 (nodes 0 to 2) has no mirror arc"), std::string::npos) << what;
  }
}

TEST(Symmetry, SymmetrizedTargetsMoveAsMirrorImagesAndPlaneNodesStayOnThePlane) {
  const MirroredSketch s = mirrored_sketch();
  const TriMesh& mesh = s.ex.mesh;
  const ClosestPointTree tree(mesh);
  const SymmetryPairs pairs = find_mirror_pairs(mesh, s.full, s.plane);
  // Proposed targets: each node's vertex pushed off in its own direction (asymmetric).
  std::vector<SurfacePoint> targets;
  const Vec3 push[4] = {{0.05, 0.1, 0.0}, {0.1, 0.0, 0.05}, {-0.08, 0.02, 0.0}, {0.0, -0.1, 0.1}};
  for (int i = 0; i < 4; ++i) {
    const Vec3 x = vertex(mesh, s.full.nodes[i].vertex) + push[i];
    targets.push_back(project_to_surface(tree, x).point);
  }
  const double d = diagonal(mesh);
  const auto out = symmetrize_targets(mesh, tree, s.plane, pairs.node_mirror, targets);
  ASSERT_EQ(out.size(), 4u);
  const Vec3 x0 = surface_point_position(mesh, out[0]);
  const Vec3 x3 = surface_point_position(mesh, out[3]);
  EXPECT_LT((s.plane.reflect(x0) - x3).norm() / d, 1e-9);
  // The pair moved to the mean of the two proposals (one reflected), up to the projection.
  const Vec3 mean = 0.5 * (surface_point_position(mesh, targets[0]) +
                           s.plane.reflect(surface_point_position(mesh, targets[3])));
  EXPECT_LT((x0 - mean).norm(),
            0.05 * (x0 - surface_point_position(mesh, targets[0])).norm() + 1e-3 * d);
  for (int i : {1, 2}) {
    const Vec3 x = surface_point_position(mesh, out[i]);
    EXPECT_LT(std::abs(s.plane.signed_distance(x)) / d, 1e-9) << "node index " << i;
    EXPECT_LT(tree.closest(x).distance, 1e-12);
  }
  // A fixed (pinned) node keeps its target; its partner mirrors it.
  std::vector<char> fixed(4, 0);
  fixed[3] = 1;
  const auto pinned = symmetrize_targets(mesh, tree, s.plane, pairs.node_mirror, targets, fixed);
  EXPECT_EQ(pinned[3].face, targets[3].face);
  EXPECT_EQ(pinned[3].bary, targets[3].bary);
  EXPECT_LT((s.plane.reflect(surface_point_position(mesh, pinned[3])) -
             surface_point_position(mesh, pinned[0]))
                    .norm() /
                d,
            1e-9);
  // A pairing that is not mutual is refused.
  std::vector<int> bad = pairs.node_mirror;
  bad[0] = 1;
  EXPECT_THROW(symmetrize_targets(mesh, tree, s.plane, bad, targets), InvalidInputError);
  EXPECT_THROW(symmetrize_targets(mesh, tree, s.plane, {0}, targets), InvalidInputError);
}

TEST(Symmetry, OptionsAndNamesAreChecked) {
  EXPECT_EQ(parse_symmetry_axis("x"), SymmetryAxis::X);
  EXPECT_EQ(parse_symmetry_axis("auto"), SymmetryAxis::Auto);
  EXPECT_THROW(parse_symmetry_axis("w"), InvalidInputError);
  SymmetryFitOptions o;
  o.max_samples = 3;
  EXPECT_THROW(validate_symmetry_fit_options(o), InvalidInputError);
  o = {};
  o.iterations = -1;
  EXPECT_THROW(validate_symmetry_fit_options(o), InvalidInputError);
  const auto ex = ellipsoid();
  SymmetryPairOptions p;
  p.tolerance = 0.0;
  EXPECT_THROW(match_mirror_pairs(ex.mesh, ex.layout, axis_plane(ex.mesh, 0), p),
               InvalidInputError);
  p.tolerance = std::nan("");
  EXPECT_THROW(match_mirror_pairs(ex.mesh, ex.layout, axis_plane(ex.mesh, 0), p),
               InvalidInputError);
  p = {};
  p.edge_lengths = -1.0;
  EXPECT_THROW(match_mirror_pairs(ex.mesh, ex.layout, axis_plane(ex.mesh, 0), p),
               InvalidInputError);
  EXPECT_THROW(axis_plane(ex.mesh, 3), InvalidInputError);
}

}  // namespace
}  // namespace qs
