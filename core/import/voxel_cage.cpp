#include "core/import/voxel_cage.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh_checks.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// good_block()[mask]: the 2×2×2 cell block around a grid vertex, bit dx + 2·dy + 4·dz set for
// an occupied cell, gives a manifold surface at the vertex: occupied and empty cells are each
// face-connected inside the block (the boundary curve on the vertex's link sphere is then a
// single cycle, or empty).
const std::array<bool, 256>& good_block() {
  static const std::array<bool, 256> table = [] {
    std::array<bool, 256> t{};
    auto connected = [](int set) {
      if (set == 0) return true;
      int seen = set & -set, grew = 1;
      while (grew) {
        grew = 0;
        for (int c = 0; c < 8; ++c) {
          if (!(seen >> c & 1)) continue;
          for (int axis = 0; axis < 3; ++axis) {
            const int d = c ^ (1 << axis);
            if ((set >> d & 1) && !(seen >> d & 1)) {
              seen |= 1 << d;
              grew = 1;
            }
          }
        }
      }
      return seen == set;
    };
    for (int m = 0; m < 256; ++m) t[m] = connected(m) && connected(~m & 255);
    return t;
  }();
  return table;
}

// Inside test of every cell centre by ray parity along one axis; adds one vote per inside cell.
void parity_votes(const TriMesh& mesh, const VoxelGrid& g, int a, std::vector<uint8_t>& votes) {
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  // Rays run through the cell centres, offset by a small irrational fraction of a cell so
  // that hits on mesh edges and vertices of axis-aligned models are unlikely.
  const double jb = g.h * 1.37e-3 * (a + 1), jc = g.h * 0.91e-3 * (a + 2);
  const int nb = g.dims[b], nc = g.dims[c];
  std::vector<std::vector<double>> hits(static_cast<size_t>(nb) * nc);
  for (const auto f : mesh.faces()) {
    Vec3 p[3];
    int k = 0;
    for (const auto v : mesh.fv_range(f)) p[k++] = mesh.point(v);
    double lob = std::numeric_limits<double>::infinity(), hib = -lob, loc = lob, hic = -lob;
    for (const Vec3& q : p) {
      lob = std::min(lob, q[b]);
      hib = std::max(hib, q[b]);
      loc = std::min(loc, q[c]);
      hic = std::max(hic, q[c]);
    }
    // Columns whose ray (origin + (j + 0.5)h + jitter) lies in [lo, hi].
    const int j0 = std::max(0, static_cast<int>(std::ceil((lob - g.origin[b] - jb) / g.h - 0.5)));
    const int j1 =
        std::min(nb - 1, static_cast<int>(std::floor((hib - g.origin[b] - jb) / g.h - 0.5)));
    const int k0 = std::max(0, static_cast<int>(std::ceil((loc - g.origin[c] - jc) / g.h - 0.5)));
    const int k1 =
        std::min(nc - 1, static_cast<int>(std::floor((hic - g.origin[c] - jc) / g.h - 0.5)));
    if (j0 > j1 || k0 > k1) continue;
    const double area =
        (p[1][b] - p[0][b]) * (p[2][c] - p[0][c]) - (p[2][b] - p[0][b]) * (p[1][c] - p[0][c]);
    if (area == 0) continue;  // parallel to the ray
    for (int j = j0; j <= j1; ++j) {
      const double yb = g.origin[b] + (j + 0.5) * g.h + jb;
      for (int kk = k0; kk <= k1; ++kk) {
        const double yc = g.origin[c] + (kk + 0.5) * g.h + jc;
        double w[3];
        for (int e = 0; e < 3; ++e) {
          const Vec3& u = p[(e + 1) % 3];
          const Vec3& v = p[(e + 2) % 3];
          w[e] = ((u[b] - yb) * (v[c] - yc) - (v[b] - yb) * (u[c] - yc)) / area;
        }
        if (w[0] < 0 || w[1] < 0 || w[2] < 0) continue;
        hits[static_cast<size_t>(j) + static_cast<size_t>(nb) * kk].push_back(
            w[0] * p[0][a] + w[1] * p[1][a] + w[2] * p[2][a]);
      }
    }
  }
  int idx[3];
  for (int kk = 0; kk < nc; ++kk) {
    for (int j = 0; j < nb; ++j) {
      auto& list = hits[static_cast<size_t>(j) + static_cast<size_t>(nb) * kk];
      if (list.empty()) continue;
      std::sort(list.begin(), list.end());
      size_t passed = 0;
      idx[b] = j;
      idx[c] = kk;
      for (int i = 0; i < g.dims[a]; ++i) {
        const double x = g.origin[a] + (i + 0.5) * g.h;
        while (passed < list.size() && list[passed] < x) ++passed;
        idx[a] = i;
        if (passed % 2 == 1) ++votes[g.cell(idx[0], idx[1], idx[2])];
      }
    }
  }
}

// Fills empty cells that cannot be reached from the outer layer through empty cells.
int fill_voids(VoxelGrid& g) {
  const int n = static_cast<int>(g.occupied.size());
  std::vector<char> outside(n, 0);
  std::vector<int> queue{0};
  outside[0] = 1;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int id = queue[head];
    const int i = id % g.dims[0], j = (id / g.dims[0]) % g.dims[1],
              k = id / (g.dims[0] * g.dims[1]);
    const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                          {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
    for (const auto& q : nb) {
      if (q[0] < 0 || q[1] < 0 || q[2] < 0 || q[0] >= g.dims[0] || q[1] >= g.dims[1] ||
          q[2] >= g.dims[2])
        continue;
      const int c = g.cell(q[0], q[1], q[2]);
      if (outside[c] || g.occupied[c]) continue;
      outside[c] = 1;
      queue.push_back(c);
    }
  }
  int filled = 0;
  for (int c = 0; c < n; ++c) {
    if (!g.occupied[c] && !outside[c]) {
      g.occupied[c] = 1;
      ++filled;
    }
  }
  return filled;
}

// Flips cells until every grid vertex's block is good. Returns the number of flips, or -1 when
// some block cannot be repaired.
int repair_manifold(VoxelGrid& g, const ClosestPointTree& tree, std::vector<char>& flipped) {
  const auto& good = good_block();
  std::vector<double> dist(g.occupied.size(), -1.0);
  auto distance = [&](int c) {
    if (dist[c] < 0) {
      const int i = c % g.dims[0], j = (c / g.dims[0]) % g.dims[1], k = c / (g.dims[0] * g.dims[1]);
      const Vec3 centre = g.origin + Vec3(i + 0.5, j + 0.5, k + 0.5) * g.h;
      dist[c] = tree.closest(centre).distance;
    }
    return dist[c];
  };
  int flips = 0;
  for (int pass = 0; pass < 64; ++pass) {
    int bad = 0, stuck = 0;
    for (int z = 1; z < g.dims[2]; ++z) {
      for (int y = 1; y < g.dims[1]; ++y) {
        for (int x = 1; x < g.dims[0]; ++x) {
          int cells[8], mask = 0;
          for (int bit = 0; bit < 8; ++bit) {
            cells[bit] = g.cell(x - 1 + (bit & 1), y - 1 + (bit >> 1 & 1), z - 1 + (bit >> 2 & 1));
            if (g.occupied[cells[bit]]) mask |= 1 << bit;
          }
          if (good[mask]) continue;
          ++bad;
          int best = -1;
          double best_score = std::numeric_limits<double>::infinity();
          for (int bit = 0; bit < 8; ++bit) {
            const int c = cells[bit];
            const int i = c % g.dims[0], j = (c / g.dims[0]) % g.dims[1],
                      k = c / (g.dims[0] * g.dims[1]);
            if (flipped[c] || i == 0 || j == 0 || k == 0 || i == g.dims[0] - 1 ||
                j == g.dims[1] - 1 || k == g.dims[2] - 1)
              continue;
            // Repairing flips first, then the cell whose centre is nearest to the surface
            // (the most uncertain classification); fills win ties.
            double score = distance(c) / g.h + (good[mask ^ (1 << bit)] ? 0.0 : 100.0);
            if (g.occupied[c]) score += 1e-6;
            if (score < best_score) {
              best_score = score;
              best = c;
            }
          }
          if (best < 0) {
            ++stuck;
            continue;
          }
          g.occupied[best] ^= 1;
          flipped[best] = 1;
          ++flips;
        }
      }
    }
    if (bad == 0) return flips;
    if (stuck == bad) return -1;
  }
  return -1;
}

std::string attempt_text(int resolution, const std::string& what) {
  return "resolution " + std::to_string(resolution) + ": " + what;
}

}  // namespace

PolyMesh voxel_cage(const TriMesh& mesh, int resolution, VoxelCageInfo* info, double shift,
                    int subsamples) {
  if (mesh.n_faces() == 0) throw InvalidInputError("the mesh has no faces");
  for (const auto e : mesh.edges()) {
    if (mesh.is_boundary(e)) {
      throw InvalidInputError("the mesh has a boundary (edge " + std::to_string(e.idx()) +
                              "); a voxel cage needs a closed surface");
    }
  }
  if (resolution < 2 || resolution > 200) {
    throw InvalidInputError("the cage resolution must be between 2 and 200 cells (got " +
                            std::to_string(resolution) + ")");
  }
  if (subsamples < 1 || subsamples > 8 || resolution * subsamples > 400) {
    throw InvalidInputError("the cage subsamples must be between 1 and 8, with resolution × " +
                            std::string("subsamples at most 400 (got ") +
                            std::to_string(subsamples) + " at resolution " +
                            std::to_string(resolution) + ")");
  }
  const double inf = std::numeric_limits<double>::infinity();
  Vec3 lo(inf, inf, inf), hi(-inf, -inf, -inf);
  for (const auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  const Vec3 extent = hi - lo;
  const double longest = std::max({extent[0], extent[1], extent[2]});
  if (!(longest > 0) || !std::isfinite(longest))
    throw InvalidInputError("the mesh has an empty or non-finite bounding box");
  VoxelCageInfo local;
  VoxelCageInfo& out = info ? *info : local;
  out = VoxelCageInfo{};
  VoxelGrid& g = out.grid;
  g.h = longest / resolution;
  for (int a = 0; a < 3; ++a) {
    // At least one cell over the extent, plus two empty layers on each side.
    g.dims[a] = std::max(1, static_cast<int>(std::ceil(extent[a] / g.h - 1e-9))) + 4;
    g.origin[a] = 0.5 * (lo[a] + hi[a]) - (0.5 * g.dims[a] + shift) * g.h;
    if (shift != 0) g.dims[a] += 1;
  }
  g.occupied.assign(static_cast<size_t>(g.dims[0]) * g.dims[1] * g.dims[2], 0);
  {
    // Inside test on the sample grid (the cells split subsamples³ times), counted per cell.
    const int s = subsamples;
    VoxelGrid samples;
    samples.h = g.h / s;
    samples.origin = g.origin;
    for (int a = 0; a < 3; ++a) samples.dims[a] = g.dims[a] * s;
    std::vector<uint8_t> votes(
        static_cast<size_t>(samples.dims[0]) * samples.dims[1] * samples.dims[2], 0);
    for (int a = 0; a < 3; ++a) parity_votes(mesh, samples, a, votes);
    std::vector<int> inside(g.occupied.size(), 0);
    for (int k = 0; k < samples.dims[2]; ++k)
      for (int j = 0; j < samples.dims[1]; ++j)
        for (int i = 0; i < samples.dims[0]; ++i)
          if (votes[samples.cell(i, j, k)] >= 2) ++inside[g.cell(i / s, j / s, k / s)];
    for (size_t c = 0; c < inside.size(); ++c) {
      g.occupied[c] = inside[c] > 0 && 2 * inside[c] >= s * s * s;
      out.inside_cells += g.occupied[c];
    }
  }
  if (out.inside_cells == 0) {
    throw InvalidInputError(attempt_text(
        resolution, "no cell centre lies inside the mesh (the shape is thinner than a cell)"));
  }
  const ClosestPointTree tree(mesh);
  std::vector<char> flipped(g.occupied.size(), 0);
  for (int round = 0;; ++round) {
    out.filled_voids += fill_voids(g);
    const int flips = repair_manifold(g, tree, flipped);
    if (flips < 0) {
      throw InvalidInputError(
          attempt_text(resolution, "the voxel surface could not be made manifold"));
    }
    out.flipped_cells += flips;
    if (flips == 0) break;
    if (round == 8) {
      throw InvalidInputError(
          attempt_text(resolution, "the voxel surface repair did not converge"));
    }
  }

  // Boundary faces of the occupied cells, oriented outward.
  const int gx = g.dims[0] + 1, gy = g.dims[1] + 1;
  auto grid_id = [&](int x, int y, int z) {
    return static_cast<long long>(x) + gx * (static_cast<long long>(y) + gy * z);
  };
  std::vector<std::array<long long, 4>> quads;
  for (int k = 1; k + 1 < g.dims[2]; ++k) {
    for (int j = 1; j + 1 < g.dims[1]; ++j) {
      for (int i = 1; i + 1 < g.dims[0]; ++i) {
        if (!g.at(i, j, k)) continue;
        for (int a = 0; a < 3; ++a) {
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          for (int side = 0; side < 2; ++side) {
            int q[3] = {i, j, k};
            q[a] += side ? 1 : -1;
            if (g.at(q[0], q[1], q[2])) continue;
            int base[3] = {i, j, k};
            base[a] += side;
            const int offs[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            std::array<long long, 4> quad;
            for (int s = 0; s < 4; ++s) {
              int p[3] = {base[0], base[1], base[2]};
              p[b] += offs[s][0];
              p[c] += offs[s][1];
              quad[side ? s : 3 - s] = grid_id(p[0], p[1], p[2]);
            }
            quads.push_back(quad);
          }
        }
      }
    }
  }
  std::vector<long long> ids;
  for (const auto& q : quads) ids.insert(ids.end(), q.begin(), q.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  PolyMesh cage;
  out.grid_vertex.clear();
  for (long long id : ids) {
    const int x = static_cast<int>(id % gx), y = static_cast<int>((id / gx) % gy),
              z = static_cast<int>(id / (static_cast<long long>(gx) * gy));
    out.grid_vertex.push_back({x, y, z});
    cage.add_vertex(g.origin + Vec3(x, y, z) * g.h);
  }
  for (const auto& q : quads) {
    std::vector<VH> vs;
    for (long long id : q)
      vs.emplace_back(static_cast<int>(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin()));
    if (!cage.add_face(vs).is_valid()) {
      throw InvalidInputError(attempt_text(
          resolution, "internal error: a voxel boundary face could not be added to the cage"));
    }
  }
  MeshReport report;
  count_topology(cage, report);
  out.genus = report.genus;
  out.components = report.components;
  return cage;
}

}  // namespace qs
