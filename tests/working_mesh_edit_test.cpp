// Tests of single working-mesh edits (core/mesh/working_mesh.h): splits, point insertion and
// its quality guarantee, moves, removal, flips, improve, locate and argument errors.
#include <gtest/gtest.h>

#include "tests/working_mesh_checks.h"

namespace qs::test {
namespace {

TEST(WorkingMesh, StartsAsTheInput) {
  const auto input = ellipsoid_mesh();
  WorkingMesh wm(input);
  EXPECT_EQ(wm.mesh().n_vertices(), input->n_vertices());
  EXPECT_EQ(wm.mesh().n_faces(), input->n_faces());
  EXPECT_EQ(wm.growth(), 1.0);
  EXPECT_EQ(wm.max_origin_error(), 0.0);
  for (auto f : input->faces()) {
    EXPECT_EQ(wm.host(f.idx()), f.idx());
    EXPECT_EQ(face_corners(wm.mesh(), f.idx()), face_corners(*input, f.idx()));
  }
  for (auto v : input->vertices()) {
    EXPECT_EQ(wm.carrier(v.idx()), WorkingMesh::Carrier::kInputVertex);
    // An input vertex is valid in every incident input face and in no other.
    std::set<int> incident;
    for (auto f : input->vf_range(v)) incident.insert(f.idx());
    for (int f : {0, 1, 2, 3, 500, 1000}) {
      const auto b = wm.bary_in_input_face(v.idx(), f);
      EXPECT_EQ(b.has_value(), incident.count(f) == 1);
      if (b) {
        EXPECT_EQ(from_bary(*input, f, *b), input->point(v));
      }
    }
  }
  expect_exact(wm, "fresh");
  expect_topology(wm, "fresh");
}

TEST(WorkingMesh, EdgeMidpointIsInsertedAsAnEdgeSplit) {
  for (bool boundary : {false, true}) {
    SCOPED_TRACE(boundary ? "boundary edge" : "interior edge");
    const auto input = share(disk_grid(4, 3, 2, 1).mesh);
    const TriMesh& in = *input;
    WorkingMesh wm(input);
    const auto h = input_halfedge(in, boundary);
    const int a = in.from_vertex_handle(h).idx(), b = in.to_vertex_handle(h).idx();
    const int faces = wm.live_faces();
    const auto ins = wm.insert_point(point_on_halfedge(in, h, 0.5));
    EXPECT_TRUE(ins.created);
    EXPECT_TRUE(ins.exact);
    EXPECT_EQ(wm.carrier(ins.vertex), WorkingMesh::Carrier::kInputEdge);
    EXPECT_EQ(*wm.input_edge_of(ins.vertex), (std::array<int, 2>{std::min(a, b), std::max(a, b)}));
    EXPECT_EQ(wm.live_faces(), faces + (boundary ? 1 : 2));
    const auto nb = neighbours(wm.mesh(), ins.vertex);
    EXPECT_EQ(nb.size(), boundary ? 3u : 4u);
    EXPECT_TRUE(nb.count(a) && nb.count(b));
    const Vec3 mid = 0.5 * (in.point(VH(a)) + in.point(VH(b)));
    EXPECT_LE((wm.mesh().point(VH(ins.vertex)) - mid).norm(), 1e-15 * diagonal(in));
    if (!boundary) {
      // Valid in both input faces of the edge, with the same position from either.
      const int g = in.opposite_face_handle(h).idx();
      const auto bg = wm.bary_in_input_face(ins.vertex, g);
      ASSERT_TRUE(bg.has_value());
      EXPECT_EQ(zeros(*bg), 1);
      EXPECT_EQ(wm.position(SurfacePoint{g, *bg}), wm.mesh().point(VH(ins.vertex)));
    }
    expect_exact(wm, "after the midpoint");
  }
}

TEST(WorkingMesh, SplitEdgeKeepsTheEdgeIndexOnTheSecondHalf) {
  const auto input = share(cube_sphere(3).mesh);
  WorkingMesh wm(input);
  const TriMesh& w = wm.mesh();
  const int e = 7;
  const auto h = w.halfedge_handle(EH(e), 0);
  const int a = w.from_vertex_handle(h).idx(), b = w.to_vertex_handle(h).idx();
  const int v = wm.split_edge(e, 0.25);
  const Vec3 expected = 0.75 * w.point(VH(a)) + 0.25 * w.point(VH(b));
  EXPECT_LE((w.point(VH(v)) - expected).norm(), 1e-15);
  const auto h2 = w.halfedge_handle(EH(e), 0);
  EXPECT_EQ((std::set<int>{w.from_vertex_handle(h2).idx(), w.to_vertex_handle(h2).idx()}),
            (std::set<int>{v, b}));
  expect_exact(wm, "after split_edge");
}

TEST(WorkingMesh, TwoPointsInOneInputTriangleAreBothInserted) {
  const auto input = ellipsoid_mesh();
  WorkingMesh wm(input);
  const int f = 100;
  const auto i1 = wm.insert_point(SurfacePoint{f, {{0.2, 0.3, 0.5}}});
  const auto i2 = wm.insert_point(SurfacePoint{f, {{0.5, 0.3, 0.2}}});
  EXPECT_TRUE(i1.created && i2.created);
  EXPECT_TRUE(i1.exact && i2.exact);
  EXPECT_NE(i1.vertex, i2.vertex);
  EXPECT_EQ(wm.carrier(i1.vertex), WorkingMesh::Carrier::kInputFace);
  EXPECT_EQ(wm.carrier(i2.vertex), WorkingMesh::Carrier::kInputFace);
  EXPECT_GE(wm.hosted_faces(f).size(), 5u);
  // A point within snap of the first: reused unless the caller forbids it.
  const SurfacePoint close{f, {{0.2 + 1e-3, 0.3, 0.5 - 1e-3}}};
  const auto reused = wm.insert_point(close);
  EXPECT_EQ(reused.vertex, i1.vertex);
  EXPECT_FALSE(reused.created);
  EXPECT_FALSE(reused.exact);
  const auto i3 = wm.insert_point(close, [&](int v) { return v != i1.vertex; });
  EXPECT_TRUE(i3.created);
  EXPECT_NE(i3.vertex, i1.vertex);
  EXPECT_NE(i3.vertex, i2.vertex);
  // Not exactly there (a sliver against the first), but never further than a snap.
  EXPECT_LE((wm.mesh().point(VH(i3.vertex)) - wm.position(close)).norm(),
            wm.options().snap * 1e-3 * diagonal(*input) + 1e-12);
  // Barycentrics that sum to 1 only within the files' tolerance are normalized: the vertex lies
  // on the input face's plane.
  const int g = f + 1;
  const auto loose = wm.insert_point(SurfacePoint{g, {{0.3333333, 0.3333333, 0.3333333}}});
  EXPECT_TRUE(loose.created && loose.exact);
  const SurfacePoint& o = wm.origin(loose.vertex);
  EXPECT_NEAR(o.bary[0] + o.bary[1] + o.bary[2], 1, 1e-15);
  EXPECT_LE(
      (wm.mesh().point(VH(loose.vertex)) - from_bary(*input, g, {{1.0 / 3, 1.0 / 3, 1.0 / 3}}))
          .norm(),
      1e-15 * diagonal(*input));
  // The same point again reuses the vertex exactly.
  const auto again = wm.insert_point(SurfacePoint{f, {{0.2, 0.3, 0.5}}});
  EXPECT_EQ(again.vertex, i1.vertex);
  EXPECT_TRUE(again.exact);
  expect_exact(wm, "after the insertions");
}

// The smallest angle around the vertex that the exact insertion of p (a split of the face or
// edge containing p, no snapping) creates in a copy of \p wm; 0 when that split is degenerate.
double exact_insertion_angle(WorkingMesh wm, const SurfacePoint& p) {
  const auto loc = wm.locate(p);
  const auto c = face_corners(wm.mesh(), loc.face);
  try {
    int v = -1;
    if (zeros(loc.bary) == 0) {
      v = wm.split_face(loc.face, loc.bary);
    } else {
      int k = 0;
      while (loc.bary[k] != 0) ++k;
      const int a = c[(k + 1) % 3], b = c[(k + 2) % 3];
      const auto h = wm.mesh().find_halfedge(VH(a), VH(b));
      const double t = loc.bary[(k + 2) % 3] / (loc.bary[(k + 1) % 3] + loc.bary[(k + 2) % 3]);
      const bool forward = wm.mesh().halfedge_handle(wm.mesh().edge_handle(h), 0) == h;
      v = wm.split_edge(wm.mesh().edge_handle(h).idx(), forward ? t : 1 - t);
    }
    return star_min_angle(wm.mesh(), v);
  } catch (const InvalidInputError&) {
    return 0;
  }
}

// The guarantee of insert_point: the triangles of a created vertex keep a smallest angle of
// min(min_angle_deg, the faces around the point before), or are no worse than the exact
// insertion of the point would make them.
TEST(WorkingMesh, InsertPointKeepsTheQualityBarOrDoesNoWorseThanExact) {
  const std::vector<std::shared_ptr<const TriMesh>> inputs = {
      ellipsoid_mesh(), share(cube_sphere(4).mesh), share(disk_grid(6, 6, 2, 2).mesh)};
  uint32_t seed = 3;
  for (const auto& input : inputs) {
    WorkingMesh wm(input);
    const TriMesh& w = wm.mesh();
    Rng rng(seed++);
    int created = 0, below = 0, worse_than_exact = 0;
    for (int i = 0; i < 800; ++i) {
      const SurfacePoint p = random_point(*input, rng);
      const auto loc = wm.locate(p);
      double before = face_min_angle(w, loc.face);
      for (auto g : w.ff_range(FH(loc.face))) before = std::min(before, face_min_angle(w, g.idx()));
      const WorkingMesh copy = wm;
      const auto ins = wm.insert_point(p);
      if (!ins.created) continue;
      ++created;
      const double angle = star_min_angle(w, ins.vertex);
      if (angle >= std::min(wm.options().min_angle_deg, before) - 1e-9) continue;
      ++below;
      if (angle < exact_insertion_angle(copy, p) - 1e-9) ++worse_than_exact;
    }
    EXPECT_GT(created, 300);
    EXPECT_EQ(worse_than_exact, 0);
    EXPECT_LE(below * 50, created);  // the bar holds for nearly every insertion
    expect_exact(wm, "after the insertions");
  }
}

// A point next to a vertex that may not be reused gets its own vertex, moved towards the face's
// centre by at most the snap distance (not exact).
TEST(WorkingMesh, PointNextToAForbiddenVertexGetsItsOwnVertexWithinSnap) {
  const auto input = share(disk_grid(4, 4, 2, 2).mesh);
  const int v = 6;  // the interior grid point (1, 1)
  const int f = input->vf_range(VH(v)).begin()->idx();
  const auto c = face_corners(*input, f);
  SurfacePoint p{f, {{1e-4, 1e-4, 1e-4}}};
  for (int k = 0; k < 3; ++k) {
    if (c[k] == v) p.bary[k] = 1 - 2e-4;
  }
  WorkingMesh reuse(input);
  const auto r = reuse.insert_point(p);
  EXPECT_EQ(r.vertex, v);
  EXPECT_FALSE(r.created);
  EXPECT_FALSE(r.exact);
  WorkingMesh forbid(input);
  const auto s = forbid.insert_point(p, [v](int u) { return u != v; });
  EXPECT_TRUE(s.created);
  EXPECT_NE(s.vertex, v);
  EXPECT_LE((forbid.mesh().point(VH(s.vertex)) - forbid.position(p)).norm(),
            forbid.options().snap * std::sqrt(2.0) + 1e-12);
  expect_exact(forbid, "after the forced insertion");
  // Exactly on a vertex that may not be reused: refused with the vertex named.
  SurfacePoint at{f, {{0, 0, 0}}};
  for (int k = 0; k < 3; ++k) at.bary[k] = c[k] == v ? 1 : 0;
  EXPECT_NE(error_of([&] {
              forbid.insert_point(at, [v](int u) { return u != v; });
            }).find("vertex " + std::to_string(v)),
            std::string::npos);
}

TEST(WorkingMesh, RemoveAfterInsertRestoresGrowth) {
  const auto input = ellipsoid_mesh();
  WorkingMesh wm(input);
  Rng rng(5);
  std::vector<int> created;
  for (int i = 0; i < 300; ++i) {
    const SurfacePoint p = random_point(*input, rng);
    if (zeros(p.bary) == 2) continue;  // an input vertex cannot be created
    const auto ins = wm.insert_point(p, [](int) { return false; });
    ASSERT_TRUE(ins.created);
    created.push_back(ins.vertex);
  }
  EXPECT_GT(wm.growth(), 1.3);
  double growth = wm.growth();
  for (auto it = created.rbegin(); it != created.rend(); ++it) {
    ASSERT_TRUE(wm.remove_vertex(*it)) << "vertex " << *it;
    EXPECT_LT(wm.growth(), growth);
    growth = wm.growth();
  }
  EXPECT_EQ(wm.growth(), 1.0);
  expect_exact(wm, "after the removals");
  wm.compact();
  EXPECT_EQ(wm.mesh().n_vertices(), input->n_vertices());
  EXPECT_EQ(wm.mesh().n_faces(), input->n_faces());
  expect_exact(wm, "compacted");
  expect_topology(wm, "compacted");
}

TEST(WorkingMesh, RemoveVertexKeepsInputEdgesAndInputVertices) {
  const auto input = share(disk_grid(4, 3, 2, 1).mesh);
  WorkingMesh wm(input);
  EXPECT_FALSE(wm.remove_vertex(3));
  // A vertex on an interior input edge with an interior vertex beside it: the collapse goes
  // along the input edge, never into the interior vertex.
  const auto h = input_halfedge(*input, false);
  const auto ins = wm.insert_point(point_on_halfedge(*input, h, 0.5));
  const int f = input->face_handle(h).idx();
  const auto side = wm.insert_point(SurfacePoint{f, {{0.3, 0.3, 0.4}}});
  ASSERT_TRUE(ins.created && side.created);
  const int a = input->from_vertex_handle(h).idx(), b = input->to_vertex_handle(h).idx();
  ASSERT_TRUE(wm.remove_vertex(ins.vertex));
  EXPECT_TRUE(wm.mesh().find_halfedge(VH(a), VH(b)).is_valid());
  expect_exact(wm, "after removing the edge vertex");
  wm.compact();
  expect_topology(wm, "compacted");
}

TEST(WorkingMesh, MoveVertexStaysInItsCarrier) {
  const auto input = share(disk_grid(4, 3, 2, 1).mesh);
  const TriMesh& in = *input;
  WorkingMesh wm(input);
  const TriMesh& w = wm.mesh();
  // Interior vertex: moves inside its host only.
  const int f = 5;
  const int v = wm.split_face(f, {0.3, 0.3, 0.4});
  const SurfacePoint o = wm.origin(v);
  EXPECT_EQ(o.face, f);
  SurfacePoint inside{f, {{0.35, 0.3, 0.35}}};
  EXPECT_TRUE(wm.move_vertex(v, inside));
  EXPECT_EQ(wm.origin(v).bary, inside.bary);
  EXPECT_EQ(w.point(VH(v)), wm.position(inside));
  EXPECT_FALSE(wm.move_vertex(v, SurfacePoint{f + 1, {{0.3, 0.3, 0.4}}}));  // another host
  EXPECT_FALSE(wm.move_vertex(v, SurfacePoint{f, {{0.5, 0.5, 0.0}}}));      // onto an input edge
  EXPECT_FALSE(wm.move_vertex(3, SurfacePoint{f, {{0.3, 0.3, 0.4}}}));      // an input vertex
  // Near an edge of the star: positively oriented but below the angle bar.
  const Vec3 before = w.point(VH(v));
  EXPECT_FALSE(wm.move_vertex(v, SurfacePoint{f, {{0.4995, 0.4995, 0.001}}}));
  EXPECT_EQ(w.point(VH(v)), before);
  // Outside the star of a vertex inside a sub-triangle: its star would fold.
  const auto sub = wm.locate(SurfacePoint{f, {{0.6, 0.2, 0.2}}});
  const int u = wm.split_face(sub.face, {1.0 / 3, 1.0 / 3, 1.0 / 3});
  EXPECT_FALSE(wm.can_move_vertex(u, SurfacePoint{f, {{0.05, 0.05, 0.9}}}));
  EXPECT_FALSE(wm.move_vertex(u, SurfacePoint{f, {{0.05, 0.05, 0.9}}}));
  // A vertex on an input edge slides along it, given in either adjacent input face.
  const auto h = input_halfedge(in, false);
  const int e = wm.split_edge(in.edge_handle(h).idx(), 0.5);
  EXPECT_EQ(wm.carrier(e), WorkingMesh::Carrier::kInputEdge);
  EXPECT_TRUE(wm.move_vertex(e, point_on_halfedge(in, h, 0.4)));
  EXPECT_EQ(w.point(VH(e)), wm.position(point_on_halfedge(in, h, 0.4)));
  EXPECT_TRUE(wm.move_vertex(e, point_on_halfedge(in, in.opposite_halfedge_handle(h), 0.45)));
  EXPECT_EQ(wm.carrier(e), WorkingMesh::Carrier::kInputEdge);
  SurfacePoint off = point_on_halfedge(in, h, 0.5);
  for (double& b : off.bary) b = b == 0 ? 0.01 : b - 0.005;
  EXPECT_FALSE(wm.move_vertex(e, off));  // off the input edge
  // A vertex on a boundary edge keeps the boundary: moving it inward would fold nothing but
  // cut the surface.
  const auto hb = input_halfedge(in, true);
  const int fb = in.face_handle(hb).idx();
  const int boundary_vertex = wm.split_edge(in.edge_handle(hb).idx(), 0.5);
  SurfacePoint inward = point_on_halfedge(in, hb, 0.5);
  for (double& b : inward.bary) b = b == 0 ? 0.02 : b - 0.01;
  EXPECT_EQ(inward.face, fb);
  EXPECT_FALSE(wm.move_vertex(boundary_vertex, inward));
  EXPECT_TRUE(wm.move_vertex(boundary_vertex, point_on_halfedge(in, hb, 0.55)));
  expect_exact(wm, "after the moves");
}

TEST(WorkingMesh, FlipOnlyInsideOneHostAndConvexQuads) {
  const auto input = share(disk_grid(4, 3, 2, 1).mesh);
  const TriMesh& in = *input;
  {
    WorkingMesh wm(input);
    EXPECT_FALSE(wm.flip_edge(in.edge_handle(input_halfedge(in, false)).idx()));  // two hosts
    EXPECT_FALSE(wm.flip_edge(in.edge_handle(input_halfedge(in, true)).idx()));   // boundary
    // After an input-edge split, the edge from the new vertex to an opposite corner lies in one
    // host but its quad has the new vertex exactly on a side: not strictly convex.
    const auto h = input_halfedge(in, false);
    const int m = wm.split_edge(in.edge_handle(h).idx(), 0.5);
    const int c = in.to_vertex_handle(in.next_halfedge_handle(h)).idx();
    const auto mc = wm.mesh().find_halfedge(VH(m), VH(c));
    ASSERT_TRUE(mc.is_valid());
    EXPECT_FALSE(wm.flip_edge(mc.edge().idx()));
  }
  // Edges inside one refined host: flip_edge agrees with an independent convexity test.
  auto build = [&] {
    auto wm = std::make_unique<WorkingMesh>(input);
    wm->split_face(5, {0.6, 0.25, 0.15});
    wm->split_face(5, {0.2, 0.5, 0.3});
    const auto loc = wm->locate(SurfacePoint{5, {{0.15, 0.15, 0.7}}});
    wm->split_face(loc.face, {0.3, 0.3, 0.4});
    return wm;
  };
  const auto reference = build();
  const TriMesh& w = reference->mesh();
  int convex = 0, concave = 0;
  for (auto e : w.edges()) {
    if (e.is_boundary()) continue;
    const auto h0 = e.halfedge(0), h1 = e.halfedge(1);
    const int host = reference->host(h0.face().idx());
    if (reference->host(h1.face().idx()) != host || host != 5) continue;
    auto b = [&](OpenMesh::VertexHandle v) {
      return *reference->bary_in_input_face(v.idx(), host);
    };
    const Bary a = b(h0.from()), bb = b(h0.to()), c = b(h0.next().to()), d = b(h1.next().to());
    const bool exists = w.find_halfedge(h0.next().to(), h1.next().to()).is_valid();
    const double o1 = orient(a, d, c), o2 = orient(d, bb, c);
    if (std::abs(o1) < 1e-9 || std::abs(o2) < 1e-9) continue;
    const bool predicted = o1 > 0 && o2 > 0 && !exists;
    predicted ? ++convex : ++concave;
    auto wm = build();
    EXPECT_EQ(wm->flip_edge(e.idx()), predicted) << "edge " << e.idx();
    expect_exact(*wm, "after a flip");
  }
  EXPECT_GT(convex, 0);
  EXPECT_GT(concave, 0);
}

TEST(WorkingMesh, ImproveRaisesSmallAnglesAndKeepsProtectedEdges) {
  const auto input = ellipsoid_mesh();
  WorkingMesh wm(input);
  Rng rng(9);
  std::vector<int> created;
  for (int i = 0; i < 400; ++i) {
    const int f = rng.index(static_cast<int>(wm.mesh().n_faces()));
    Bary b{rng.uniform(0.02, 1), rng.uniform(0.02, 1), rng.uniform(0.02, 1)};
    const double s = b[0] + b[1] + b[2];
    for (double& x : b) x /= s;
    created.push_back(wm.split_face(f, b));
  }
  const TriMesh& w = wm.mesh();
  std::set<int> protect;
  std::vector<std::array<int, 2>> protected_pairs;
  for (int k = 0; k < 40; ++k) {
    for (auto e : w.ve_range(VH(created[k]))) {
      protect.insert(e.idx());
      protected_pairs.push_back({e.v0().idx(), e.v1().idx()});
    }
  }
  auto count_below = [&](double degrees) {
    int n = 0;
    for (auto f : w.faces()) n += face_min_angle(w, f.idx()) < degrees;
    return n;
  };
  const double before = wm.min_angle_deg();
  const int slivers = count_below(5);
  const int flips = wm.improve({}, [&](int e) { return protect.count(e) > 0; });
  EXPECT_GT(flips, 20);
  EXPECT_GE(wm.min_angle_deg(), before);
  EXPECT_LT(count_below(5), slivers);
  for (const auto& pr : protected_pairs) {
    EXPECT_TRUE(w.find_halfedge(VH(pr[0]), VH(pr[1])).is_valid());
  }
  // Locally Delaunay inside every host, apart from protected edges.
  int non_delaunay = 0;
  for (auto e : w.edges()) {
    if (e.is_boundary() || protect.count(e.idx())) continue;
    const auto h0 = e.halfedge(0), h1 = e.halfedge(1);
    if (wm.host(h0.face().idx()) != wm.host(h1.face().idx())) continue;
    auto angle = [&](OpenMesh::VertexHandle at) {
      const Vec3 u = w.point(h0.from()) - w.point(at), v = w.point(h0.to()) - w.point(at);
      return std::atan2(OpenMesh::cross(u, v).norm(), OpenMesh::dot(u, v));
    };
    if (angle(h0.next().to()) + angle(h1.next().to()) > M_PI + 1e-9) ++non_delaunay;
  }
  EXPECT_EQ(non_delaunay, 0);
  expect_exact(wm, "after improve");
}

TEST(WorkingMesh, LocatesPointsOnInputEdgesExactly) {
  const auto input = share(cube_sphere(3).mesh);
  const TriMesh& in = *input;
  WorkingMesh wm(input);
  const auto h = input_halfedge(in, false);
  for (double t : {0.2, 0.45, 0.7}) wm.insert_point(point_on_halfedge(in, h, t));
  for (auto side : {h, in.opposite_halfedge_handle(h)}) {
    for (double t : {0.1, 0.2, 0.3, 0.5, 0.8}) {
      const SurfacePoint p = point_on_halfedge(in, side, t);
      const auto loc = wm.locate(p);
      EXPECT_EQ(wm.host(loc.face), p.face);
      EXPECT_GE(zeros(loc.bary), 1) << "t " << t;
      const auto c = face_corners(wm.mesh(), loc.face);
      Vec3 x(0, 0, 0);
      for (int k = 0; k < 3; ++k) x += loc.bary[k] * wm.mesh().point(VH(c[k]));
      EXPECT_LE((x - wm.position(p)).norm(), 1e-15);
    }
  }
  // An input vertex: a face around it, weight 1 at its corner.
  const int v = in.from_vertex_handle(h).idx();
  const auto loc = wm.locate(point_on_halfedge(in, h, 0.0));
  const auto c = face_corners(wm.mesh(), loc.face);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(loc.bary[k], c[k] == v ? 1.0 : 0.0);
}

TEST(WorkingMesh, RejectsBadArgumentsNamingTheElement) {
  const auto input = ellipsoid_mesh();
  WorkingMesh wm(input);
  auto names = [](const std::string& message, const std::string& what) {
    return message.find(what) != std::string::npos;
  };
  for (double t : {0.0, 1.0, -0.5, 1.5, std::nan("")}) {
    EXPECT_TRUE(names(error_of([&] { wm.split_edge(5, t); }), "edge 5")) << t;
  }
  EXPECT_TRUE(names(error_of([&] { wm.split_edge(-1, 0.5); }), "edge -1"));
  EXPECT_TRUE(names(error_of([&] { wm.split_edge(1 << 20, 0.5); }), "edge 1048576"));
  for (Bary b : {Bary{0, 0.5, 0.5}, Bary{1.2, -0.1, -0.1}, Bary{0.5, 0.5, 0.5}, Bary{0.3, 0.3, 0.3},
                 Bary{std::nan(""), 0.5, 0.5}}) {
    EXPECT_TRUE(names(error_of([&] { wm.split_face(9, b); }), "face 9"));
  }
  EXPECT_TRUE(names(error_of([&] {
                      wm.insert_point(SurfacePoint{-1, {{1, 0, 0}}});
                    }),
                    "input face -1"));
  EXPECT_TRUE(names(error_of([&] {
                      wm.insert_point(SurfacePoint{4, {{0.5, 0.6, -0.1}}});
                    }),
                    "input face 4"));
  EXPECT_TRUE(names(error_of([&] {
                      wm.locate(SurfacePoint{4, {{0.5, 0.5, 0.5}}});
                    }),
                    "input face 4"));
  EXPECT_TRUE(names(error_of([&] {
                      wm.move_vertex(-3, SurfacePoint{0, {{1, 0, 0}}});
                    }),
                    "vertex -3"));
  EXPECT_TRUE(names(error_of([&] { wm.remove_vertex(100000); }), "vertex 100000"));
  EXPECT_TRUE(names(error_of([&] { wm.flip_edge(-2); }), "edge -2"));
  // Deleted elements are invalid arguments too.
  const int v = wm.split_face(9, {0.2, 0.3, 0.5});
  std::vector<int> star;
  for (auto f : wm.mesh().vf_range(VH(v))) star.push_back(f.idx());
  ASSERT_TRUE(wm.remove_vertex(v));
  int deleted = -1;
  for (int f : star) {
    if (wm.mesh().status(FH(f)).deleted()) deleted = f;
  }
  ASSERT_GE(deleted, 0);
  EXPECT_TRUE(names(error_of([&] {
                      wm.split_face(deleted, {0.2, 0.3, 0.5});
                    }),
                    "face " + std::to_string(deleted)));
  EXPECT_TRUE(names(error_of([&] { wm.remove_vertex(v); }), "vertex " + std::to_string(v)));
  // Options and input.
  EXPECT_TRUE(names(error_of([&] { WorkingMesh bad(input, {-0.1, 1.0}); }), "snap"));
  EXPECT_TRUE(names(error_of([&] { WorkingMesh bad(input, {std::nan(""), 1.0}); }), "snap"));
  EXPECT_TRUE(names(error_of([&] { WorkingMesh bad(input, {0.1, 60.0}); }), "min_angle_deg"));
  EXPECT_TRUE(names(error_of([&] { WorkingMesh bad(nullptr); }), "no input mesh"));
  TriMesh isolated = *input;
  isolated.add_vertex(Vec3(0, 0, 0));
  EXPECT_TRUE(names(error_of([&] { WorkingMesh bad(share(isolated)); }),
                    "input vertex " + std::to_string(input->n_vertices())));
}

}  // namespace
}  // namespace qs::test
