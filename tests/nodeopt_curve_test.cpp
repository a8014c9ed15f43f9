// Node optimization on curves (issue #5, paper §6.1.1): a node on the mesh boundary or on a
// feature curve slides along it, its arcs along the curve moving with it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/field/curvature.h"
#include "core/import/perturb.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/relocation.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Vertex index of grid point (i, j) of test::disk_grid(nx, ·, ·, ·).
int grid_vertex(int nx, int i, int j) {
  return j * (nx + 1) + i;
}

int node_at(const Layout& layout, int vertex) {
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n)
    if (layout.nodes[n].vertex == vertex) return n;
  return -1;
}

// Every edge of the chain \p curve (consecutive vertices) lies on some arc path.
bool curve_covered_by_arcs(const Layout& layout, const std::vector<int>& curve) {
  for (size_t k = 0; k + 1 < curve.size(); ++k) {
    bool found = false;
    for (const auto& arc : layout.arcs)
      for (size_t j = 0; j + 1 < arc.path.size() && !found; ++j)
        found = (arc.path[j] == curve[k] && arc.path[j + 1] == curve[k + 1]) ||
                (arc.path[j] == curve[k + 1] && arc.path[j + 1] == curve[k]);
    if (!found) return false;
  }
  return true;
}

// Moves the node on the walk's first vertex to its last one, the arcs along the curve with it;
// returns the node's index, or -1 when the move or the moved layout is not valid.
int displace(const TriMesh& mesh, Layout& layout, const CurveWalk& walk) {
  const int n = node_at(layout, walk.vertices.front());
  if (n < 0 ||
      !move_node_and_reroute(mesh, layout, n, walk.vertices.back(), {}, nullptr, nullptr, &walk))
    return -1;
  return validate_layout(mesh, layout).valid() ? n : -1;
}

struct SlideRun {
  NodeOptResult result;
  bool equivalent = false;
};

SlideRun optimize(const TriMesh& mesh, const Layout& layout, bool slide) {
  NodeOptOptions no;
  no.moves.slide_on_curves = slide;
  SlideRun run;
  run.result = optimize_nodes(mesh, layout, PipelineOptions{}, no);
  Pipeline check(run.result.mesh, run.result.layout);
  check.compute_parameterization();
  run.equivalent = check.extract().structurally_equivalent;
  return run;
}

// What both displaced nodes must show: the residual gone (the flat grid is isometric again),
// the run without sliding left the node where it was, the curve still covered by arcs, a valid
// and structurally equivalent layout without fold-overs.
void expect_slid(const SlideRun& on, const SlideRun& off, int n, const CurveWalk& walk,
                 const std::vector<int>& curve) {
  const NodeOptResult& r = on.result;
  EXPECT_LT(r.E_final, 1e-9 * r.E_init);
  EXPECT_GT(off.result.E_final, 0.1 * r.E_init) << "without sliding the node stays displaced";
  EXPECT_EQ(off.result.layout.nodes[n].vertex, walk.vertices.back());
  EXPECT_TRUE(curve_covered_by_arcs(r.layout, curve));
  EXPECT_TRUE(validate_layout(r.mesh, r.layout).valid());
  EXPECT_TRUE(on.equivalent);
  EXPECT_EQ(r.foldovers_final, 0);
}

// A T-node on the boundary of a flat 2×2 grid layout, displaced two edges along the boundary,
// slides until the layout's middle line is straight again (the flat grid is then isometric).
TEST(CurveSliding, BoundaryNodeSlidesBack) {
  const int nx = 12;
  const auto grid = test::disk_grid(nx, 12, 2, 2);
  Layout layout = grid.layout;
  const CurveWalk walk{{grid_vertex(nx, 6, 0), grid_vertex(nx, 7, 0), grid_vertex(nx, 8, 0)},
                       grid_vertex(nx, 5, 0)};
  const int n = displace(grid.mesh, layout, walk);
  ASSERT_GE(n, 0);
  std::vector<int> bottom;
  for (int i = 0; i <= nx; ++i) bottom.push_back(grid_vertex(nx, i, 0));
  ASSERT_TRUE(curve_covered_by_arcs(layout, bottom)) << "the displaced arcs left the boundary";

  const SlideRun on = optimize(grid.mesh, layout, true);
  const SlideRun off = optimize(grid.mesh, layout, false);
  const NodeOptResult& r = on.result;
  const int v = r.layout.nodes[n].vertex;
  const Vec3 p = r.mesh.point(r.mesh.vertex_handle(v));
  std::printf(
      "[stat] boundary node: E %.4g -> %.4g sliding (node at x = %.3f), %.4g without; %d steps\n",
      r.E_init, r.E_final, p[1] == 0 ? p[0] : -1.0, off.result.E_final, r.steps);
  EXPECT_TRUE(r.mesh.is_boundary(r.mesh.vertex_handle(v)));
  EXPECT_EQ(p[1], 0.0) << "the node left the boundary line";
  // The vertical middle line of the layout straight again (at x = 6 or wherever the free
  // translation took it): the flat grid is isometric.
  const int centre = node_at(grid.layout, grid_vertex(nx, 6, 6));
  const Vec3 c = r.mesh.point(r.mesh.vertex_handle(r.layout.nodes[centre].vertex));
  EXPECT_NEAR(c[0], p[0], 1e-6);
  expect_slid(on, off, n, walk, bottom);
}

// The centre node of the same layout on an explicit feature curve (the vertical middle grid
// line), displaced two edges along it: it slides along the feature, never off it, until the
// horizontal middle line is straight again.
TEST(CurveSliding, FeatureNodeSlidesAlongTheFeature) {
  const int nx = 12;
  const auto grid = test::disk_grid(nx, 12, 2, 2);
  Layout layout = grid.layout;
  std::vector<int> line;
  for (int j = 0; j <= 12; ++j) line.push_back(grid_vertex(nx, 6, j));
  for (size_t k = 0; k + 1 < line.size(); ++k)
    layout.feature_edges.push_back({line[k], line[k + 1]});
  const CurveWalk walk{{grid_vertex(nx, 6, 6), grid_vertex(nx, 6, 7), grid_vertex(nx, 6, 8)},
                       grid_vertex(nx, 6, 5)};
  const int n = displace(grid.mesh, layout, walk);
  ASSERT_GE(n, 0);
  ASSERT_TRUE(curve_covered_by_arcs(layout, line));

  const SlideRun on = optimize(grid.mesh, layout, true);
  const SlideRun off = optimize(grid.mesh, layout, false);
  const NodeOptResult& r = on.result;
  const int v = r.layout.nodes[n].vertex;
  const Vec3 p = r.mesh.point(r.mesh.vertex_handle(v));
  std::printf("[stat] feature node: E %.4g -> %.4g sliding (node at y = %.3f), %.4g without\n",
              r.E_init, r.E_final, p[0] == 6 ? p[1] : -1.0, off.result.E_final);
  EXPECT_EQ(p[0], 6.0) << "the node left the feature line";
  EXPECT_NE(std::find(line.begin(), line.end(), v), line.end());
  // The horizontal middle line straight again (the side nodes slide along the boundary too).
  for (int side : {node_at(grid.layout, grid_vertex(nx, 0, 6)),
                   node_at(grid.layout, grid_vertex(nx, 12, 6))}) {
    const Vec3 q = r.mesh.point(r.mesh.vertex_handle(r.layout.nodes[side].vertex));
    EXPECT_NEAR(q[1], p[1], 1e-6);
  }
  expect_slid(on, off, n, walk, line);
  // Every relocated vertex of the result stays on the original surface (z = 0); the ones on
  // the feature line stay on it.
  for (auto vh : r.mesh.vertices()) {
    EXPECT_EQ(r.mesh.point(vh)[2], 0.0);
    if (std::find(line.begin(), line.end(), vh.idx()) != line.end()) {
      EXPECT_EQ(r.mesh.point(vh)[0], 6.0) << "feature vertex " << vh.idx();
    }
  }
}

// NodeOptOptions::Moves::sharp_edges_as_curves on the genus-2 polycube with nodes displaced one
// ring from its corners: the polycube's edges are sharp curves, nodes on them slide along them, the
// others step onto them only at a vertex's place. Every node ends on its corner and no vertex
// on a sharp edge leaves the polycube's edge lines.
TEST(CurveSliding, SharpEdgesKeepTheirShape) {
  const auto poly = test::genus2_polycube(4);
  PerturbLayoutOptions po;
  po.rings = 1;
  po.seed = 1;
  const Layout start = perturb_layout(poly.mesh, poly.layout, po).layout;
  const GeometryCache g = build_geometry(poly.mesh);
  const std::vector<char> sharp = sharp_edges(poly.mesh, g, 35.0);
  const CurveNetwork curves = make_curve_network(poly.mesh, start, 30.0, &sharp);
  // Vertices on sharp edges that left the polycube's edge lines in a state of the run.
  auto off_lines = [&](const TriMesh& mesh) {
    int off = 0;
    for (auto vh : poly.mesh.vertices()) {
      const auto& nb = curves.neighbours[vh.idx()];
      const Vec3 q = poly.mesh.point(vh), p = mesh.point(vh);
      if (nb.empty() || p == q) continue;
      bool on_line = false;  // on the segment to one of its curve neighbours
      for (int x : nb) {
        const Vec3 d = poly.mesh.point(poly.mesh.vertex_handle(x)) - q;
        on_line |= (d % (p - q)).norm() <= 1e-12 * d.norm() && (d | (p - q)) > 0;
      }
      off += !on_line;
    }
    return off;
  };
  auto run = [&](bool keep, int& off, int& sliding) {
    NodeOptOptions no;
    no.moves.sharp_edges_as_curves = keep;
    NodeOptimizer opt(poly.mesh, start, PipelineOptions{}, no);
    off = 0;
    while (opt.step()) off += off_lines(opt.mesh());
    const NodeOptResult r = opt.finish();
    sliding = r.sliding_nodes;
    return r;
  };
  int off_keep = 0, off_free = 0, sliding = 0, unused = 0;
  const NodeOptResult r = run(true, off_keep, sliding);
  run(false, off_free, unused);
  std::printf(
      "[stat] polycube, sharp edges as curves: E %.4g -> %.4g, %d sliding nodes; sharp vertices "
      "off their lines summed over the steps: %d (without: %d)\n",
      r.E_init, r.E_final, sliding, off_keep, off_free);
  EXPECT_GT(sliding, 0);
  EXPECT_LT(r.E_final, 1e-6 * r.E_init);
  EXPECT_EQ(off_keep, 0);
  EXPECT_GT(off_free, 0) << "the case should relocate sharp vertices without the option";
  EXPECT_EQ(off_lines(r.mesh), 0);
}

// A hop along a curve (hop_sweep with HopSweepOptions::curves): the displaced boundary node,
// its vertex relocated along the boundary towards where it belongs, hops to that boundary
// neighbour (a boundary vertex, which other hops may not take) with its arcs along the
// boundary; without the curves the same target is refused.
TEST(CurveSliding, HopAlongTheBoundary) {
  const int nx = 12;
  const auto grid = test::disk_grid(nx, 12, 2, 2);
  Layout layout = grid.layout;
  const CurveWalk walk{{grid_vertex(nx, 6, 0), grid_vertex(nx, 7, 0)}, grid_vertex(nx, 5, 0)};
  const int n = displace(grid.mesh, layout, walk);
  ASSERT_GE(n, 0);
  TriMesh mesh = grid.mesh;  // the node's vertex (7, 0) relocated to x = 6.6, towards (6, 0)
  const auto vh = mesh.vertex_handle(grid_vertex(nx, 7, 0));
  mesh.set_point(vh, Vec3(6.6, 0, 0));
  const HopEvaluator evaluate = [](const TriMesh& m, const Layout& l, double& E, int& folds) {
    Pipeline p(m, l, PipelineOptions{}, false);
    const Parameterization& par = p.compute_parameterization();
    E = unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, par, PipelineOptions{}.param);
    folds = par.foldovers;
    return true;
  };
  double E0 = 0;
  int folds0 = 0;
  ASSERT_TRUE(evaluate(mesh, layout, E0, folds0));
  const CurveNetwork curves = make_curve_network(grid.mesh, layout, 30.0);
  HopSweepOptions options;
  options.targets = {{grid_vertex(nx, 6, 0)}};
  TriMesh refused_mesh = mesh;
  Layout refused = layout;
  const HopSweepResult none =
      hop_sweep(grid.mesh, refused_mesh, refused, {n}, {}, E0, folds0, options, evaluate);
  EXPECT_EQ(none.moved, 0) << "a boundary vertex is no target for a plain hop";
  options.curves = &curves;
  const HopSweepResult r =
      hop_sweep(grid.mesh, mesh, layout, {n}, {}, E0, folds0, options, evaluate);
  std::printf("[stat] hop along the boundary: E %.4g -> %.4g\n", E0, r.E);
  ASSERT_EQ(r.moved, 1);
  EXPECT_EQ(layout.nodes[n].vertex, grid_vertex(nx, 6, 0));
  EXPECT_EQ(mesh.point(vh), grid.mesh.point(vh)) << "the vertex it left is back in place";
  EXPECT_LT(r.E, 1e-9 * E0);
  std::vector<int> bottom;
  for (int i = 0; i <= nx; ++i) bottom.push_back(grid_vertex(nx, i, 0));
  EXPECT_TRUE(curve_covered_by_arcs(layout, bottom));
  EXPECT_TRUE(validate_layout(mesh, layout).valid());
}

// Curve ends, junctions and corners do not slide.
TEST(CurveSliding, CornersAndJunctionsStay) {
  const int nx = 12;
  const auto grid = test::disk_grid(nx, 12, 2, 2);
  Layout layout = grid.layout;
  for (int j = 0; j < 12; ++j)
    layout.feature_edges.push_back({grid_vertex(nx, 6, j), grid_vertex(nx, 6, j + 1)});
  const CurveNetwork curves = make_curve_network(grid.mesh, layout, 30.0);
  EXPECT_FALSE(curves.slides[grid_vertex(nx, 0, 0)]);  // boundary corner (90°)
  EXPECT_TRUE(curves.slides[grid_vertex(nx, 3, 0)]);   // straight boundary
  EXPECT_FALSE(curves.slides[grid_vertex(nx, 6, 0)]);  // boundary meets the feature
  EXPECT_TRUE(curves.slides[grid_vertex(nx, 6, 6)]);   // on the feature line
  EXPECT_FALSE(curves.slides[grid_vertex(nx, 3, 3)]);  // interior, no curve
  EXPECT_EQ(curves.neighbours[grid_vertex(nx, 6, 0)].size(), 3u);
}

// The carrying vertex of a node that slid along a curve segment (the optimizer's rule for sliding
// nodes): the nearer end first, at the point itself; the farther end at most at the middle; an
// end that does not slide only at its own place; an occupied end not at all.
TEST(CurveSliding, CarrierOfASlidNodeFollowsTheSegmentRules) {
  // Vertices 0 and 1 slide, 2 is a corner (does not slide).
  const std::vector<char> slides = {1, 1, 0};
  auto any = [](int) { return true; };
  auto pairs = [](const std::vector<CurveCarrier>& c) {
    std::vector<std::pair<int, double>> out;
    for (const CurveCarrier& x : c) out.push_back({x.vertex, x.fraction});
    return out;
  };
  using P = std::vector<std::pair<int, double>>;
  // Both ends slide: the nearer carries to the point, the farther to the middle.
  EXPECT_EQ(pairs(curve_carriers(0, 1, 0.3, 0, slides, any)), (P{{0, 0.3}, {1, 0.5}}));
  EXPECT_EQ(pairs(curve_carriers(0, 1, 0.8, 0, slides, any)), (P{{1, 0.8}, {0, 0.5}}));
  // Stopped just short of the corner 2: the corner cannot carry the node there, so the node's
  // own vertex does, capped at the middle (not at 0.9, which would squeeze its faces).
  EXPECT_EQ(pairs(curve_carriers(0, 2, 0.9, 0, slides, any)), (P{{0, 0.5}}));
  // On the corner itself the corner carries it (at its own place), else the middle.
  EXPECT_EQ(pairs(curve_carriers(0, 2, 1.0, 0, slides, any)), (P{{2, 1.0}, {0, 0.5}}));
  // Segment (corner, node vertex): the corner carries only at fraction 0.
  EXPECT_EQ(pairs(curve_carriers(2, 1, 0.2, 1, slides, any)), (P{{1, 0.5}}));
  EXPECT_EQ(pairs(curve_carriers(2, 1, 0.0, 1, slides, any)), (P{{2, 0.0}, {1, 0.5}}));
  // An end that may not be taken (another node or arc there) is skipped; the node's own vertex
  // is never skipped.
  auto not_1 = [](int w) { return w != 1; };
  EXPECT_EQ(pairs(curve_carriers(0, 1, 0.8, 0, slides, not_1)), (P{{0, 0.5}}));
  auto none = [](int) { return false; };
  EXPECT_EQ(pairs(curve_carriers(0, 1, 0.3, 0, slides, none)), (P{{0, 0.3}}));
  EXPECT_EQ(pairs(curve_carriers(0, 1, 0.3, 1, slides, none)), (P{{1, 0.5}}));
}

}  // namespace
}  // namespace qs
