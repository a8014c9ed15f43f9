#include "core/field/topology.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <map>
#include <numeric>
#include <sstream>

#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"

namespace qs {

namespace {

// Sign of the ccw step around v across edge e = {v, b}: +1 iff it runs along the dual edge's
// canonical orientation, i.e. iff b < v (docs/design.md, "Field topology").
int ccw_sign(const GeometryCache& g, int e, int v) {
  const auto [a, b] = g.edge_vertices[e];
  const int other = (a == v) ? b : a;
  return other < v ? +1 : -1;
}

bool interior_edge(const GeometryCache& g, int e) {
  return g.edge_face_i[e] >= 0 && g.edge_face_j[e] >= 0;
}

// 4·I_0(v) = 4·round((Ω − Σ_ccw κ)/2π) for interior vertices.
std::vector<int> base_quarter_indices(const TriMesh& mesh, const GeometryCache& g) {
  std::vector<double> sum(g.n_vertices, 0.0);
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior_edge(g, e)) continue;
    const auto [a, b] = g.edge_vertices[e];
    sum[a] += ccw_sign(g, e, a) * g.kappa[e];
    sum[b] += ccw_sign(g, e, b) * g.kappa[e];
  }
  std::vector<int> i0(g.n_vertices, 0);
  for (auto v : mesh.vertices()) {
    if (g.vertex_on_boundary[v.idx()]) continue;
    i0[v.idx()] =
        4 * static_cast<int>(std::lround((g.angle_defect[v.idx()] - sum[v.idx()]) / (2 * M_PI)));
  }
  return i0;
}

std::string arc_list(const Layout& layout, const std::vector<std::pair<int, bool>>& cycle) {
  std::ostringstream ss;
  for (size_t i = 0; i < cycle.size(); ++i) ss << (i ? ", " : "") << layout.arcs[cycle[i].first].id;
  return ss.str();
}

// Affine integer functions c + Σ_k coef_k g_k of the free unknowns g, one per row, stored flat
// (row r's coefficients at coef[r·n, (r+1)·n)): no allocation per edge or vertex.
struct AffineRows {
  int n = 0;  // free unknowns
  std::vector<long> c, coef;
  AffineRows(size_t rows, int nfree) : n(nfree), c(rows, 0), coef(rows * nfree, 0) {}
  long* row(size_t r) { return coef.data() + r * n; }
  const long* row(size_t r) const { return coef.data() + r * n; }
  //! this[r] += s · other[q]
  void add(size_t r, long s, const AffineRows& other, size_t q) {
    c[r] += s * other.c[q];
    long* a = row(r);
    const long* b = other.row(q);
    for (int k = 0; k < n; ++k) a[k] += s * b[k];
  }
};

}  // namespace

std::vector<int> target_quarter_indices(const TriMesh& mesh, const Layout& layout,
                                        const LayoutTopology& topology) {
  std::vector<int> t(mesh.n_vertices(), 0);
  for (int n = 0; n < topology.num_nodes; ++n) {
    const int v = layout.nodes[n].vertex;
    if (!mesh.is_boundary(mesh.vertex_handle(v))) t[v] = 4 - topology.valence[n];
  }
  return t;
}

std::vector<int> quarter_indices_from_jumps(const GeometryCache& g, const std::vector<int>& p) {
  std::vector<double> sum(g.n_vertices, 0.0);
  std::vector<long> psum(g.n_vertices, 0);
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior_edge(g, e)) continue;
    for (int v : g.edge_vertices[e]) {
      sum[v] += ccw_sign(g, e, v) * g.kappa[e];
      psum[v] += ccw_sign(g, e, v) * p[e];
    }
  }
  std::vector<int> idx(g.n_vertices, 0);
  for (int v = 0; v < g.n_vertices; ++v) {
    if (g.vertex_on_boundary[v]) continue;
    const long i0 = 4 * std::lround((g.angle_defect[v] - sum[v]) / (2 * M_PI));
    idx[v] = static_cast<int>(i0 - psum[v]);
  }
  return idx;
}

std::vector<std::vector<std::pair<int, bool>>> layout_fundamental_cycles(
    const Layout& layout, const LayoutTopology& topo) {
  const int n = topo.num_nodes;
  std::vector<std::vector<std::pair<int, int>>> adj(n);  // (arc, neighbour)
  for (int a = 0; a < topo.num_arcs; ++a) {
    if (layout.arcs[a].dangling()) continue;
    const int u = topo.half_node[2 * a], v = topo.half_node[2 * a + 1];
    adj[u].push_back({a, v});
    if (u != v) adj[v].push_back({a, u});
  }
  std::vector<int> parent_arc(n, -1), depth(n, -1), parent(n, -1);
  std::vector<char> tree_arc(topo.num_arcs, 0);
  for (int root = 0; root < n; ++root) {
    if (depth[root] >= 0) continue;
    depth[root] = 0;
    std::deque<int> queue{root};
    while (!queue.empty()) {
      const int u = queue.front();
      queue.pop_front();
      for (auto [a, v] : adj[u]) {
        if (depth[v] >= 0) continue;
        depth[v] = depth[u] + 1;
        parent[v] = u;
        parent_arc[v] = a;
        tree_arc[a] = 1;
        queue.push_back(v);
      }
    }
  }
  std::vector<std::vector<std::pair<int, bool>>> cycles;
  for (int a = 0; a < topo.num_arcs; ++a) {
    if (tree_arc[a] || layout.arcs[a].dangling()) continue;
    const int u = topo.half_node[2 * a], v = topo.half_node[2 * a + 1];
    // Cycle: u → v along a, then v up to the common ancestor, then down to u.
    std::vector<std::pair<int, bool>> up_from_v, up_from_u;
    int x = v, y = u;
    while (depth[x] > depth[y])
      up_from_v.push_back({parent_arc[x], topo.half_node[2 * parent_arc[x]] == x}), x = parent[x];
    while (depth[y] > depth[x])
      up_from_u.push_back({parent_arc[y], topo.half_node[2 * parent_arc[y]] == y}), y = parent[y];
    while (x != y) {
      up_from_v.push_back({parent_arc[x], topo.half_node[2 * parent_arc[x]] == x});
      x = parent[x];
      up_from_u.push_back({parent_arc[y], topo.half_node[2 * parent_arc[y]] == y});
      y = parent[y];
    }
    std::vector<std::pair<int, bool>> cycle{{a, true}};
    cycle.insert(cycle.end(), up_from_v.begin(), up_from_v.end());
    for (auto it = up_from_u.rbegin(); it != up_from_u.rend(); ++it)
      cycle.push_back({it->first, !it->second});
    cycles.push_back(std::move(cycle));
  }
  return cycles;
}

namespace {

// One layout cycle turned into an equation Σ_Γ sign·p_e = rhs (docs/design.md, "Field topology").
struct CycleEquation {
  std::vector<std::pair<int, int>> terms;  // (edge, sign)
  long rhs = 0;
  bool ok = false;
};

// The left face strip Γ of a path at its vertex w, entered by u→w and left by w→y: calls
// term(edge, sign) for every edge {w,z} crossed clockwise around w from the face holding u→w
// to the face holding w→y, and adds that edge's signed κ and π − β_w (β_w: the visited corner
// angles at w) to the sums. False when the strip runs through the exterior.
template <class Term>
bool left_strip_at(const TriMesh& mesh, const GeometryCache& g, int u_idx, int w_idx, int y_idx,
                   double& kappa_sum, double& angle_term, Term&& term) {
  const auto u = mesh.vertex_handle(u_idx);
  const auto w = mesh.vertex_handle(w_idx);
  const auto y = mesh.vertex_handle(y_idx);
  const auto h_in = mesh.find_halfedge(u, w);
  const auto h_out = mesh.find_halfedge(w, y);
  if (mesh.is_boundary(h_in) || mesh.is_boundary(h_out)) return false;  // exterior on the left
  auto corner = [&](OpenMesh::HalfedgeHandle out) {
    const int f = mesh.face_handle(out).idx();
    const auto& fv = g.face_vertices[f];
    const int c = fv[0] == w_idx ? 0 : (fv[1] == w_idx ? 1 : 2);
    return g.corner_angle[3 * f + c];
  };
  auto h = mesh.next_halfedge_handle(h_in);  // w→x in face(u→w)
  double beta = corner(h);
  int guard = 0;
  while (h != h_out) {
    const int e = mesh.edge_handle(h).idx();
    const int z = mesh.to_vertex_handle(h).idx();
    const int sign = w_idx < z ? +1 : -1;
    const auto opp = mesh.opposite_halfedge_handle(h);
    if (mesh.is_boundary(opp)) return false;  // the left side runs through the exterior
    term(e, sign);
    kappa_sum += sign * g.kappa[e];
    h = mesh.next_halfedge_handle(opp);
    beta += corner(h);
    if (++guard > 10000) return false;
  }
  angle_term += M_PI - beta;
  return true;
}

// W = (Σ_Γ κ + Σ_w (π − β_w))/2π, an integer up to round-off (a built-in check).
long integral_winding(double kappa_sum, double angle_term, const std::string& name) {
  const double W = (kappa_sum + angle_term) / (2 * M_PI);
  const long Wi = std::lround(W);
  if (std::abs(W - Wi) > 1e-6)
    throw QsError("internal error: non-integral winding " + std::to_string(W) + " along " + name);
  return Wi;
}

// Σ_Γ p = sectors_term − 4W for the closed vertex path, Γ its left face strip (§1.3).
CycleEquation path_equation(const TriMesh& mesh, const GeometryCache& g,
                            const std::vector<int>& path, long sectors_term,
                            const std::string& name) {
  CycleEquation eq;
  const int len = static_cast<int>(path.size());
  double kappa_sum = 0, angle_term = 0;
  for (int k = 0; k < len; ++k) {
    if (!left_strip_at(mesh, g, path[(k + len - 1) % len], path[k], path[(k + 1) % len], kappa_sum,
                       angle_term, [&](int e, int sign) {
                         eq.terms.push_back({e, sign});
                       }))
      return eq;
  }
  eq.rhs = sectors_term - 4 * integral_winding(kappa_sum, angle_term, name);
  eq.ok = true;
  return eq;
}

// Σ (2 − s_i) over the nodes of a layout cycle: s_i sectors on its left at node i.
long cycle_sectors_term(const LayoutTopology& topo,
                        const std::vector<std::pair<int, bool>>& cycle) {
  long sectors_term = 0;
  const int m = static_cast<int>(cycle.size());
  for (int i = 0; i < m; ++i) {
    const auto [a, fwd] = cycle[i];
    // Node at the start of this arc: h_out leaves along it, h_in is the previous arc's end.
    const int h_out = fwd ? 2 * a : 2 * a + 1;
    const auto [pa, pfwd] = cycle[(i + m - 1) % m];
    const int h_in = pfwd ? 2 * pa + 1 : 2 * pa;
    const int node = topo.half_node[h_out];
    const auto& list = topo.node_half_arcs[node];
    const int val = static_cast<int>(list.size());
    const int pos_out = static_cast<int>(std::find(list.begin(), list.end(), h_out) - list.begin());
    const int pos_in = static_cast<int>(std::find(list.begin(), list.end(), h_in) - list.begin());
    const int s = ((pos_in - pos_out) % val + val) % val;
    sectors_term += 2 - s;
  }
  return sectors_term;
}

// Path vertex k of an arc traversed forward or backward.
int arc_vertex(const LayoutArc& arc, bool fwd, size_t k) {
  return fwd ? arc.path[k] : arc.path[arc.path.size() - 1 - k];
}

// Left-strip sums of directed arcs, cached: every layout cycle is a concatenation of arcs, and
// the strip at an arc's interior vertices depends on that arc and direction only (arcs near the
// root of the layout's spanning tree lie on many fundamental cycles).
class ArcStrips {
 public:
  ArcStrips(const TriMesh& mesh, const GeometryCache& g, const Layout& layout, const AffineRows& p)
      : mesh_(mesh),
        g_(g),
        layout_(layout),
        p_(p),
        sums_(2 * layout.arcs.size(), p.n),
        state_(2 * layout.arcs.size(), 0),
        kappa_(2 * layout.arcs.size(), 0.0),
        angle_(2 * layout.arcs.size(), 0.0) {}

  //! Row (Σ_Γ sign·p_e as an affine function) and rhs of a layout cycle; false when its left
  //! side runs through the exterior.
  bool equation(const LayoutTopology& topo, const std::vector<std::pair<int, bool>>& cycle,
                long* row, long* b) {
    const int n = p_.n;
    std::fill(row, row + n, 0L);
    long c = 0;
    double kappa_sum = 0, angle_term = 0;
    const int m = static_cast<int>(cycle.size());
    for (int i = 0; i < m; ++i) {
      const auto [a, fwd] = cycle[i];
      const auto [pa, pfwd] = cycle[(i + m - 1) % m];
      const LayoutArc& arc = layout_.arcs[a];
      const LayoutArc& prev = layout_.arcs[pa];
      // The node vertex at the start of arc i.
      const int u = arc_vertex(prev, pfwd, prev.path.size() - 2);
      const int w = arc_vertex(arc, fwd, 0), y = arc_vertex(arc, fwd, 1);
      if (!left_strip_at(mesh_, g_, u, w, y, kappa_sum, angle_term, [&](int e, int sign) {
            c += sign * p_.c[e];
            const long* pr = p_.row(e);
            for (int k = 0; k < n; ++k) row[k] += sign * pr[k];
          }))
        return false;
      // The arc's interior vertices.
      const size_t d = 2 * static_cast<size_t>(a) + (fwd ? 0 : 1);
      if (!state_[d]) compute(d, a, fwd);
      if (state_[d] < 0) return false;
      c += sums_.c[d];
      const long* sr = sums_.row(d);
      for (int k = 0; k < n; ++k) row[k] += sr[k];
      kappa_sum += kappa_[d];
      angle_term += angle_[d];
    }
    const double W = (kappa_sum + angle_term) / (2 * M_PI);
    if (std::abs(W - std::round(W)) > 1e-6)
      integral_winding(kappa_sum, angle_term,
                       "layout cycle (arcs " + arc_list(layout_, cycle) + ")");
    const long rhs = cycle_sectors_term(topo, cycle) - 4 * std::lround(W);
    *b = rhs - c;
    return true;
  }

 private:
  void compute(size_t d, int a, bool fwd) {
    const LayoutArc& arc = layout_.arcs[a];
    bool ok = true;
    for (size_t k = 1; ok && k + 1 < arc.path.size(); ++k) {
      ok = left_strip_at(mesh_, g_, arc_vertex(arc, fwd, k - 1), arc_vertex(arc, fwd, k),
                         arc_vertex(arc, fwd, k + 1), kappa_[d], angle_[d],
                         [&](int e, int sign) { sums_.add(d, sign, p_, e); });
    }
    state_[d] = ok ? 1 : -1;
  }

  const TriMesh& mesh_;
  const GeometryCache& g_;
  const Layout& layout_;
  const AffineRows& p_;
  AffineRows sums_;
  std::vector<signed char> state_;  // 0 unknown, 1 ok, -1 runs through the exterior
  std::vector<double> kappa_, angle_;
};

}  // namespace

std::vector<int> compute_period_jumps(const TriMesh& mesh, const GeometryCache& g,
                                      const Layout& layout, const LayoutTopology& topo,
                                      PeriodJumpReport* report, FreeLoopTurning free_loops) {
  const int nv = g.n_vertices, nf = g.n_faces, ne = g.n_edges;
  PeriodJumpReport rep;
  // c_v = 4 I_0(v) − 4 I_target(v).
  const std::vector<int> i0 = base_quarter_indices(mesh, g);
  const std::vector<int> target = target_quarter_indices(mesh, layout, topo);

  // 1. Dual spanning tree T* (BFS over faces); p = 0 on it.
  const std::vector<char> in_tstar = dual_spanning_tree(mesh, [](int) { return true; });

  // 2. Primal graph: interior vertices and one virtual vertex per boundary loop.
  const auto loops = boundary_loops(mesh);
  const int nb = static_cast<int>(loops.size());
  std::vector<int> gnode(nv);
  for (int v = 0; v < nv; ++v) gnode[v] = v;
  for (int l = 0; l < nb; ++l)
    for (int v : loops[l]) gnode[v] = nv + l;
  const int ng = nv + nb;
  std::vector<std::vector<int>> incident(ng);  // eligible edges per graph node
  std::vector<char> is_free(ne, 0);
  for (int e = 0; e < ne; ++e) {
    if (!interior_edge(g, e) || in_tstar[e]) continue;
    const int a = gnode[g.edge_vertices[e][0]], b = gnode[g.edge_vertices[e][1]];
    if (a == b) {
      is_free[e] = 1;  // a chord of one boundary loop that does not separate: generator-like
      continue;
    }
    incident[a].push_back(e);
    incident[b].push_back(e);
  }
  // Spanning tree T (BFS) from the root: the first boundary loop, or vertex 0 when closed.
  const int root = nb > 0 ? nv : 0;
  std::vector<int> parent_edge(ng, -1), order;
  std::vector<char> reached(ng, 0);
  std::vector<char> in_t(ne, 0);
  {
    reached[root] = 1;
    std::deque<int> queue{root};
    while (!queue.empty()) {
      const int x = queue.front();
      queue.pop_front();
      order.push_back(x);
      for (int e : incident[x]) {
        const int a = gnode[g.edge_vertices[e][0]], b = gnode[g.edge_vertices[e][1]];
        const int y = a == x ? b : a;
        if (reached[y]) continue;
        reached[y] = 1;
        parent_edge[y] = e;
        in_t[e] = 1;
        queue.push_back(y);
      }
    }
  }
  for (int x = 0; x < ng; ++x) {
    const bool used = x >= nv || !g.vertex_on_boundary[x];
    if (used && !reached[x])
      throw InvalidInputError("the mesh is not connected; the cross field needs one component");
  }
  // Free unknowns: leftover edges (2g generators, chords) and the parent edges of the non-root
  // boundary loops, whose turning numbers come from layout cycles.
  for (int e = 0; e < ne; ++e)
    if (interior_edge(g, e) && !in_tstar[e] && !in_t[e]) is_free[e] = 1;
  for (int l = 0; l < nb; ++l)
    if (nv + l != root) is_free[parent_edge[nv + l]] = 1;
  std::vector<int> free_index(ne, -1);
  int nfree = 0;
  for (int e = 0; e < ne; ++e)
    if (is_free[e]) free_index[e] = nfree++;
  rep.free_unknowns = nfree;

  // 3. Solve the vertex equations leaves-first; p as affine functions of the free unknowns.
  AffineRows p(ne, nfree);
  for (int e = 0; e < ne; ++e)
    if (is_free[e]) p.row(e)[free_index[e]] = 1;
  // All interior edges around each interior vertex (compressed rows).
  std::vector<int> around_start(nv + 1, 0), around;
  for (int e = 0; e < ne; ++e) {
    if (!interior_edge(g, e)) continue;
    ++around_start[g.edge_vertices[e][0] + 1];
    ++around_start[g.edge_vertices[e][1] + 1];
  }
  for (int v = 0; v < nv; ++v) around_start[v + 1] += around_start[v];
  around.resize(around_start[nv]);
  {
    std::vector<int> fill(around_start.begin(), around_start.end() - 1);
    for (int e = 0; e < ne; ++e) {
      if (!interior_edge(g, e)) continue;
      around[fill[g.edge_vertices[e][0]]++] = e;
      around[fill[g.edge_vertices[e][1]]++] = e;
    }
  }
  AffineRows r(1, nfree);  // c_v − Σ_ccw p at one vertex
  auto residual = [&](int v) {
    r.c[0] = i0[v] - target[v];
    std::fill(r.coef.begin(), r.coef.end(), 0L);
    for (int k = around_start[v]; k < around_start[v + 1]; ++k) {
      const int e = around[k];
      r.add(0, -ccw_sign(g, e, v), p, e);
    }
  };
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const int x = *it;
    if (x == root || x >= nv) continue;  // boundary loops: handled through free unknowns
    const int e = parent_edge[x];
    // p_e currently 0; solve s·p_e = residual.
    residual(x);
    const int s = ccw_sign(g, e, x);
    p.c[e] = s * r.c[0];
    for (int k = 0; k < nfree; ++k) p.row(e)[k] = s * r.coef[k];
  }
  if (nb == 0) {
    residual(root);
    bool zero = r.c[0] == 0;
    for (long c : r.coef) zero = zero && c == 0;
    if (!zero) {
      long total = 0;
      for (int v = 0; v < nv; ++v) total += target[v];
      throw TopologyError("the layout's node valences give singularity indices that sum to " +
                          std::to_string(total) + "/4, but the surface needs " +
                          std::to_string(4 * (nv - ne + nf)) + "/4 (Poincaré–Hopf)");
    }
  }

  // 4. Fix the free unknowns with layout cycle equations.
  std::vector<long> gval(nfree, 0);
  const auto cycles = layout_fundamental_cycles(layout, topo);
  std::vector<std::vector<long>> rows;
  std::vector<long> rhs;
  std::vector<int> row_cycle;
  ArcStrips strips(mesh, g, layout, p);
  for (size_t c = 0; c < cycles.size(); ++c) {
    std::vector<long> row(nfree, 0);
    long b = 0;
    bool ok = strips.equation(topo, cycles[c], row.data(), &b);
    if (!ok) {
      auto reversed = cycles[c];
      std::reverse(reversed.begin(), reversed.end());
      for (auto& [a, fwd] : reversed) fwd = !fwd;
      ok = strips.equation(topo, reversed, row.data(), &b);
    }
    if (!ok) {
      ++rep.cycles_skipped;
      continue;
    }
    rows.push_back(std::move(row));
    rhs.push_back(b);
    row_cycle.push_back(static_cast<int>(c));
  }
  rep.cycles = static_cast<int>(rows.size());
  auto rank_of = [&](const std::vector<std::vector<long>>& R) {
    if (R.empty() || nfree == 0) return 0;
    Eigen::MatrixXd A(R.size(), nfree);
    for (size_t r = 0; r < R.size(); ++r)
      for (int k = 0; k < nfree; ++k) A(r, k) = static_cast<double>(R[r][k]);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    qr.setThreshold(1e-9);
    return static_cast<int>(qr.rank());
  };
  // Boundary loops that no layout cycle determines (holes that dangling arcs run into, with
  // no closed arc cycle around them, i.e. boundaries the layout leaves free), FreeLoopTurning:
  // - kCap: the field turns along such a loop as around a regular point, as if the hole were
  //   capped by a disk without singularity, so the iso-lines run on across the hole. A loop is
  //   walked with the surface on its left, so the cap lies on its right: sectors term −4 (a
  //   convex patch boundary walked with the patch on its left has +4).
  // - kWrap: the field turns like the loop's tangent (sectors term 0, a cycle without corners,
  //   as along an aligned boundary), so the iso-lines wrap around the hole.
  // Gauss–Bonnet leaves one loop of a sphere with holes to the others: the shortest loops are
  // taken first, so that the longest one (a disk's outer boundary) is the one determined. Each
  // is added only where it raises the rank, so it never overrides what the layout implies.
  // (Wrapping every free loop folds the mask with arcs into both free eye holes around the eyes;
  // capped, it embeds.)
  if (nfree > 0 && rank_of(rows) < nfree) {
    std::vector<char> node_vertex(nv, 0);
    for (const auto& n : layout.nodes) node_vertex[n.vertex] = 1;
    std::vector<double> loop_length(nb, 0.0);
    for (int l = 0; l < nb; ++l)
      for (size_t k = 0; k < loops[l].size(); ++k) {
        const int a = loops[l][k], b = loops[l][(k + 1) % loops[l].size()];
        loop_length[l] +=
            (mesh.point(mesh.vertex_handle(a)) - mesh.point(mesh.vertex_handle(b))).norm();
      }
    std::vector<int> loop_order(nb);
    std::iota(loop_order.begin(), loop_order.end(), 0);
    std::stable_sort(loop_order.begin(), loop_order.end(),
                     [&](int a, int b) { return loop_length[a] < loop_length[b]; });
    const long sectors = free_loops == FreeLoopTurning::kCap ? -4 : 0;
    int current = rank_of(rows);
    for (int li = 0; li < nb && current < nfree; ++li) {
      const int l = loop_order[li];
      bool has_node = false;
      for (int v : loops[l]) has_node |= node_vertex[v] != 0;
      if (has_node) continue;
      CycleEquation eq =
          path_equation(mesh, g, loops[l], sectors, "boundary loop " + std::to_string(l));
      if (!eq.ok) continue;
      std::vector<long> row(nfree, 0);
      long b = eq.rhs;
      for (auto [e, s] : eq.terms) {
        b -= s * p.c[e];
        for (int k = 0; k < nfree; ++k) row[k] += s * p.row(e)[k];
      }
      rows.push_back(row);
      if (rank_of(rows) > current) {
        ++current;
        rhs.push_back(b);
        row_cycle.push_back(-1 - l);
        ++rep.boundary_loop_equations;
      } else {
        rows.pop_back();
      }
    }
  }
  if (nfree > 0) {
    Eigen::MatrixXd A(rows.size(), nfree);
    Eigen::VectorXd B(rows.size());
    for (size_t r = 0; r < rows.size(); ++r) {
      for (int k = 0; k < nfree; ++k) A(r, k) = static_cast<double>(rows[r][k]);
      B(r) = static_cast<double>(rhs[r]);
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    qr.setThreshold(1e-9);
    rep.rank = rows.empty() ? 0 : static_cast<int>(qr.rank());
    if (rep.rank < nfree) {
      std::ostringstream ss;
      ss << "the layout does not determine the cross-field turning number of " << (nfree - rep.rank)
         << " homology generator or boundary cycle(s); every handle and every boundary loop must "
            "be "
            "crossed or followed by a closed cycle of arcs";
      throw TopologyError(ss.str());
    }
    const Eigen::VectorXd sol = qr.solve(B);
    for (int k = 0; k < nfree; ++k) {
      if (std::abs(sol(k) - std::round(sol(k))) > 1e-6) {
        throw TopologyError("the layout implies a non-integral cross-field turning number (" +
                            std::to_string(sol(k)) + " quarter turns) along a homology generator");
      }
      gval[k] = std::lround(sol(k));
    }
  }
  for (size_t r = 0; r < rows.size(); ++r) {
    long lhs = 0;
    for (int k = 0; k < nfree; ++k) lhs += rows[r][k] * gval[k];
    if (lhs != rhs[r]) {
      const std::string cycle =
          row_cycle[r] >= 0
              ? "the layout cycle through arcs " + arc_list(layout, cycles[row_cycle[r]])
              : "boundary loop " + std::to_string(-1 - row_cycle[r]);
      throw TopologyError(cycle + " needs a cross-field turning of " +
                          std::to_string(rhs[r] - lhs) +
                          " quarter turns that no field with singularities only at the nodes "
                          "can have");
    }
  }

  std::vector<int> out(ne, 0);
  for (int e = 0; e < ne; ++e) {
    long val = p.c[e];
    for (int k = 0; k < nfree; ++k) val += p.row(e)[k] * gval[k];
    out[e] = static_cast<int>(val);
    rep.max_abs_jump = std::max(rep.max_abs_jump, std::abs(out[e]));
  }
  // Every interior vertex must now have its target index.
  const std::vector<int> idx = quarter_indices_from_jumps(g, out);
  for (int v = 0; v < nv; ++v) {
    if (!g.vertex_on_boundary[v] && idx[v] != target[v])
      throw QsError("internal error: vertex " + std::to_string(v) + " has index " +
                    std::to_string(idx[v]) + "/4 instead of " + std::to_string(target[v]) +
                    "/4 after period-jump construction");
  }
  if (report) *report = rep;
  return out;
}

}  // namespace qs
