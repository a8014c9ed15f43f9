// Random edits of the working mesh (core/mesh/working_mesh.h) on three inputs: after every
// batch, W is exact (vertices on their origins, faces in their hosts, the input's area), and
// after compaction manifold with the input's topology, with consistent index maps.
#include <gtest/gtest.h>

#include "tests/working_mesh_checks.h"

namespace qs::test {
namespace {

struct OpCounts {
  int split_edge = 0, split_face = 0, insert_created = 0, insert_reused = 0, insert_refused = 0,
      move = 0, move_refused = 0, remove = 0, flip = 0, improve = 0, compact = 0;
};

// Random edits in batches; every batch ends with the invariant checks, a compaction (checked
// against its maps) and locate checks.
void stress(std::shared_ptr<const TriMesh> input, uint32_t seed, int batches, int ops,
            OpCounts& count) {
  WorkingMesh wm(input);
  const TriMesh& in = *input;
  const TriMesh& w = wm.mesh();
  const double diag = diagonal(in);
  double longest_input_edge = 0;
  for (auto e : in.edges())
    longest_input_edge = std::max(longest_input_edge, in.calc_edge_length(e));
  Rng rng(seed);
  for (int batch = 0; batch < batches; ++batch) {
    const uint32_t salt = static_cast<uint32_t>(batch) * 2654435761u;
    // Every fourth vertex (by a per-batch hash) may not be reused by insert_point.
    auto may_reuse = [salt](int v) {
      return ((static_cast<uint32_t>(v) * 2246822519u) ^ salt) % 4 != 0;
    };
    for (int op = 0; op < ops; ++op) {
      const double r = rng.uniform();
      const int nv = static_cast<int>(w.n_vertices()), nf = static_cast<int>(w.n_faces()),
                ne = static_cast<int>(w.n_edges());
      auto live_vertex = [&](int v) { return !w.status(VH(v)).deleted(); };
      auto live_face = [&](int f) { return !w.status(FH(f)).deleted(); };
      auto live_edge = [&](int e) { return !w.status(EH(e)).deleted(); };
      if (r < 0.12) {
        const int e = random_live(rng, ne, live_edge);
        if (e < 0) continue;
        const int v = wm.split_edge(e, rng.uniform(0.15, 0.85));
        EXPECT_EQ(v, nv);
        ++count.split_edge;
      } else if (r < 0.24) {
        const int f = random_live(rng, nf, live_face);
        if (f < 0) continue;
        Bary b{rng.uniform(0.1, 1), rng.uniform(0.1, 1), rng.uniform(0.1, 1)};
        const double s = b[0] + b[1] + b[2];
        for (double& x : b) x /= s;
        wm.split_face(f, b);
        ++count.split_face;
      } else if (r < 0.50) {
        const SurfacePoint p = random_point(in, rng);
        const bool restricted = rng.uniform() < 0.5;
        WorkingMesh::Inserted ins;
        try {
          ins = restricted ? wm.insert_point(p, may_reuse) : wm.insert_point(p);
        } catch (const InvalidInputError&) {
          // Only a point on a vertex that may not be reused is refused.
          const auto loc = wm.locate(p);
          EXPECT_TRUE(restricted);
          EXPECT_EQ(zeros(loc.bary), 2);
          ++count.insert_refused;
          continue;
        }
        const double d = (w.point(VH(ins.vertex)) - wm.position(p)).norm();
        if (ins.exact) {
          EXPECT_LE(d, 1e-12 * diag);
        } else {
          EXPECT_LE(d, wm.options().snap * longest_input_edge * (1 + 1e-9));
        }
        if (!ins.created && restricted) {
          EXPECT_TRUE(may_reuse(ins.vertex));
        }
        EXPECT_EQ(ins.created, ins.vertex >= nv);
        ins.created ? ++count.insert_created : ++count.insert_reused;
      } else if (r < 0.64) {
        if (nv == wm.input_vertices()) continue;
        const int v = random_live(rng, nv - wm.input_vertices(),
                                  [&](int i) { return live_vertex(i + wm.input_vertices()); });
        if (v < 0) continue;
        const int vv = v + wm.input_vertices();
        SurfacePoint p = wm.origin(vv);
        const int i = rng.index(3), j = (i + 1 + rng.index(2)) % 3;
        const double delta = rng.uniform(-0.05, 0.05);
        if (p.bary[i] != 0 && p.bary[j] != 0 && p.bary[i] + delta > 0 && p.bary[j] - delta > 0) {
          p.bary[i] += delta;
          p.bary[j] -= delta;
        }
        if (rng.uniform() < 0.1) p = random_point(in, rng);  // mostly refused
        const Vec3 before = w.point(VH(vv));
        const SurfacePoint origin_before = wm.origin(vv);
        const bool can = wm.can_move_vertex(vv, p);
        const bool moved = wm.move_vertex(vv, p);
        EXPECT_EQ(can, moved);
        if (moved) {
          EXPECT_EQ(wm.origin(vv).face, p.face);
          EXPECT_EQ(w.point(VH(vv)), wm.position(p));
          ++count.move;
        } else {
          EXPECT_EQ(w.point(VH(vv)), before);
          EXPECT_EQ(wm.origin(vv).bary, origin_before.bary);
          ++count.move_refused;
        }
      } else if (r < 0.80) {
        if (nv == wm.input_vertices()) continue;
        const int v = random_live(rng, nv, live_vertex);
        if (v < 0) continue;
        const bool removed = wm.remove_vertex(v);
        if (v < wm.input_vertices()) {
          EXPECT_FALSE(removed);
        }
        if (removed) {
          EXPECT_TRUE(w.status(VH(v)).deleted());
          ++count.remove;
        }
      } else if (r < 0.97) {
        // Half of the flips try an edge at a refinement vertex (mostly inside one host).
        int e = random_live(rng, ne, live_edge);
        const int n = wm.input_vertices();
        if (rng.uniform() < 0.5 && nv > n) {
          const int v = random_live(rng, nv - n, [&](int i) { return live_vertex(i + n); });
          if (v >= 0) {
            std::vector<int> star;
            for (auto ve : w.ve_range(VH(v + n))) star.push_back(ve.idx());
            e = star[rng.index(static_cast<int>(star.size()))];
          }
        }
        if (e < 0) continue;
        const auto h0 = w.halfedge_handle(EH(e), 0);
        const bool boundary = w.is_boundary(EH(e));
        const int fa = boundary ? -1 : w.face_handle(h0).idx();
        const int fb = boundary ? -1 : w.opposite_face_handle(h0).idx();
        const bool flipped = wm.flip_edge(e);
        if (flipped) {
          EXPECT_FALSE(boundary);
          EXPECT_EQ(wm.host(fa), wm.host(fb));
          ++count.flip;
        }
      } else {
        std::vector<int> faces;
        for (int k = 0; k < 5; ++k) {
          const int f = random_live(rng, nf, live_face);
          if (f >= 0) faces.push_back(f);
        }
        const double before = wm.min_angle_deg();
        wm.improve(faces);
        EXPECT_GE(wm.min_angle_deg(), before - 1e-9);
        ++count.improve;
      }
    }
    const std::string where = "seed " + std::to_string(seed) + " batch " + std::to_string(batch);
    expect_exact(wm, where + " before compact");
    // Compaction: maps consistent with the old mesh.
    std::vector<Vec3> old_points(w.n_vertices());
    for (auto v : w.all_vertices()) old_points[v.idx()] = w.point(v);
    std::vector<int> old_hosts(w.n_faces(), -1);
    for (auto f : w.faces()) old_hosts[f.idx()] = wm.host(f.idx());
    std::vector<std::array<int, 2>> old_edges(w.n_edges());
    for (auto e : w.edges()) old_edges[e.idx()] = {e.v0().idx(), e.v1().idx()};
    const auto map = wm.compact();
    ++count.compact;
    for (int v = 0; v < wm.input_vertices(); ++v) EXPECT_EQ(map.vertex[v], v);
    for (size_t v = 0; v < map.vertex.size(); ++v) {
      if (map.vertex[v] >= 0) {
        EXPECT_EQ(w.point(VH(map.vertex[v])), old_points[v]);
      }
    }
    for (size_t f = 0; f < map.face.size(); ++f) {
      EXPECT_EQ(map.face[f] >= 0, old_hosts[f] >= 0);
      if (map.face[f] >= 0) {
        EXPECT_EQ(wm.host(map.face[f]), old_hosts[f]);
      }
    }
    for (size_t e = 0; e < map.edge.size(); ++e) {
      if (map.edge[e] < 0) continue;
      const auto h = w.halfedge_handle(EH(map.edge[e]), 0);
      std::set<int> now{w.from_vertex_handle(h).idx(), w.to_vertex_handle(h).idx()};
      std::set<int> then{map.vertex[old_edges[e][0]], map.vertex[old_edges[e][1]]};
      EXPECT_EQ(now, then);
    }
    expect_exact(wm, where + " after compact");
    expect_topology(wm, where);
    // locate(): the returned face contains the point.
    for (int k = 0; k < 30; ++k) {
      const SurfacePoint p = random_point(in, rng);
      const auto loc = wm.locate(p);
      EXPECT_GE(loc.face, 0);
      if (loc.face < 0) continue;
      const auto c = face_corners(w, loc.face);
      Vec3 x(0, 0, 0);
      for (int j = 0; j < 3; ++j) {
        EXPECT_GE(loc.bary[j], 0);
        x += loc.bary[j] * w.point(VH(c[j]));
      }
      EXPECT_NEAR(loc.bary[0] + loc.bary[1] + loc.bary[2], 1, 1e-12);
      EXPECT_LE((x - wm.position(p)).norm(), 1e-12 * diag);
      if (zeros(p.bary) == 1) {
        EXPECT_GE(zeros(loc.bary), 1);
      }
    }
    if (::testing::Test::HasFailure()) break;
  }
}

void expect_all_ops_ran(const OpCounts& c) {
  EXPECT_GT(c.split_edge, 100);
  EXPECT_GT(c.split_face, 100);
  EXPECT_GT(c.insert_created, 100);
  EXPECT_GT(c.insert_reused, 20);
  EXPECT_GT(c.move, 100);
  EXPECT_GT(c.move_refused, 10);
  EXPECT_GT(c.remove, 100);
  EXPECT_GT(c.flip, 30);
  EXPECT_GT(c.improve, 10);
}

TEST(WorkingMesh, RandomEditsStayExactOnEllipsoid) {
  OpCounts count;
  stress(ellipsoid_mesh(), 7, 16, 250, count);
  expect_all_ops_ran(count);
}

TEST(WorkingMesh, RandomEditsStayExactOnCubeSphere) {
  OpCounts count;
  stress(share(cube_sphere(3).mesh), 11, 16, 250, count);
  expect_all_ops_ran(count);
}

TEST(WorkingMesh, RandomEditsStayExactOnDiskWithBoundary) {
  OpCounts count;
  stress(share(disk_grid(4, 3, 2, 1).mesh), 13, 16, 250, count);
  expect_all_ops_ran(count);
}

}  // namespace
}  // namespace qs::test
