#include "core/import/cage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <limits>
#include <numeric>
#include <string>

#include "core/base/errors.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh_checks.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// Mean edge length of a polygon mesh (0 without edges).
double mean_edge_length(const PolyMesh& m) {
  double sum = 0;
  for (const auto e : m.edges()) sum += m.calc_edge_length(e);
  return sum / std::max<size_t>(1, m.n_edges());
}

// Mean position of v's neighbours (v itself when it has none).
Vec3 neighbour_mean(const PolyMesh& m, VH v) {
  Vec3 sum(0, 0, 0);
  int count = 0;
  for (const auto w : m.vv_range(v)) {
    sum += m.point(w);
    ++count;
  }
  return count ? sum / count : m.point(v);
}

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

namespace {

// Closest points restricted to faces whose normal agrees with a reference direction, among
// the faces within a search radius (a uniform hash grid of face bounding boxes); falls back
// to the unrestricted closest point. Keeps cage vertices on their own side of thin parts.
class SidedProjector {
 public:
  SidedProjector(const TriMesh& mesh, double cell) : mesh_(mesh), tree_(mesh), cell_(cell) {
    normal_.resize(mesh.n_faces());
    corners_.resize(mesh.n_faces());
    const double inf = std::numeric_limits<double>::infinity();
    lo_ = Vec3(inf, inf, inf);
    Vec3 hi(-inf, -inf, -inf);
    for (const auto v : mesh.vertices()) {
      lo_.minimize(mesh.point(v));
      hi.maximize(mesh.point(v));
    }
    for (int a = 0; a < 3; ++a)
      dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo_[a]) / cell_)) + 1);
    buckets_.assign(static_cast<size_t>(dims_[0]) * dims_[1] * dims_[2], {});
    for (const auto f : mesh.faces()) {
      int k = 0;
      Vec3 blo(inf, inf, inf), bhi(-inf, -inf, -inf);
      for (const auto v : mesh.fv_range(f)) {
        corners_[f.idx()][k++] = mesh.point(v);
        blo.minimize(mesh.point(v));
        bhi.maximize(mesh.point(v));
      }
      Vec3 n = mesh.calc_face_normal(f);
      const double len = n.norm();
      normal_[f.idx()] = len > 0 ? n / len : Vec3(0, 0, 0);
      const auto a = bucket_of(blo), b = bucket_of(bhi);
      for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
          for (int x = a[0]; x <= b[0]; ++x) buckets_[index(x, y, z)].push_back(f.idx());
    }
    stamp_.assign(mesh.n_faces(), 0);
  }

  const Vec3& face_normal(int f) const { return normal_[f]; }

  //! Closest point on a face within \p radius whose normal has a positive dot product with
  //! \p reference (unrestricted closest point when there is none).
  ClosestPoint project(const Vec3& p, const Vec3& reference, double radius) {
    const ClosestPoint nearest = tree_.closest(p);
    if (OpenMesh::dot(normal_[nearest.face], reference) > 0) return nearest;
    ClosestPoint best;
    best.distance = std::numeric_limits<double>::infinity();
    const auto a = bucket_of(p - Vec3(radius, radius, radius));
    const auto b = bucket_of(p + Vec3(radius, radius, radius));
    ++current_;
    for (int z = a[2]; z <= b[2]; ++z) {
      for (int y = a[1]; y <= b[1]; ++y) {
        for (int x = a[0]; x <= b[0]; ++x) {
          for (int f : buckets_[index(x, y, z)]) {
            if (stamp_[f] == current_) continue;
            stamp_[f] = current_;
            if (OpenMesh::dot(normal_[f], reference) <= 0) continue;
            const auto& c = corners_[f];
            const TrianglePoint tp = closest_point_on_triangle(p, c[0], c[1], c[2]);
            if (tp.distance < best.distance) {
              best.distance = tp.distance;
              best.point = tp.point;
              best.face = f;
              best.bary = tp.bary;
            }
          }
        }
      }
    }
    if (best.face < 0 || best.distance > radius) return nearest;
    return best;
  }

 private:
  std::array<int, 3> bucket_of(const Vec3& p) const {
    std::array<int, 3> b;
    for (int a = 0; a < 3; ++a)
      b[a] = std::clamp(static_cast<int>(std::floor((p[a] - lo_[a]) / cell_)), 0, dims_[a] - 1);
    return b;
  }
  size_t index(int x, int y, int z) const {
    return static_cast<size_t>(x) +
           static_cast<size_t>(dims_[0]) * (y + static_cast<size_t>(dims_[1]) * z);
  }

  const TriMesh& mesh_;
  ClosestPointTree tree_;
  double cell_;
  Vec3 lo_;
  std::array<int, 3> dims_{{1, 1, 1}};
  std::vector<std::vector<int>> buckets_;
  std::vector<Vec3> normal_;
  std::vector<std::array<Vec3, 3>> corners_;
  std::vector<int> stamp_;
  int current_ = 0;
};

// Area-weighted (Newell) normal of a polygon-mesh vertex.
Vec3 cage_vertex_normal(const PolyMesh& cage, VH v) {
  Vec3 n(0, 0, 0);
  for (const auto f : cage.vf_range(v)) {
    for (const auto h : cage.fh_range(f)) {
      n += OpenMesh::cross(cage.point(cage.from_vertex_handle(h)),
                           cage.point(cage.to_vertex_handle(h)));
    }
  }
  return n;
}

}  // namespace

void refine_fitted_cage(PolyMesh& cage, const TriMesh& mesh) {
  const size_t old_vertices = cage.n_vertices();
  if (old_vertices == 0) return;
  const double mean_edge = mean_edge_length(cage);
  cage = split_to_quads(cage);
  SidedProjector projector(mesh, 0.5 * mean_edge);
  std::vector<Vec3> normal(cage.n_vertices());
  for (const auto v : cage.vertices()) normal[v.idx()] = cage_vertex_normal(cage, v);
  for (const auto v : cage.vertices()) {
    if (static_cast<size_t>(v.idx()) < old_vertices) continue;
    cage.set_point(v, projector.project(cage.point(v), normal[v.idx()], 1.5 * mean_edge).point);
  }
}

namespace {

// Umbrella smoothing of all vertices, each round followed by a closest-point projection onto
// faces facing the same way as the quad mesh at the vertex.
void relax_vertices(PolyMesh& quads, const TriMesh& mesh, int iterations) {
  if (iterations <= 0 || quads.n_vertices() == 0) return;
  const double mean_edge = mean_edge_length(quads);
  SidedProjector projector(mesh, mean_edge);
  std::vector<Vec3> next(quads.n_vertices());
  for (int it = 0; it < iterations; ++it) {
    for (const auto v : quads.vertices()) next[v.idx()] = neighbour_mean(quads, v);
    for (const auto v : quads.vertices()) {
      const Vec3 n = cage_vertex_normal(quads, v);
      quads.set_point(v, projector.project(next[v.idx()], n, 3.0 * mean_edge).point);
    }
  }
}

}  // namespace

int fit_cage(PolyMesh& cage, const TriMesh& mesh, const CageFitOptions& options) {
  const size_t nv = cage.n_vertices();
  if (nv == 0) return 0;
  const double mean_edge = mean_edge_length(cage);
  SidedProjector projector(mesh, mean_edge);
  std::vector<Vec3> cage_normal(nv), next(nv);
  for (const auto v : cage.vertices()) cage_normal[v.idx()] = cage_vertex_normal(cage, v);
  std::vector<int> face(nv, -1);
  for (int it = 0; it < options.presmoothing; ++it) {
    for (const auto v : cage.vertices()) {
      next[v.idx()] = cage.point(v) + options.step * (neighbour_mean(cage, v) - cage.point(v));
    }
    for (const auto v : cage.vertices()) cage.set_point(v, next[v.idx()]);
  }
  const double radius = 3.0 * mean_edge;
  for (const auto v : cage.vertices()) {
    const ClosestPoint cp = projector.project(cage.point(v), cage_normal[v.idx()], radius);
    cage.set_point(v, cp.point);
    face[v.idx()] = cp.face;
  }
  // Tangential spring relaxation: every cage edge pulls/pushes towards the mean edge length,
  // every quad diagonal towards √2 times it (keeps quads from collapsing onto a line).
  const double rest = mean_edge_length(cage);
  auto spring = [&](const Vec3& from, const Vec3& to, double length) {
    const Vec3 d = to - from;
    const double l = d.norm();
    return l > 1e-12 * rest ? d * ((l - length) / l) : Vec3(0, 0, 0);
  };
  for (int it = 0; it < options.iterations; ++it) {
    for (const auto v : cage.vertices()) {
      const Vec3& p = cage.point(v);
      Vec3 force(0, 0, 0);
      int count = 0;
      for (const auto h : cage.voh_range(v)) {
        force += spring(p, cage.point(cage.to_vertex_handle(h)), rest);
        ++count;
        if (cage.is_boundary(h)) continue;
        // Diagonal of the quad left of h.
        const auto diag = cage.to_vertex_handle(cage.next_halfedge_handle(h));
        force += 0.5 * spring(p, cage.point(diag), std::sqrt(2.0) * rest);
      }
      const Vec3& n = projector.face_normal(face[v.idx()]);
      Vec3 d = count ? force / count : force;
      d -= OpenMesh::dot(d, n) * n;
      next[v.idx()] = p + options.step * d;
    }
    for (const auto v : cage.vertices()) {
      const ClosestPoint cp =
          projector.project(next[v.idx()], projector.face_normal(face[v.idx()]), radius);
      cage.set_point(v, cp.point);
      face[v.idx()] = cp.face;
    }
  }
  int folded = 0;
  for (const auto f : cage.faces()) {
    Vec3 quad_normal(0, 0, 0), surface_normal(0, 0, 0);
    for (const auto h : cage.fh_range(f)) {
      quad_normal += OpenMesh::cross(cage.point(cage.from_vertex_handle(h)),
                                     cage.point(cage.to_vertex_handle(h)));
      surface_normal += projector.face_normal(face[cage.to_vertex_handle(h).idx()]);
    }
    folded += OpenMesh::dot(quad_normal, surface_normal) <= 0;
  }
  return folded;
}

namespace {

// A closed quad mesh as a face list with vertex-face incidences, edited by diagonal collapses
// and edge rotations, with an undo journal (cancel_irregular_vertices).
class QuadEditor {
 public:
  // \p normals (per vertex, unit; may be empty): the surface normal at each vertex; when given,
  // every face an operation makes or changes must turn the normals' way at each corner, with
  // sin(corner angle) > min_sine.
  QuadEditor(const PolyMesh& quads, std::vector<Vec3> normals, double min_sine)
      : normal_(std::move(normals)), min_sine_(min_sine) {
    pos_.reserve(quads.n_vertices());
    for (const auto v : quads.vertices()) pos_.push_back(quads.point(v));
    vfaces_.resize(quads.n_vertices());
    for (const auto f : quads.faces()) {
      std::array<int, 4> q{};
      int k = 0;
      for (const auto v : quads.fv_range(f)) q[k++] = v.idx();
      face_.push_back(q);
      alive_.push_back(1);
      for (int v : q) vfaces_[v].push_back(f.idx());
    }
  }

  // An operation and how much it lowers Σ (valence − 4)².
  struct Op {
    int gain = std::numeric_limits<int>::min();
    bool collapse = false;
    int f = -1, g = -1;             // collapse: face f; rotation: the two faces
    int a = -1, c = -1;             // collapse: merged corners (c into a)
    std::array<int, 4> q1{}, q2{};  // rotation: the new faces
    bool valid() const { return f >= 0; }
  };

  int valence(int v) const { return static_cast<int>(vfaces_[v].size()); }
  static int cost(int valence) { return (valence - 4) * (valence - 4); }
  bool face_alive(int f) const { return alive_[f] != 0; }
  const std::array<int, 4>& face(int f) const { return face_[f]; }
  const std::vector<int>& faces_of(int v) const { return vfaces_[v]; }
  size_t num_faces() const { return face_.size(); }
  size_t num_vertices() const { return vfaces_.size(); }

  bool adjacent(int u, int v) const {
    for (int f : vfaces_[u]) {
      const auto& q = face_[f];
      const int k = index_in(q, u);
      if (q[(k + 1) % 4] == v || q[(k + 3) % 4] == v) return true;
    }
    return false;
  }

  void neighbours(int v, std::vector<int>& out) const {
    out.clear();
    for (int f : vfaces_[v]) {
      const auto& q = face_[f];
      const int k = index_in(q, v);
      out.push_back(q[(k + 1) % 4]);
      out.push_back(q[(k + 3) % 4]);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

  // Best diagonal collapse of face f.
  Op best_collapse(int f) const {
    Op best;
    const auto& q = face_[f];
    std::vector<int> na, nc, common;
    for (int k = 0; k < 2; ++k) {
      const int a = q[k], b = q[k + 1], c = q[(k + 2) % 4], d = q[(k + 3) % 4];
      const int va = valence(a), vb = valence(b), vc = valence(c), vd = valence(d);
      if (vb < 4 || vd < 4 || va + vc - 2 > kMaxValence) continue;
      neighbours(a, na);
      neighbours(c, nc);
      if (std::binary_search(na.begin(), na.end(), c)) continue;
      common.clear();
      std::set_intersection(na.begin(), na.end(), nc.begin(), nc.end(), std::back_inserter(common));
      if (common.size() != 2) continue;  // {b, d}; more would pinch the surface
      int shared = 0;
      for (int g : vfaces_[a]) shared += index_in(face_[g], c) >= 0;
      if (shared != 1) continue;
      const int gain = cost(va) + cost(vb) + cost(vc) + cost(vd) - cost(va + vc - 2) -
                       cost(vb - 1) - cost(vd - 1);
      if (gain > best.gain && !normal_.empty()) {
        // The faces around a and c with both at their midpoint.
        const Vec3 m = 0.5 * (pos_[a] + pos_[c]);
        Vec3 nm = normal_[a] + normal_[c];
        nm /= std::max(1e-12, nm.norm());
        bool ok = true;
        for (int w : {a, c}) {
          for (int g : vfaces_[w]) {
            if (g == f || !ok) continue;
            std::array<Vec3, 4> p, n;
            for (int i = 0; i < 4; ++i) {
              const int x = face_[g][i];
              p[i] = (x == a || x == c) ? m : pos_[x];
              n[i] = (x == a || x == c) ? nm : normal_[x];
            }
            ok = convex(p, n);
          }
        }
        if (!ok) continue;
      }
      if (gain > best.gain) {
        best.gain = gain;
        best.collapse = true;
        best.f = f;
        best.a = a;
        best.c = c;
      }
    }
    return best;
  }

  // Best rotation of the edge from q[k] to q[k + 1] of face f.
  Op best_rotation(int f, int k) const {
    Op best;
    const auto& q1 = face_[f];
    const int u = q1[k], v = q1[(k + 1) % 4], p = q1[(k + 2) % 4], pq = q1[(k + 3) % 4];
    if (valence(u) < 4 || valence(v) < 4) return best;
    int g = -1, k2 = -1;
    for (int h : vfaces_[v]) {
      const int i = index_in(face_[h], v);
      if (h != f && face_[h][(i + 1) % 4] == u) g = h, k2 = i;
    }
    if (g < 0) return best;
    const auto& q2 = face_[g];
    const int r = q2[(k2 + 2) % 4], s = q2[(k2 + 3) % 4];
    std::array<int, 6> six{u, v, p, pq, r, s};
    std::sort(six.begin(), six.end());
    if (std::adjacent_find(six.begin(), six.end()) != six.end()) return best;
    // The hexagon v, p, pq, u, r, s split along p–r or pq–s instead of u–v.
    const int x[2] = {p, pq}, y[2] = {r, s};
    for (int option = 0; option < 2; ++option) {
      if (valence(x[option]) + 1 > kMaxValence || valence(y[option]) + 1 > kMaxValence) continue;
      if (adjacent(x[option], y[option])) continue;
      if (!normal_.empty()) {
        const std::array<int, 4> n1 =
            option == 0 ? std::array<int, 4>{p, pq, u, r} : std::array<int, 4>{pq, u, r, s};
        const std::array<int, 4> n2 =
            option == 0 ? std::array<int, 4>{r, s, v, p} : std::array<int, 4>{s, v, p, pq};
        if (!convex_face(n1) || !convex_face(n2)) continue;
      }
      const int gain = cost(valence(u)) + cost(valence(v)) + cost(valence(x[option])) +
                       cost(valence(y[option])) - cost(valence(u) - 1) - cost(valence(v) - 1) -
                       cost(valence(x[option]) + 1) - cost(valence(y[option]) + 1);
      if (gain > best.gain) {
        best.gain = gain;
        best.collapse = false;
        best.f = f;
        best.g = g;
        if (option == 0) {
          best.q1 = {p, pq, u, r};
          best.q2 = {r, s, v, p};
        } else {
          best.q1 = {pq, u, r, s};
          best.q2 = {s, v, p, pq};
        }
      }
    }
    return best;
  }

  // Best operation on face f (its collapse or the rotation of one of its edges).
  Op best_at(int f) const {
    Op best = best_collapse(f);
    for (int k = 0; k < 4; ++k) {
      const Op r = best_rotation(f, k);
      if (r.gain > best.gain) best = r;
    }
    return best;
  }

  void apply(const Op& op) {
    if (op.collapse) {
      const std::array<int, 4> old = face_[op.f];
      set_face(op.f, old, false);
      set_position(op.a, 0.5 * (pos_[op.a] + pos_[op.c]));
      if (!normal_.empty()) {
        Vec3 nm = normal_[op.a] + normal_[op.c];
        normal_[op.a] = nm / std::max(1e-12, nm.norm());
      }
      const std::vector<int> around = vfaces_[op.c];
      for (int g : around) {
        std::array<int, 4> q = face_[g];
        for (int& v : q)
          if (v == op.c) v = op.a;
        set_face(g, q, true);
      }
    } else {
      set_face(op.f, op.q1, true);
      set_face(op.g, op.q2, true);
    }
  }

  // The journal position to undo back to.
  size_t mark() const { return journal_.size(); }
  void undo(size_t to) {
    while (journal_.size() > to) {
      const Entry e = journal_.back();
      journal_.pop_back();
      if (e.face >= 0) {
        replace(e.face, e.quad, e.alive);
      } else {
        pos_[e.vertex] = e.position;
        if (!normal_.empty()) normal_[e.vertex] = e.normal;
      }
    }
  }
  void forget() { journal_.clear(); }

  const Vec3& position(int v) const { return pos_[v]; }

 private:
  static constexpr int kMaxValence = 8;
  struct Entry {
    int face = -1;  // face entry, or -1 for a position entry
    std::array<int, 4> quad{};
    bool alive = false;
    int vertex = -1;
    Vec3 position{0, 0, 0}, normal{0, 0, 0};
  };

  // Every corner turns the way of the normal there, with sin(angle) > min_sine_.
  bool convex(const std::array<Vec3, 4>& p, const std::array<Vec3, 4>& n) const {
    for (int i = 0; i < 4; ++i) {
      const Vec3 e1 = p[(i + 1) % 4] - p[i], e2 = p[(i + 3) % 4] - p[i];
      if (OpenMesh::dot(OpenMesh::cross(e1, e2), n[i]) <= min_sine_ * e1.norm() * e2.norm())
        return false;
    }
    return true;
  }
  bool convex_face(const std::array<int, 4>& q) const {
    std::array<Vec3, 4> p, n;
    for (int i = 0; i < 4; ++i) p[i] = pos_[q[i]], n[i] = normal_[q[i]];
    return convex(p, n);
  }

  static int index_in(const std::array<int, 4>& q, int v) {
    for (int i = 0; i < 4; ++i)
      if (q[i] == v) return i;
    return -1;
  }

  void replace(int f, const std::array<int, 4>& q, bool alive) {
    if (alive_[f]) {
      for (int v : face_[f]) {
        auto& list = vfaces_[v];
        list.erase(std::find(list.begin(), list.end(), f));
      }
    }
    face_[f] = q;
    alive_[f] = alive;
    if (alive)
      for (int v : q) vfaces_[v].push_back(f);
  }
  void set_face(int f, const std::array<int, 4>& q, bool alive) {
    Entry e;
    e.face = f;
    e.quad = face_[f];
    e.alive = alive_[f] != 0;
    journal_.push_back(e);
    replace(f, q, alive);
  }
  void set_position(int v, const Vec3& p) {
    Entry e;
    e.vertex = v;
    e.position = pos_[v];
    if (!normal_.empty()) e.normal = normal_[v];
    journal_.push_back(e);
    pos_[v] = p;
  }

  std::vector<Vec3> pos_;
  std::vector<Vec3> normal_;
  double min_sine_ = 0;
  std::vector<std::array<int, 4>> face_;
  std::vector<char> alive_;
  std::vector<std::vector<int>> vfaces_;
  std::vector<Entry> journal_;
};

int count_irregular(const QuadEditor& ed) {
  int n = 0;
  for (size_t v = 0; v < ed.num_vertices(); ++v) {
    const int val = ed.valence(static_cast<int>(v));
    n += val > 0 && val != 4;
  }
  return n;
}

// Applies improving operations until there is none; returns how many.
int greedy_pass(QuadEditor& ed, int& collapses, int& rotations) {
  int applied = 0;
  for (bool changed = true; changed;) {
    changed = false;
    for (size_t f = 0; f < ed.num_faces(); ++f) {
      if (!ed.face_alive(static_cast<int>(f))) continue;
      const QuadEditor::Op op = ed.best_at(static_cast<int>(f));
      if (op.valid() && op.gain > 0) {
        ed.apply(op);
        ++(op.collapse ? collapses : rotations);
        ++applied;
        changed = true;
      }
    }
  }
  return applied;
}

// Faces within two rings of the given vertices.
std::vector<int> faces_near(const QuadEditor& ed, const std::vector<int>& vertices) {
  std::vector<int> ring, out;
  for (int v : vertices)
    for (int f : ed.faces_of(v))
      for (int w : ed.face(f)) ring.push_back(w);
  std::sort(ring.begin(), ring.end());
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  for (int v : ring)
    for (int f : ed.faces_of(v)) out.push_back(f);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// Tries neutral operations at the faces around \p vertices, each followed by the best
// operation near it when that one improves, else (depth > 1) by further neutral operations at
// the irregular vertices it touched. Keeps the first sequence that ends improving; undoes the
// rest.
bool look_ahead(QuadEditor& ed, const std::vector<int>& vertices, int depth,
                CageSimplifyStats& st) {
  std::vector<int> around;
  for (int v : vertices) around.insert(around.end(), ed.faces_of(v).begin(), ed.faces_of(v).end());
  std::sort(around.begin(), around.end());
  around.erase(std::unique(around.begin(), around.end()), around.end());
  std::vector<QuadEditor::Op> neutral;
  for (int f : around) {
    const QuadEditor::Op c = ed.best_collapse(f);
    if (c.valid() && c.gain == 0) neutral.push_back(c);
    for (int k = 0; k < 4; ++k) {
      const QuadEditor::Op r = ed.best_rotation(f, k);
      if (r.valid() && r.gain == 0) neutral.push_back(r);
    }
  }
  for (const QuadEditor::Op& op : neutral) {
    // Ops are found on the state before any of them; each is applied alone.
    const size_t m = ed.mark();
    std::vector<int> touched(ed.face(op.f).begin(), ed.face(op.f).end());
    if (!op.collapse) touched.insert(touched.end(), ed.face(op.g).begin(), ed.face(op.g).end());
    ed.apply(op);
    QuadEditor::Op best;
    for (int g : faces_near(ed, touched)) {
      if (!ed.face_alive(g)) continue;
      const QuadEditor::Op next = ed.best_at(g);
      if (next.gain > best.gain) best = next;
    }
    bool success = false;
    if (best.valid() && best.gain > 0) {
      ed.apply(best);
      ++(best.collapse ? st.collapses : st.rotations);
      success = true;
    } else if (depth > 1) {
      std::vector<int> irregular;
      for (int v : touched)
        if (ed.valence(v) != 0 && ed.valence(v) != 4) irregular.push_back(v);
      std::sort(irregular.begin(), irregular.end());
      irregular.erase(std::unique(irregular.begin(), irregular.end()), irregular.end());
      success = !irregular.empty() && look_ahead(ed, irregular, depth - 1, st);
    }
    if (success) {
      ++(op.collapse ? st.collapses : st.rotations);
      return true;
    }
    ed.undo(m);
  }
  return false;
}

}  // namespace

CageSimplifyStats cancel_irregular_vertices(PolyMesh& quads, const QuadSimplifyOptions& options,
                                            const std::vector<Vec3>* normals,
                                            std::vector<int>* kept_vertex) {
  CageSimplifyStats st;
  QuadEditor ed(quads, normals ? *normals : std::vector<Vec3>(), options.min_corner_sine);
  st.quads_before = static_cast<int>(quads.n_faces());
  st.irregular_before = count_irregular(ed);
  greedy_pass(ed, st.collapses, st.rotations);
  ed.forget();
  const int depth = std::max(1, options.depth);
  for (int round = 0; round < options.rounds; ++round) {
    int accepted = 0;
    for (size_t v0 = 0; v0 < ed.num_vertices(); ++v0) {
      const int val0 = ed.valence(static_cast<int>(v0));
      if (val0 == 0 || val0 == 4) continue;
      if (look_ahead(ed, {static_cast<int>(v0)}, depth, st)) ++accepted;
      ed.forget();
    }
    accepted += greedy_pass(ed, st.collapses, st.rotations);
    ed.forget();
    if (accepted == 0) break;
  }
  // Rebuild with the surviving vertices in their old order.
  std::vector<int> new_index(ed.num_vertices(), -1), kept;
  PolyMesh out;
  for (size_t v = 0; v < ed.num_vertices(); ++v) {
    if (ed.valence(static_cast<int>(v)) == 0) continue;
    new_index[v] = static_cast<int>(kept.size());
    kept.push_back(static_cast<int>(v));
    out.add_vertex(ed.position(static_cast<int>(v)));
  }
  for (size_t f = 0; f < ed.num_faces(); ++f) {
    if (!ed.face_alive(static_cast<int>(f))) continue;
    std::vector<VH> vs;
    for (int v : ed.face(static_cast<int>(f))) vs.emplace_back(new_index[v]);
    if (!out.add_face(vs).is_valid()) {
      // Not expected (the operations keep the mesh manifold): keep the input.
      st = CageSimplifyStats{};
      st.quads_before = st.quads_after = static_cast<int>(quads.n_faces());
      QuadEditor again(quads, {}, 0.0);
      st.irregular_before = st.irregular_after = count_irregular(again);
      if (kept_vertex) {
        kept_vertex->resize(quads.n_vertices());
        std::iota(kept_vertex->begin(), kept_vertex->end(), 0);
      }
      return st;
    }
  }
  quads = std::move(out);
  st.quads_after = static_cast<int>(quads.n_faces());
  st.irregular_after = count_irregular(ed);
  if (kept_vertex) *kept_vertex = std::move(kept);
  return st;
}

namespace {

// The patches of a quad complex on a quad mesh as a coarse quad mesh: one vertex per node (at
// its quad-mesh vertex), one face per patch. Returns false when that is not a manifold
// polygon mesh (a loop arc, two arcs joining the same nodes, a patch that is not 4-sided).
bool complex_to_mesh(const PolyMesh& quads, const QuadComplex& complex, PolyMesh& out) {
  out.clear();
  // Loop arcs and parallel arcs have no place in a polygon mesh (checked here rather than by
  // add_face, which reports on stderr).
  std::vector<std::pair<int, int>> ends;
  for (const auto& arc : complex.arcs) {
    if (arc.from == arc.to) return false;
    ends.emplace_back(std::min(arc.from, arc.to), std::max(arc.from, arc.to));
  }
  std::sort(ends.begin(), ends.end());
  if (std::adjacent_find(ends.begin(), ends.end()) != ends.end()) return false;
  const int n = static_cast<int>(complex.node_vertex.size());
  for (int v : complex.node_vertex) out.add_vertex(quads.point(VH(v)));
  // Position of each half-arc in its node's counter-clockwise list.
  const size_t n_half = 2 * complex.arcs.size();
  std::vector<int> node_of(n_half, -1), slot(n_half, -1);
  for (int node = 0; node < n; ++node) {
    const auto& list = complex.node_half_arcs[node];
    for (size_t i = 0; i < list.size(); ++i) {
      node_of[list[i]] = node;
      slot[list[i]] = static_cast<int>(i);
    }
  }
  for (size_t h = 0; h < n_half; ++h)
    if (node_of[h] < 0) return false;
  std::vector<char> used(n_half, 0);
  for (size_t h0 = 0; h0 < n_half; ++h0) {
    if (used[h0]) continue;
    std::vector<VH> corners;
    size_t h = h0;
    do {
      if (used[h] || corners.size() > 4) return false;
      used[h] = 1;
      corners.emplace_back(node_of[h]);
      // The face left of h continues at the other end with the half-arc clockwise before
      // h's reverse.
      const size_t back = h ^ 1;
      const auto& list = complex.node_half_arcs[node_of[back]];
      h = list[(slot[back] + list.size() - 1) % list.size()];
    } while (h != h0);
    if (corners.size() != 4 || !out.add_face(corners).is_valid()) return false;
  }
  return true;
}

// The complex of a coarse quad mesh split into a finer one (split_to_quads keeps the coarse
// vertices first, all new vertices have valence 4): every coarse vertex is a node, every coarse
// edge an arc (the straight chain of fine edges between its ends).
QuadComplex coarse_edge_complex(const PolyMesh& fine, int coarse_vertices, int coarse_faces) {
  QuadComplex qc;
  for (int v = 0; v < coarse_vertices; ++v) qc.node_vertex.push_back(v);
  qc.node_half_arcs.assign(coarse_vertices, {});
  std::vector<int> half_of(fine.n_halfedges(), -1);  // first fine halfedge -> half-arc
  for (int v = 0; v < coarse_vertices; ++v) {
    // Outgoing halfedges counter-clockwise.
    const auto start = fine.halfedge_handle(VH(v));
    auto h = start;
    do {
      if (half_of[h.idx()] < 0) {
        QuadComplex::Arc arc;
        arc.from = v;
        arc.path.push_back(v);
        auto g = h;
        while (true) {
          const int to = fine.to_vertex_handle(g).idx();
          arc.path.push_back(to);
          if (to < coarse_vertices) break;
          // Straight on through the valence-4 vertex: the opposite edge.
          const auto back = fine.opposite_halfedge_handle(g);
          auto next = fine.opposite_halfedge_handle(fine.prev_halfedge_handle(back));
          next = fine.opposite_halfedge_handle(fine.prev_halfedge_handle(next));
          g = next;
        }
        arc.to = arc.path.back();
        const int a = static_cast<int>(qc.arcs.size());
        half_of[h.idx()] = 2 * a;
        half_of[fine.opposite_halfedge_handle(g).idx()] = 2 * a + 1;
        qc.arcs.push_back(std::move(arc));
      }
      qc.node_half_arcs[v].push_back(half_of[h.idx()]);
      h = fine.opposite_halfedge_handle(fine.prev_halfedge_handle(h));
    } while (h != start);
    qc.valence.push_back(static_cast<int>(qc.node_half_arcs[v].size()));
    qc.irregular_vertices += qc.valence.back() != 4;
  }
  qc.num_patches = coarse_faces;
  return qc;
}

}  // namespace

namespace {

struct SimplifiedLayout {
  Layout layout;
  PolyMesh fine;        // the split coarse mesh on the surface
  QuadComplex complex;  // its coarse edges as arcs
  CageSimplifyStats stats;
};

// CageOptions::simplify: the complex on the fitted cage as a coarse quad mesh, its irregular
// vertices cancelled, split back down, smoothed on the surface and transferred.
// \throw InvalidInputError when the complex is no manifold mesh or the transfer fails.
SimplifiedLayout simplified_layout(const PolyMesh& cage, const QuadComplex& source,
                                   const TriMesh& mesh, const CageOptions& options) {
  PolyMesh coarse;
  if (!complex_to_mesh(cage, source, coarse))
    throw InvalidInputError("its patches do not form a manifold quad mesh");
  std::vector<Vec3> normals;
  for (int v : source.node_vertex) {
    const Vec3 n = cage_vertex_normal(cage, VH(v));
    normals.push_back(n / std::max(1e-12, n.norm()));
  }
  SimplifiedLayout out;
  out.stats = cancel_irregular_vertices(coarse, QuadSimplifyOptions{}, &normals);
  // Re-embedding alone only loses the cage's shape (its arcs become straight chains).
  if (out.stats.irregular_after == out.stats.irregular_before)
    throw InvalidInputError("no irregular node could be cancelled");
  // Merged nodes sit at midpoints: back onto the surface.
  CageFitOptions project = options.fit;
  project.presmoothing = 0;
  project.iterations = 0;
  fit_cage(coarse, mesh, project);
  const int nv = static_cast<int>(coarse.n_vertices());
  const int nf = static_cast<int>(coarse.n_faces());
  out.fine = coarse;
  for (int k = 0; k < std::max(0, options.simplify_splits); ++k) refine_fitted_cage(out.fine, mesh);
  relax_vertices(out.fine, mesh, std::max(0, options.simplify_relaxation));
  const int folded = fit_cage(out.fine, mesh, project);
  out.complex = coarse_edge_complex(out.fine, nv, nf);
  try {
    out.layout = transfer_complex(out.fine, out.complex, mesh, options.transfer);
  } catch (const InvalidInputError& e) {
    std::string why = e.what();
    why = why.substr(0, why.find("; --coarsen"));
    throw InvalidInputError(std::to_string(out.stats.irregular_before) + " -> " +
                            std::to_string(out.stats.irregular_after) + " irregular nodes, " +
                            std::to_string(nf) + " patches, " + std::to_string(folded) +
                            " folded; transfer failed: " + why);
  }
  return out;
}

}  // namespace

CageResult cage_layout(const TriMesh& mesh, const CageOptions& options) {
  MeshReport mesh_report;
  count_topology(mesh, mesh_report);
  if (mesh_report.components != 1 || mesh_report.boundary_loops != 0) {
    throw InvalidInputError(
        "a cage layout needs a closed surface with one component (the mesh has " +
        std::to_string(mesh_report.components) + " component(s) and " +
        std::to_string(mesh_report.boundary_loops) + " boundary loop(s))");
  }
  CageResult result;
  std::vector<std::string> failures;
  BaseComplexOptions bc;
  bc.all_edges = options.all_edges;
  for (int attempt = 0; attempt < std::max(1, options.attempts); ++attempt) {
    const int resolution = options.resolution + attempt / 2;
    double shift = options.shift + (attempt % 2 ? 0.5 : 0.0);
    shift -= std::floor(shift);
    if (resolution > 200) break;
    char shift_text[32] = "";
    if (shift != 0) std::snprintf(shift_text, sizeof shift_text, " (shifted %.3g)", shift);
    const std::string name = "resolution " + std::to_string(resolution) + shift_text;
    PolyMesh cage;
    try {
      cage = voxel_cage(mesh, resolution, &result.voxels, shift, options.subsamples);
    } catch (const InvalidInputError& e) {
      failures.push_back(e.what());
      continue;
    }
    if (result.voxels.components != 1 || result.voxels.genus != mesh_report.genus) {
      failures.push_back(name + ": the voxel surface has " +
                         std::to_string(result.voxels.components) +
                         " component(s) of total genus " + std::to_string(result.voxels.genus) +
                         ", the mesh has genus " + std::to_string(mesh_report.genus));
      continue;
    }
    const int folded = fit_cage(cage, mesh, options.fit);
    int chosen = -1, refined = 0;
    bool simplified = false;
    QuadComplex complex;
    CoarsenStats stats;
    // Splitting adds arcs in all-edges mode (one patch per quad), so it is for complexes only.
    const int max_refine = options.all_edges ? 0 : std::max(0, options.max_refine);
    for (; refined <= max_refine && chosen < 0; ++refined) {
      if (refined > 0) refine_fitted_cage(cage, mesh);
      const std::string level = refined ? " (split " + std::to_string(refined) + "x)" : "";
      const QuadComplex full = base_complex(cage, bc);
      // The coarsened complex first (when asked for), then the cage's full complex.
      std::vector<std::pair<QuadComplex, CoarsenStats>> candidates;
      if (options.coarsen > 0 && !options.all_edges) {
        CoarsenOptions co;
        co.max_width = options.coarsen * result.voxels.grid.h;
        CoarsenStats coarse_stats;
        QuadComplex coarse = coarsen_complex(cage, full, co, &coarse_stats);
        if (options.simplify && refined == 0 && !simplified) {
          simplified = true;
          try {
            SimplifiedLayout sl = simplified_layout(
                cage, coarse_stats.chords_collapsed > 0 ? coarse : full, mesh, options);
            result.layout = std::move(sl.layout);
            result.simplify = sl.stats;
            result.simplified = true;
            complex = std::move(sl.complex);
            stats = coarse_stats;
            stats.nodes_after = static_cast<int>(complex.node_vertex.size());
            stats.arcs_after = static_cast<int>(complex.arcs.size());
            stats.patches_after = complex.num_patches;
            cage = std::move(sl.fine);
            chosen = 0;
          } catch (const InvalidInputError& e) {
            failures.push_back(name + ": simplified layout: " + e.what());
          }
        }
        if (coarse_stats.chords_collapsed > 0)
          candidates.emplace_back(std::move(coarse), coarse_stats);
      }
      CoarsenStats plain;
      plain.nodes_before = plain.nodes_after = static_cast<int>(full.node_vertex.size());
      plain.arcs_before = plain.arcs_after = static_cast<int>(full.arcs.size());
      plain.patches_before = plain.patches_after = full.num_patches;
      candidates.emplace_back(full, plain);
      for (size_t k = 0; k < candidates.size() && chosen < 0; ++k) {
        try {
          result.layout = transfer_complex(cage, candidates[k].first, mesh, options.transfer);
          chosen = static_cast<int>(k);
          complex = std::move(candidates[k].first);
          stats = candidates[k].second;
        } catch (const InvalidInputError& e) {
          // import-quads' hint about its --coarsen option does not apply here.
          std::string why = e.what();
          why = why.substr(0, why.find("; --coarsen"));
          failures.push_back(name + ": " + std::to_string(cage.n_faces()) + " cage quads" + level +
                             ", " + std::to_string(candidates[k].first.num_patches) + " patches" +
                             (candidates[k].second.chords_collapsed ? " (coarsened)" : "") + ", " +
                             std::to_string(folded) + " folded; transfer failed: " + why);
        }
      }
    }
    if (chosen < 0) continue;
    result.resolution = resolution;
    result.shift = shift;
    result.refined = refined - 1;
    result.folded_quads = folded;
    result.complex = std::move(complex);
    result.coarsen = stats;
    result.layout.mesh_vertices = static_cast<int>(mesh.n_vertices());
    result.layout.mesh_faces = static_cast<int>(mesh.n_faces());
    for (const auto& f : failures) result.warnings.push_back("skipped " + f);
    if (folded > 0) {
      result.warnings.push_back(
          std::to_string(folded) +
          " cage quad(s) were folded after fitting (the transferred layout still "
          "validated)");
    }
    result.cage = std::move(cage);
    return result;
  }
  std::string msg = "no voxel cage gave a valid layout on this mesh (genus " +
                    std::to_string(mesh_report.genus) + ", " + std::to_string(mesh.n_faces()) +
                    " faces); thin parts or narrow gaps need a finer resolution, dense cages "
                    "a finer mesh:";
  for (const auto& f : failures) msg += "\n  " + f.substr(0, 400);
  throw InvalidInputError(msg);
}

}  // namespace qs
