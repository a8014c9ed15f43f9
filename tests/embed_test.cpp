// Discretizing a layout onto a working mesh (core/layout/embed.h): layouts far too fine for the
// input triangulation embed, the input surface is kept exactly, and only layouts that are
// invalid as curves fail, naming their arcs.
#include "core/layout/embed.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "core/base/errors.h"
#include "core/layout/separation.h"
#include "core/layout/validate.h"
#include "core/mesh/closest_point.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

SurfacePoint surface_point(const ClosestPointTree& tree, const Vec3& p) {
  const ClosestPoint c = tree.closest(p);
  SurfacePoint s;
  s.face = c.face;
  s.bary = c.bary;
  return s;
}

// The box layout (8 nodes, 12 arcs, 6 patches) with corners in the directions
// (±1, ±1, ±flat), projected onto \p mesh, each arc given by points along its great circle.
// With a small `flat` the top and bottom corners come within one triangle of each other on a
// coarse sphere, and the top and bottom arcs within one edge.
Layout box_layout(const TriMesh& mesh, double flat, int samples = 6) {
  const ClosestPointTree tree(mesh);
  Layout layout;
  std::vector<Vec3> dir;
  for (int i = 0; i < 8; ++i) {
    const Vec3 d((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? flat : -flat);
    dir.push_back(d.normalized());
    LayoutNode n;
    n.id = i;
    n.point = surface_point(tree, dir.back());
    layout.nodes.push_back(n);
  }
  int id = 0;
  for (int i = 0; i < 8; ++i) {
    for (int bit : {1, 2, 4}) {
      const int j = i | bit;
      if (j == i) continue;
      LayoutArc arc;
      arc.id = id++;
      arc.from = i;
      arc.to = j;
      for (int k = 1; k < samples; ++k) {
        const double t = double(k) / samples;
        arc.points.push_back(surface_point(tree, ((1 - t) * dir[i] + t * dir[j]).normalized()));
      }
      layout.arcs.push_back(arc);
    }
  }
  return layout;
}

// Every working vertex is reproduced from its origin, no input vertex moved, the area is the
// input's.
void expect_exact(const WorkingMesh& w) {
  EXPECT_LE(w.max_origin_error(), 1e-12);
  for (int v = 0; v < w.input_vertices(); ++v)
    ASSERT_EQ(w.mesh().point(OpenMesh::VertexHandle(v)),
              w.input().point(OpenMesh::VertexHandle(v)));
  double a = 0, b = 0;
  for (auto f : w.mesh().faces()) a += w.mesh().calc_face_area(f);
  for (auto f : w.input().faces()) b += w.input().calc_face_area(f);
  EXPECT_NEAR(a, b, 1e-12 * b);
}

// No vertex is the only room between two arcs: the separation rule holds after embedding.
void expect_separated(const WorkingMesh& w, const Layout& layout) {
  WorkingMesh copy = w;
  EXPECT_EQ(separate_layout(copy, layout), 0);
}

TEST(Embed, CoarseSphereTakesABoxLayoutWithTwoNodesPerTriangle) {
  const auto mesh = std::make_shared<const TriMesh>(test::icosphere(1));  // 80 faces
  const Layout layout = box_layout(*mesh, 0.08);
  // The premise, from the input alone: the top and bottom corners share input faces.
  int shared = 0;
  for (int i = 0; i < 4; ++i)
    shared += layout.nodes[i].point->face == layout.nodes[i + 4].point->face;
  ASSERT_GT(shared, 0);
  const EmbeddedLayout e = embed_layout(mesh, layout);
  std::printf(
      "[stat] box on an 80-face sphere: %zu -> %zu faces (%.2fx), %d route and %d "
      "separation splits, %d flips\n",
      mesh->n_faces(), e.mesh->mesh().n_faces(), e.mesh->growth(), e.stats.route_splits,
      e.stats.separation_splits, e.stats.flips);
  const ValidationResult v = validate_layout(e.mesh->mesh(), e.layout);
  for (const auto& issue : v.issues) ADD_FAILURE() << format_issue(issue);
  ASSERT_TRUE(v.valid());
  expect_exact(*e.mesh);
  expect_separated(*e.mesh, e.layout);
  for (size_t i = 0; i < layout.nodes.size(); ++i) {
    const Vec3 want = e.mesh->position(*layout.nodes[i].point);
    const Vec3 got = e.mesh->mesh().point(OpenMesh::VertexHandle(e.layout.nodes[i].vertex));
    EXPECT_LE((want - got).norm(), 0.1 * 0.8) << "node " << i;  // within the snap distance
  }
  // The layout embeds: with the orientation constraints its fixed-node parameterization has no
  // fold-over and the traced layout is structurally equivalent.
  PipelineOptions options;
  options.param.orientation.enabled = true;
  Pipeline p(e.mesh->mesh(), e.layout, options);
  p.compute_field();
  const Parameterization& par = p.compute_parameterization();
  EXPECT_EQ(par.foldovers, 0) << par.orientation.message;
  EXPECT_TRUE(p.extract().structurally_equivalent);
}

TEST(Embed, NodeAtAnEdgeMidpointSplitsTheEdge) {
  const auto mesh = std::make_shared<const TriMesh>(test::icosphere(2));
  Layout layout = box_layout(*mesh, 0.6);
  // Node 0 exactly at the midpoint of an edge of its face.
  SurfacePoint& p = *layout.nodes[0].point;
  p.bary = {0.5, 0.5, 0.0};
  const EmbeddedLayout e = embed_layout(mesh, layout);
  const int v = e.layout.nodes[0].vertex;
  ASSERT_FALSE(e.mesh->is_input_vertex(v));
  EXPECT_EQ(e.mesh->carrier(v), WorkingMesh::Carrier::kInputEdge);
  EXPECT_EQ(e.mesh->position(*e.layout.nodes[0].point), e.mesh->position(p));
  EXPECT_TRUE(validate_layout(e.mesh->mesh(), e.layout).valid());
  expect_exact(*e.mesh);
}

TEST(Embed, ExplicitInputPathsAreKeptThroughSplits) {
  const auto in = test::cube_sphere(3);
  const auto mesh = std::make_shared<const TriMesh>(in.mesh);
  const EmbeddedLayout e = embed_layout(mesh, in.layout);
  ASSERT_TRUE(validate_layout(e.mesh->mesh(), e.layout).valid());
  // The cube layout has room everywhere: nothing to split, the same paths.
  EXPECT_EQ(e.stats.separation_splits, 0);
  for (size_t a = 0; a < in.layout.arcs.size(); ++a)
    EXPECT_EQ(e.layout.arcs[a].path, in.layout.arcs[a].path) << "arc " << a;
}

TEST(Embed, TwoNodesAtOnePointAreReported) {
  const auto mesh = std::make_shared<const TriMesh>(test::icosphere(2));
  Layout layout = box_layout(*mesh, 0.6);
  try {
    Layout bad = layout;
    bad.nodes[1].point = bad.nodes[0].point;  // two nodes at one point
    embed_layout(mesh, bad);
    FAIL() << "expected an error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("node 1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace qs
