#include "core/param/labeling.h"

#include <cmath>
#include <deque>

#include "core/base/errors.h"
#include "core/param/cut_graph.h"

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;

int mod4(int x) {
  return ((x % 4) + 4) % 4;
}

// Left strip of a vertex path; false if it would run through the exterior.
bool left_strip(const TriMesh& mesh, const std::vector<int>& walk, ArcStrip& s) {
  s.walk = walk;
  s.steps.clear();
  s.arrival.assign(walk.size(), 0);
  const HH first = mesh.find_halfedge(mesh.vertex_handle(walk[0]), mesh.vertex_handle(walk[1]));
  if (mesh.is_boundary(first)) return false;
  HH h_in = first;  // walk[k − 1] → walk[k]
  for (size_t k = 1; k + 1 < walk.size(); ++k) {
    s.arrival[k] = static_cast<int>(s.steps.size());
    const HH h_out =
        mesh.find_halfedge(mesh.vertex_handle(walk[k]), mesh.vertex_handle(walk[k + 1]));
    if (mesh.is_boundary(h_out)) return false;
    HH o = mesh.next_halfedge_handle(h_in);
    int guard = 0;
    while (o != h_out) {
      const HH opp = mesh.opposite_halfedge_handle(o);
      if (mesh.is_boundary(opp) || ++guard > 1000) return false;
      s.steps.push_back(o);
      o = mesh.next_halfedge_handle(opp);
    }
    h_in = h_out;
  }
  s.arrival.back() = static_cast<int>(s.steps.size());
  return true;
}

}  // namespace

Labeling label_layout(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                      const LayoutTopology& topo, const std::vector<int>& p,
                      const std::vector<double>& theta) {
  const int na = topo.num_arcs;
  Labeling L;
  L.strips.resize(na);
  L.chart_face.assign(2 * na, -1);
  L.chart_halfedge.assign(2 * na, HH());
  L.symbol.assign(2 * na, -1);
  L.iso_u.assign(na, 0);
  auto rot_of = [&](HH s) {
    const int e = mesh.edge_handle(s).idx();
    return step_rotation(p[e], mesh.from_vertex_handle(s).idx(), mesh.to_vertex_handle(s).idx());
  };
  for (int a = 0; a < na; ++a) {
    const auto& path = layout.arcs[a].path;
    ArcStrip& s = L.strips[a];
    if (!left_strip(mesh, path, s)) {
      std::vector<int> rev(path.rbegin(), path.rend());
      if (!left_strip(mesh, rev, s))
        throw TopologyError("arc " + std::to_string(layout.arcs[a].id) +
                            " touches the mesh boundary on both sides; it cannot be embedded");
      s.reversed = true;
    }
    s.rotation = 0;
    for (HH st : s.steps) s.rotation = mod4(s.rotation + rot_of(st));
    const auto& w = s.walk;
    const size_t k = w.size() - 1;
    const HH start = mesh.find_halfedge(mesh.vertex_handle(w[0]), mesh.vertex_handle(w[1]));
    // End chart: face(w[k-1]→w[k]); its outgoing halfedge at w[k] is next(w[k-1]→w[k]).
    const HH end = mesh.next_halfedge_handle(
        mesh.find_halfedge(mesh.vertex_handle(w[k - 1]), mesh.vertex_handle(w[k])));
    const int h_start = s.reversed ? 2 * a + 1 : 2 * a;
    const int h_end = s.reversed ? 2 * a : 2 * a + 1;
    L.chart_halfedge[h_start] = start;
    L.chart_face[h_start] = mesh.face_handle(start).idx();
    L.chart_halfedge[h_end] = end;
    L.chart_face[h_end] = mesh.face_handle(end).idx();
  }

  // Symbol of half-arc h in its chart from the geometry: its first edge against the field.
  auto geometric_angle = [&](int h) {
    const HH first = topo.half_first[h];
    const Vec3 d =
        mesh.point(mesh.to_vertex_handle(first)) - mesh.point(mesh.from_vertex_handle(first));
    const int f = L.chart_face[h];
    return g.angle_in_face(f, d) - theta[f];
  };
  // σ relation: symbol change from h to σ(h).
  auto sigma_delta = [&](int h) {
    const int a = h >> 1;
    const ArcStrip& s = L.strips[a];
    const int walk_start = s.reversed ? 2 * a + 1 : 2 * a;
    // d(walk end) = d(walk start) + r + 2.
    return h == walk_start ? s.rotation + 2 : -s.rotation + 2;
  };
  // θ relation: d(θ(h)) = d(h) − 1 + r(τ_θ), τ_θ clockwise around the node.
  auto theta_delta = [&](int h, int t) {
    HH o = L.chart_halfedge[h];
    const HH target = L.chart_halfedge[t];
    int r = 0, guard = 0;
    while (o != target) {
      r += rot_of(o);
      const HH opp = mesh.opposite_halfedge_handle(o);
      if (mesh.is_boundary(opp) || ++guard > 1000)
        throw QsError("internal error: rotation around node vertex " +
                      std::to_string(mesh.from_vertex_handle(o).idx()) + " left the surface");
      o = mesh.next_halfedge_handle(opp);
    }
    return r - 1;
  };

  // Propagate from half-arc 0 with symbol 0; the global choice is made afterwards.
  std::vector<int> rel(2 * na, -1);
  rel[0] = 0;
  std::deque<int> queue{0};
  auto visit = [&](int from, int to, int delta) {
    const int value = mod4(rel[from] + delta);
    if (rel[to] < 0) {
      rel[to] = value;
      queue.push_back(to);
    } else if (rel[to] != value) {
      throw TopologyError("inconsistent u/v labelling at arc " +
                          std::to_string(layout.arcs[to >> 1].id) +
                          ": the layout's rotation system contradicts the cross-field topology");
    }
  };
  // Inverse θ for the backwards step.
  std::vector<int> theta_inv(2 * na, -1);
  for (int h = 0; h < 2 * na; ++h)
    if (topo.theta[h] >= 0) theta_inv[topo.theta[h]] = h;
  while (!queue.empty()) {
    const int h = queue.front();
    queue.pop_front();
    visit(h, h ^ 1, sigma_delta(h));
    if (topo.half_node[h] < 0) continue;  // dangling end
    if (topo.theta[h] >= 0 && topo.theta[h] != h)
      visit(h, topo.theta[h], theta_delta(h, topo.theta[h]));
    if (theta_inv[h] >= 0 && theta_inv[h] != h)
      visit(h, theta_inv[h], -theta_delta(theta_inv[h], h));
  }
  for (int h = 0; h < 2 * na; ++h)
    if (rel[h] < 0)
      throw QsError("internal error: half-arc " + std::to_string(h) + " not reached by labelling");

  // Global choice: the offset that best matches the geometry of all half-arcs.
  std::vector<double> angle(2 * na);
  for (int h = 0; h < 2 * na; ++h) angle[h] = geometric_angle(h);
  int best = 0;
  double best_score = -1e300;
  for (int d0 = 0; d0 < 4; ++d0) {
    double score = 0;
    for (int h = 0; h < 2 * na; ++h) score += std::cos(angle[h] - (rel[h] + d0) * M_PI / 2);
    if (score > best_score) best_score = score, best = d0;
  }
  for (int h = 0; h < 2 * na; ++h) {
    L.symbol[h] = mod4(rel[h] + best);
    const int geometric = mod4(static_cast<int>(std::lround(angle[h] / (M_PI / 2))));
    L.geometric_mismatches += geometric != L.symbol[h];
  }
  for (int a = 0; a < na; ++a) L.iso_u[a] = L.symbol[2 * a] % 2 == 1;
  return L;
}

}  // namespace qs
