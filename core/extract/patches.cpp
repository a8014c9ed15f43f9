#include "core/extract/patches.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include "core/param/cut_graph.h"

namespace qs {

namespace {

using V2 = std::array<double, 2>;
using Tri2 = std::array<V2, 3>;

V2 sub(const V2& a, const V2& b) {
  return {a[0] - b[0], a[1] - b[1]};
}
V2 add(const V2& a, const V2& b) {
  return {a[0] + b[0], a[1] + b[1]};
}
double dot(const V2& a, const V2& b) {
  return a[0] * b[0] + a[1] * b[1];
}
double cross(const V2& a, const V2& b) {
  return a[0] * b[1] - a[1] * b[0];
}

// Does triangle t overlap the open box (lo, hi) with positive area? Separating axis test on the
// box axes and the triangle's edge normals; touching counts as separated.
bool overlaps_box(const Tri2& t, const V2& lo, const V2& hi) {
  for (int axis = 0; axis < 2; ++axis) {
    const double mn = std::min({t[0][axis], t[1][axis], t[2][axis]});
    const double mx = std::max({t[0][axis], t[1][axis], t[2][axis]});
    if (mx <= lo[axis] || mn >= hi[axis]) return false;
  }
  const V2 box[4] = {lo, {hi[0], lo[1]}, hi, {lo[0], hi[1]}};
  for (int k = 0; k < 3; ++k) {
    const V2& a = t[k];
    const V2& b = t[(k + 1) % 3];
    const V2 n{a[1] - b[1], b[0] - a[0]};
    const double pa = dot(n, a), pc = dot(n, t[(k + 2) % 3]);
    const double tmin = std::min(pa, pc), tmax = std::max(pa, pc);
    double bmin = std::numeric_limits<double>::infinity(), bmax = -bmin;
    for (const V2& c : box) {
      const double p = dot(n, c);
      bmin = std::min(bmin, p);
      bmax = std::max(bmax, p);
    }
    if (bmax <= tmin || bmin >= tmax) return false;
  }
  return true;
}

// Barycentric coordinates of p in triangle t; false for a degenerate or inverted triangle.
bool barycentric(const Tri2& t, const V2& p, std::array<double, 3>& b) {
  const double a2 = cross(sub(t[1], t[0]), sub(t[2], t[0]));
  if (!(a2 > 0)) return false;
  b[1] = cross(sub(p, t[0]), sub(t[2], t[0])) / a2;
  b[2] = cross(sub(t[1], t[0]), sub(p, t[0])) / a2;
  b[0] = 1 - b[1] - b[2];
  return true;
}

// Quarter turns q with R^q(1,0) closest to direction d.
int quarter_of(const V2& d) {
  const int q = static_cast<int>(std::lround(std::atan2(d[1], d[0]) / (M_PI / 2)));
  return ((q % 4) + 4) % 4;
}

}  // namespace

bool is_quad_patch(const LayoutTopology::Patch& p) {
  return p.darts.size() == 4 && p.corners.size() == 4 && !p.trimmed && p.euler == 1 &&
         p.border_cycles == 1;
}

Vec3 surface_position(const TriMesh& mesh, const GeometryCache& g, const SurfacePoint& sp) {
  const auto& fv = g.face_vertices[sp.face];
  return sp.bary[0] * mesh.point(mesh.vertex_handle(fv[0])) +
         sp.bary[1] * mesh.point(mesh.vertex_handle(fv[1])) +
         sp.bary[2] * mesh.point(mesh.vertex_handle(fv[2]));
}

PatchChart build_patch_chart(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                             const LayoutTopology& topo, const Extraction& ex,
                             const std::vector<int>& period_jump, const std::vector<V2>& uv,
                             int patch, const PatchChartOptions& opt) {
  PatchChart chart;
  chart.patch = patch;
  chart.locate_tolerance = opt.locate_tolerance;
  const auto& P = topo.patches[patch];
  auto fail = [&](std::string why) {
    chart.ok = false;
    chart.failure = std::move(why);
    return chart;
  };
  if (!is_quad_patch(P)) {
    if (P.trimmed) return fail("trimmed patch (part of its border is bare mesh boundary)");
    return fail("not a 4-sided disk patch (" + std::to_string(P.darts.size()) + " sides)");
  }
  for (int d : P.darts)
    if (!ex.arcs[d >> 1].ok)
      return fail("arc " + std::to_string(layout.arcs[d >> 1].id) +
                  " of its border failed to trace");
  const auto len = [&](int k) { return ex.arcs[P.darts[k] >> 1].param_length; };
  chart.w = 0.5 * (len(0) + len(2));
  chart.h = 0.5 * (len(1) + len(3));
  if (!(chart.w > 0 && chart.h > 0)) return fail("zero parametric size");
  const double scale = std::max(chart.w, chart.h);

  // Seed: the face holding the end of dart 0's arc at corner 0, with the dart's direction.
  const int d0 = P.darts[0];
  const TracedArc& t0 = ex.arcs[d0 >> 1];
  if (t0.samples.size() < 2) return fail("arc with fewer than 2 samples");
  const bool fwd = (d0 & 1) == 0;
  const size_t i0 = fwd ? 0 : t0.samples.size() - 1, i1 = fwd ? 1 : t0.samples.size() - 2;
  const int seed = t0.samples[i0].face;
  const V2 origin = t0.uv[i0];
  const V2 dir = sub(uv_in_face(mesh, g, uv, t0.samples[i1], seed), origin);
  if (std::hypot(dir[0], dir[1]) <= 1e-14 * scale) return fail("degenerate first arc segment");
  const int q0 = (4 - quarter_of(dir)) % 4;

  struct Instance {
    int face;
    int q;
    Tri2 st;
  };
  std::vector<Instance> inst;
  std::vector<std::vector<int>> face_inst(g.n_faces);
  std::deque<int> queue;
  const double eps = opt.overlap_margin * scale;
  const V2 lo{eps, eps}, hi{chart.w - eps, chart.h - eps};
  const double same_tol = 1e-6 * scale;
  auto find_same = [&](int f, const Tri2& st) {
    for (int i : face_inst[f]) {
      double d = 0;
      for (int k = 0; k < 3; ++k)
        d = std::max(d, std::hypot(inst[i].st[k][0] - st[k][0], inst[i].st[k][1] - st[k][1]));
      if (d <= same_tol) return true;
    }
    return false;
  };
  {
    Instance s{seed, q0, {}};
    for (int k = 0; k < 3; ++k) s.st[k] = rotate(q0, sub(uv[3 * seed + k], origin));
    face_inst[seed].push_back(0);
    inst.push_back(s);
    queue.push_back(0);
  }
  const size_t cap = 8 * static_cast<size_t>(g.n_faces) + 64;
  while (!queue.empty()) {
    const Instance cur = inst[queue.front()];
    queue.pop_front();
    const auto fh = mesh.face_handle(cur.face);
    for (auto h : mesh.fh_range(fh)) {
      const auto opp = mesh.opposite_halfedge_handle(h);
      if (mesh.is_boundary(opp)) continue;
      const int j = mesh.face_handle(opp).idx();
      const int w = mesh.from_vertex_handle(h).idx(), z = mesh.to_vertex_handle(h).idx();
      const int r = step_rotation(period_jump[mesh.edge_handle(h).idx()], w, z);
      Instance next{j, ((cur.q - r) % 4 + 4) % 4, {}};
      const V2 base = cur.st[corner_of(g, cur.face, w)];
      const V2 xw = uv[3 * j + corner_of(g, j, w)];
      for (int k = 0; k < 3; ++k) next.st[k] = add(base, rotate(next.q, sub(uv[3 * j + k], xw)));
      if (!overlaps_box(next.st, lo, hi) || find_same(j, next.st)) continue;
      face_inst[j].push_back(static_cast<int>(inst.size()));
      queue.push_back(static_cast<int>(inst.size()));
      inst.push_back(next);
      if (inst.size() > cap) return fail("chart does not close (runaway BFS)");
    }
  }
  for (const Instance& i : inst)
    if (overlaps_box(i.st, lo, hi)) chart.triangles.push_back({i.face, i.st});
  if (chart.triangles.empty()) return fail("no face overlaps the patch rectangle");

  // Check: every corner node sits on its rectangle corner.
  const V2 expect[4] = {{0, 0}, {chart.w, 0}, {chart.w, chart.h}, {0, chart.h}};
  for (int k = 0; k < 4; ++k) {
    const int v = layout.nodes[P.corners[k]].vertex;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : chart.triangles) {
      const auto& fv = g.face_vertices[t.face];
      for (int c = 0; c < 3; ++c)
        if (fv[c] == v)
          best = std::min(best, std::hypot(t.st[c][0] - expect[k][0], t.st[c][1] - expect[k][1]));
    }
    chart.corner_error = std::max(chart.corner_error, best);
  }
  if (!(chart.corner_error <= opt.corner_tolerance * scale))
    return fail("corner nodes do not map to the rectangle corners (error " +
                std::to_string(chart.corner_error / scale) + " of the patch size)");
  chart.build_bins();
  chart.ok = true;
  return chart;
}

void PatchChart::build_bins() {
  const int n = static_cast<int>(triangles.size());
  const int b = std::clamp(static_cast<int>(std::sqrt(static_cast<double>(n))), 1, 512);
  bins_x_ = bins_y_ = b;
  auto range = [&](double lo_v, double hi_v, double extent, int bins, int& i0, int& i1) {
    i0 = std::clamp(static_cast<int>(std::floor(lo_v / extent * bins)), 0, bins - 1);
    i1 = std::clamp(static_cast<int>(std::floor(hi_v / extent * bins)), 0, bins - 1);
  };
  std::vector<int> count(bins_x_ * bins_y_ + 1, 0);
  auto for_bins = [&](const PatchChartTriangle& t, auto&& fn) {
    int x0, x1, y0, y1;
    range(std::min({t.st[0][0], t.st[1][0], t.st[2][0]}),
          std::max({t.st[0][0], t.st[1][0], t.st[2][0]}), w, bins_x_, x0, x1);
    range(std::min({t.st[0][1], t.st[1][1], t.st[2][1]}),
          std::max({t.st[0][1], t.st[1][1], t.st[2][1]}), h, bins_y_, y0, y1);
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) fn(y * bins_x_ + x);
  };
  for (const auto& t : triangles) for_bins(t, [&](int bin) { ++count[bin + 1]; });
  for (size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
  bin_start_ = count;
  bin_items_.assign(count.back(), -1);
  std::vector<int> fill(count.begin(), count.end() - 1);
  for (int i = 0; i < n; ++i) for_bins(triangles[i], [&](int bin) { bin_items_[fill[bin]++] = i; });
}

bool PatchChart::locate(const V2& st, SurfacePoint& out) const {
  if (bins_x_ == 0) return false;
  const int x = std::clamp(static_cast<int>(std::floor(st[0] / w * bins_x_)), 0, bins_x_ - 1);
  const int y = std::clamp(static_cast<int>(std::floor(st[1] / h * bins_y_)), 0, bins_y_ - 1);
  const int bin = y * bins_x_ + x;
  double best = -std::numeric_limits<double>::infinity();
  for (int k = bin_start_[bin]; k < bin_start_[bin + 1]; ++k) {
    const auto& t = triangles[bin_items_[k]];
    std::array<double, 3> b;
    if (!barycentric(t.st, st, b)) continue;
    const double score = std::min({b[0], b[1], b[2]});
    if (score > best) {
      best = score;
      out.face = t.face;
      out.bary = b;
    }
  }
  if (!(best >= -locate_tolerance)) return false;
  // Clamp round-off so the point is exactly on the face.
  double sum = 0;
  for (double& c : out.bary) sum += (c = std::max(c, 0.0));
  for (double& c : out.bary) c /= sum;
  return true;
}

}  // namespace qs
