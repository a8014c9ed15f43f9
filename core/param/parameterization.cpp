#include "core/param/parameterization.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "core/base/errors.h"
#include "core/base/timing.h"

namespace qs {

namespace {

using Terms = std::vector<std::pair<int, double>>;

// A pair of affine expressions (u, v) in the unknowns.
struct Lin2 {
  Terms u, v;
  double cu = 0, cv = 0;
};

Lin2 corner_expr(const GeometryCache& g, const CutGraph& cut, int f, int vertex) {
  const int w = cut.corner_wedge[3 * f + corner_of(g, f, vertex)];
  Lin2 e;
  e.u.push_back({2 * w, 1.0});
  e.v.push_back({2 * w + 1, 1.0});
  return e;
}

Terms scaled(const Terms& t, double s) {
  Terms out = t;
  for (auto& [v, c] : out) c *= s;
  return out;
}

void append(Terms& a, const Terms& b, double s = 1.0) {
  for (auto [v, c] : b) a.push_back({v, s * c});
}

Lin2 sub(const Lin2& a, const Lin2& b) {
  Lin2 r = a;
  append(r.u, b.u, -1.0);
  append(r.v, b.v, -1.0);
  r.cu -= b.cu;
  r.cv -= b.cv;
  return r;
}

Lin2 add(const Lin2& a, const Lin2& b) {
  Lin2 r = a;
  append(r.u, b.u);
  append(r.v, b.v);
  r.cu += b.cu;
  r.cv += b.cv;
  return r;
}

Lin2 rotate(int r, const Lin2& a) {
  switch (((r % 4) + 4) % 4) {
    case 1:
      return {scaled(a.v, -1.0), a.u, -a.cv, a.cu};
    case 2:
      return {scaled(a.u, -1.0), scaled(a.v, -1.0), -a.cu, -a.cv};
    case 3:
      return {a.v, scaled(a.u, -1.0), a.cv, -a.cu};
    default:
      return a;
  }
}

// Merges duplicate variables so expressions stay short along long arcs.
void compact(Terms& t) {
  std::sort(t.begin(), t.end());
  Terms out;
  for (auto [v, c] : t) {
    if (!out.empty() && out.back().first == v)
      out.back().second += c;
    else
      out.push_back({v, c});
  }
  out.erase(
      std::remove_if(out.begin(), out.end(), [](auto& p) { return std::abs(p.second) < 1e-15; }),
      out.end());
  t.swap(out);
}

// Checks that \p g holds the per-face gradients face_gradients reads.
// \throw InvalidInputError when it does not (a cache not from build_geometry).
void check_face_gradients(const GeometryCache& g) {
  if (static_cast<int>(g.face_gradient.size()) != g.n_faces)
    throw InvalidInputError("geometry cache has " + std::to_string(g.face_gradient.size()) +
                            " face gradients for " + std::to_string(g.n_faces) +
                            " faces (build it with build_geometry)");
}

// Local 2D gradient operator of face f: ∇φ_k (2D, in the frame r_f, n×r_f), and the area
// (GeometryCache::face_gradient; check_face_gradients first).
void face_gradients(const GeometryCache& g, int f, Eigen::Matrix<double, 2, 3>& G, double& area) {
  const std::array<double, 7>& grad = g.face_gradient[f];
  for (int k = 0; k < 3; ++k) G.col(k) = Eigen::Vector2d(grad[2 * k], grad[2 * k + 1]);
  area = grad[6];
}

}  // namespace

std::vector<int> parameterization_groups(int wedges, const std::vector<int>& free_index, int free) {
  std::vector<int> group(free, -1);
  std::vector<int> wedge_group(wedges, -1);
  int groups = 0;
  for (int i = 0; i < static_cast<int>(free_index.size()); ++i) {
    const int k = free_index[i];
    if (k < 0 || k >= free) continue;
    if (i < 2 * wedges) {
      int& g = wedge_group[i / 2];
      if (g < 0) g = groups++;
      group[k] = g;
    } else {
      group[k] = groups++;
    }
  }
  for (int& g : group)
    if (g < 0) g = groups++;  // not named by free_index (does not happen for a Reduction)
  return group;
}

double param_signed_area2(const std::vector<std::array<double, 2>>& uv, int f) {
  const auto& a = uv[3 * f];
  const auto& b = uv[3 * f + 1];
  const auto& c = uv[3 * f + 2];
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

ParamSolver::ParamSolver(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                         const LayoutTopology& topo, const std::vector<int>& p,
                         const std::vector<double>& theta, const ParamOptions& options,
                         ParamSolver* previous, bool solve_now)
    : options_(options), period_jump_(p) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!options_.face_weights.empty() && static_cast<int>(options_.face_weights.size()) != g.n_faces)
    throw InvalidInputError("ParamOptions::face_weights must have one entry per face");
  std::vector<char> singular(g.n_vertices, 0);
  for (int n = 0; n < topo.num_nodes; ++n)
    if (topo.valence[n] != 4) singular[layout.nodes[n].vertex] = 1;
  if (options_.second_thread) {  // independent: the labels on a second thread
    // (std::async's future waits in its destructor if the cut graph throws)
    auto labels = std::async(std::launch::async,
                             [&]() { return label_layout(mesh, g, layout, topo, p, theta); });
    cut_ = build_cut_graph(mesh, g, p, singular);
    labeling_ = labels.get();
  } else {
    cut_ = build_cut_graph(mesh, g, p, singular);
    labeling_ = label_layout(mesh, g, layout, topo, p, theta);
  }
  // H's pattern on the wedges needs the cut only: on a large mesh, built on a second thread
  // beside the constraint rows and their elimination, else where it is collected. (std::async's
  // future waits in its destructor if they throw; it reads cut_, a member.)
  constexpr int kThreadWedges = 8192;
  std::future<ReducedAssembly::WedgePattern> wedge_pattern = std::async(
      options_.second_thread && cut_.wedges >= kThreadWedges ? std::launch::async
                                                             : std::launch::deferred,
      [this]() { return ReducedAssembly::wedge_pattern(cut_.corner_wedge, cut_.wedges); });
  system_.variables = 2 * cut_.wedges;

  auto add_row = [&](Terms terms, double rhs, int origin) {
    compact(terms);
    system_.rows.push_back({std::move(terms), rhs, origin});
  };
  auto edge_name = [&](int a, int b) {
    return "(" + std::to_string(a) + ", " + std::to_string(b) + ")";
  };

  // Fixed point first (removes the translation null space): the first node at (0, 0).
  {
    const int h = topo.node_half_arcs[0].empty() ? 0 : topo.node_half_arcs[0][0];
    const Lin2 x = corner_expr(g, cut_, labeling_.chart_face[h], layout.nodes[0].vertex);
    const int o = system_.add_origin("fixed point at node " + std::to_string(layout.nodes[0].id));
    add_row(x.u, 0.0, o);
    add_row(x.v, 0.0, o);
  }
  // Seams: one translation t_c per cut curve (a maximal chain of cut edges through regular
  // vertices of cut-valence 2). Across every cut edge, each endpoint w satisfies
  // X_right(w) = R^r X_left(w) + t_c. Rows stay three terms long, so elimination does not chain
  // along the curve (edge-vector rows would, filling the reduced matrix).
  {
    std::vector<int> cut_valence(g.n_vertices, 0);
    for (int e = 0; e < g.n_edges; ++e)
      if (cut_.cut[e]) ++cut_valence[g.edge_vertices[e][0]], ++cut_valence[g.edge_vertices[e][1]];
    auto curve_node = [&](int v) {
      return cut_valence[v] != 2 || singular[v] || g.vertex_on_boundary[v];
    };
    std::vector<char> done(g.n_edges, 0);
    int curves = 0;
    std::vector<std::vector<std::pair<OpenMesh::HalfedgeHandle, int>>>
        curve_edges;  // (halfedge along, r)
    for (int e0 = 0; e0 < g.n_edges; ++e0) {
      if (!cut_.cut[e0] || done[e0]) continue;
      // Walk backwards to the start of this curve (a curve node, or around a closed loop).
      auto h = mesh.halfedge_handle(mesh.edge_handle(e0), 0);
      const auto h_first = h;
      for (int guard = 0; guard < g.n_edges; ++guard) {
        const int v = mesh.from_vertex_handle(h).idx();
        if (curve_node(v)) break;
        OpenMesh::HalfedgeHandle prev;
        for (auto o : mesh.vih_range(mesh.vertex_handle(v)))
          if (cut_.cut[mesh.edge_handle(o).idx()] && mesh.edge_handle(o) != mesh.edge_handle(h))
            prev = o;
        if (!prev.is_valid() || prev == h_first) break;
        h = prev;
        if (h == h_first) break;
      }
      // Walk forwards, splitting where the rotation changes.
      std::vector<std::pair<OpenMesh::HalfedgeHandle, int>> edges;
      int r_curve = -1;
      for (int guard = 0; guard < g.n_edges; ++guard) {
        const int e = mesh.edge_handle(h).idx();
        if (done[e]) break;
        const int w = mesh.from_vertex_handle(h).idx(), z = mesh.to_vertex_handle(h).idx();
        const int r = step_rotation(p[e], w, z);
        if (r_curve >= 0 && r != r_curve) {
          curve_edges.push_back(std::move(edges));
          edges.clear();
        }
        r_curve = r;
        done[e] = 1;
        edges.push_back({h, r});
        if (curve_node(z)) break;
        OpenMesh::HalfedgeHandle next;
        for (auto o : mesh.voh_range(mesh.vertex_handle(z)))
          if (cut_.cut[mesh.edge_handle(o).idx()] && mesh.edge_handle(o) != mesh.edge_handle(h))
            next = o;
        if (!next.is_valid()) break;
        h = next;
      }
      if (!edges.empty()) curve_edges.push_back(std::move(edges));
    }
    curves = static_cast<int>(curve_edges.size());
    const int t0_index = system_.variables;
    system_.variables += 2 * curves;
    // The translations appear in every node row whose strip crosses their curve: eliminate
    // them last (constraints.h).
    system_.eliminate_last.assign(system_.variables, 0);
    std::fill(system_.eliminate_last.begin() + t0_index, system_.eliminate_last.end(), 1);
    for (int c = 0; c < curves; ++c) {
      const int tu = t0_index + 2 * c, tv = tu + 1;
      for (const auto& [h, r] : curve_edges[c]) {
        const int left = mesh.face_handle(h).idx();
        const int right = mesh.face_handle(mesh.opposite_halfedge_handle(h)).idx();
        const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
        const int o =
            system_.add_origin("seam at edge " + edge_name(std::min(a, b), std::max(a, b)));
        for (int w : {a, b}) {
          Lin2 d = sub(corner_expr(g, cut_, right, w), rotate(r, corner_expr(g, cut_, left, w)));
          d.u.push_back({tu, -1.0});
          d.v.push_back({tv, -1.0});
          add_row(d.u, 0.0, o);
          add_row(d.v, 0.0, o);
        }
      }
    }
    result_.cut_curves = curves;
  }
  std::unordered_map<int, double> prescribed_length;  // arc id -> length (--integer)
  for (const ArcLength& l : options_.arc_lengths) {
    if (!std::isfinite(l.length))
      throw InvalidInputError("fixed length of arc " + std::to_string(l.arc_id) +
                              " is not a finite number");
    prescribed_length[l.arc_id] = l.length;
  }
  // Do the halfedges x→y and y→z lie in one face (a path turning inside a triangle)?
  auto same_face = [&](int x, int y, int z) {
    const auto h0 = mesh.find_halfedge(mesh.vertex_handle(x), mesh.vertex_handle(y));
    const auto h1 = mesh.find_halfedge(mesh.vertex_handle(y), mesh.vertex_handle(z));
    return !mesh.is_boundary(h0) && mesh.face_handle(h0) == mesh.face_handle(h1);
  };
  // Arcs: node connection (3); along boundary and pinned arcs every path vertex is on the
  // iso-line (except the apex of an "ear", below).
  for (int a = 0; a < topo.num_arcs; ++a) {
    const LayoutArc& arc = layout.arcs[a];
    const ArcStrip& s = labeling_.strips[a];
    bool along_boundary = true;
    for (size_t k = 0; k + 1 < arc.path.size(); ++k) {
      const auto h =
          mesh.find_halfedge(mesh.vertex_handle(arc.path[k]), mesh.vertex_handle(arc.path[k + 1]));
      along_boundary &= mesh.is_boundary(mesh.edge_handle(h));
    }
    const bool iso_all = arc.pinned || along_boundary;
    if (arc.dangling() && !iso_all) continue;
    const int start_half = s.reversed ? 2 * a + 1 : 2 * a;
    const int d0 = labeling_.symbol[start_half];
    const int origin =
        system_.add_origin("arc " + std::to_string(arc.id) +
                           (iso_all ? " (iso-line along its path)" : " (node connection)"));
    Lin2 P = corner_expr(g, cut_, labeling_.chart_face[start_half], s.walk[0]);
    int r_total = 0;
    size_t step = 0;
    const size_t K = s.walk.size() - 1;
    for (size_t k = 1; k <= K; ++k) {
      for (; step < static_cast<size_t>(s.arrival[k]); ++step) {
        const auto h = s.steps[step];
        const int fi = mesh.face_handle(h).idx();
        const int fj = mesh.face_handle(mesh.opposite_halfedge_handle(h)).idx();
        const int pivot = mesh.from_vertex_handle(h).idx();
        const int r =
            step_rotation(p[mesh.edge_handle(h).idx()], pivot, mesh.to_vertex_handle(h).idx());
        if (r == 0 && !cut_.cut[mesh.edge_handle(h).idx()]) continue;  // identity, same wedge
        P = add(rotate(r, sub(P, corner_expr(g, cut_, fi, pivot))),
                corner_expr(g, cut_, fj, pivot));
        compact(P.u);
        compact(P.v);
        r_total += r;
      }
      const bool last = k == K;
      if (!iso_all && !last) continue;
      // An "ear": the path turns at w_k inside one triangle (both path edges belong to the same
      // face, e.g. a boundary triangle with two boundary edges). Putting w_k on the iso-line too
      // would map that triangle to a segment (inspired_mesh: parametric area 0, E_confor 1e28),
      // so w_k stays free and the iso-line cuts across the triangle.
      if (!last && (same_face(s.walk[k - 1], s.walk[k], s.walk[k + 1]) ||
                    same_face(s.walk[k + 1], s.walk[k], s.walk[k - 1])))
        continue;
      if (last && arc.dangling()) break;
      const int face = mesh.face_handle(mesh.find_halfedge(mesh.vertex_handle(s.walk[k - 1]),
                                                           mesh.vertex_handle(s.walk[k])))
                           .idx();
      const Lin2 X = corner_expr(g, cut_, face, s.walk[k]);
      const bool along_u = (d0 + r_total) % 2 == 0;  // the arc runs along ±u here: v constant
      Terms row = along_u ? P.v : P.u;
      append(row, along_u ? X.v : X.u, -1.0);
      add_row(row, along_u ? X.cv - P.cv : X.cu - P.cu, origin);
      if (last) {  // the running coordinate: its change along the arc is the arc's length
        ArcSpan span;
        span.arc_id = arc.id;
        span.terms = along_u ? X.u : X.v;
        append(span.terms, along_u ? P.u : P.v, -1.0);
        compact(span.terms);
        span.constant = along_u ? X.cu - P.cu : X.cv - P.cv;
        if (const auto it = prescribed_length.find(arc.id); it != prescribed_length.end()) {
          const int o = system_.add_origin("arc " + std::to_string(arc.id) + " (fixed length " +
                                           std::to_string(it->second) + ")");
          add_row(span.terms, it->second - span.constant, o);
        }
        arc_spans_.push_back(std::move(span));
      }
    }
  }
  // Explicit feature edges (layout "features") that are not arcs: iso-lines of the field's
  // matching parameter.
  feature_rows_ = feature_edge_rows(mesh, g, layout, theta);
  for (size_t i = 0; i < layout.feature_edges.size(); ++i) {
    const FeatureRow& row = feature_rows_[i];
    if (row.face < 0) continue;
    const auto [a, b] = layout.feature_edges[i];
    const Lin2 d = sub(corner_expr(g, cut_, row.face, b), corner_expr(g, cut_, row.face, a));
    const int o = system_.add_origin("feature edge " + edge_name(a, b));
    add_row(row.along_u ? d.v : d.u, 0.0, o);
  }
  reduction_ = eliminate_constraints(system_);
  assembly_ =
      ReducedAssembly(wedge_pattern.get(), system_.variables, reduction_.Z, options_.second_thread);
  result_.wedges = cut_.wedges;
  result_.cut_edges = cut_.cut_edges;
  result_.constraint_rows = static_cast<int>(system_.rows.size());
  result_.eliminated = reduction_.eliminated;
  result_.redundant = reduction_.redundant;
  result_.unknowns = static_cast<int>(reduction_.Z.cols());
  n_vertices_ = g.n_vertices;
  wedge_vertex_.assign(cut_.wedges, -1);
  for (int c = 0; c < 3 * g.n_faces; ++c)
    wedge_vertex_[cut_.corner_wedge[c]] = g.face_vertices[c / 3][c % 3];
  result_.timings.setup_s = seconds_since(t0);
  if (previous && previous != this) {
    std::swap(solver_, previous->solver_);
    // The sizing Laplacian depends on the connectivity only: keep its analysis too.
    if (options_.sizing.enabled && previous->sizing_ && previous->sizing_->same_connectivity(g) &&
        previous->sizing_->options().clamp == options_.sizing.clamp &&
        previous->sizing_->options().exclude_singular_faces ==
            options_.sizing.exclude_singular_faces)
      sizing_ = std::move(previous->sizing_);
  }
  if (solve_now)
    solve(mesh, g, theta);
  else
    begin_analysis();  // the first factorization's, meanwhile
}

ParamSolver::~ParamSolver() = default;

std::vector<ParamSolver::FeatureRow> ParamSolver::feature_edge_rows(
    const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
    const std::vector<double>& theta) {
  std::vector<FeatureRow> out(layout.feature_edges.size());
  if (out.empty()) return out;
  const std::vector<char> arc_edge = arc_edge_mask(mesh, layout);
  for (size_t i = 0; i < out.size(); ++i) {
    const auto [a, b] = layout.feature_edges[i];
    auto h = mesh.find_halfedge(mesh.vertex_handle(a), mesh.vertex_handle(b));
    if (!h.is_valid() || arc_edge[mesh.edge_handle(h).idx()]) continue;
    if (mesh.is_boundary(h)) h = mesh.opposite_halfedge_handle(h);
    const int f = mesh.face_handle(h).idx();
    const Vec3 t = mesh.point(mesh.vertex_handle(b)) - mesh.point(mesh.vertex_handle(a));
    const double rel = g.angle_in_face(f, t) - theta[f];
    out[i] = {f, std::lround(rel / (M_PI / 2)) % 2 == 0};
  }
  return out;
}

bool ParamSolver::adopt_field(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                              const LayoutTopology& topology, const std::vector<int>& p,
                              const std::vector<double>& theta) {
  if (p != period_jump_ || feature_edge_rows(mesh, g, layout, theta) != feature_rows_) return false;
  Labeling labels = label_layout(mesh, g, layout, topology, p, theta);
  // The rows see a symbol's parity only (which parameter is constant along the arc): symbols
  // that all differ by a half turn give the same system.
  for (size_t h = 0; h < labels.symbol.size(); ++h)
    if (labels.symbol[h] % 2 != labeling_.symbol[h] % 2) return false;
  labeling_ = std::move(labels);  // its symbols and diagnostics for θ (extraction reads them)
  return true;
}

std::vector<ArcLength> ParamSolver::arc_lengths() const {
  // Wedge values from the corner values (every corner of a wedge has the same (u, v)).
  std::vector<std::array<double, 2>> wedge_uv(cut_.wedges, {0.0, 0.0});
  for (size_t c = 0; c < result_.corner_uv.size() && c < cut_.corner_wedge.size(); ++c)
    wedge_uv[cut_.corner_wedge[c]] = result_.corner_uv[c];
  std::vector<ArcLength> out;
  out.reserve(arc_spans_.size());
  for (const ArcSpan& span : arc_spans_) {
    double value = span.constant;
    for (const auto& [variable, coefficient] : span.terms) {
      if (variable >= 2 * cut_.wedges) continue;  // spans only involve wedge unknowns
      value += coefficient * wedge_uv[variable / 2][variable % 2];
    }
    out.push_back({span.arc_id, value});
  }
  return out;
}

void ParamSolver::begin_analysis() {
  if (!options_.second_thread) return;
  hint_ordering(assembly_.A());
  solver_.begin_analysis(assembly_.A());
}

void ParamSolver::hint_ordering(const Eigen::SparseMatrix<double>& A) {
  if (!(options_.wedge_ordering || options_.vertex_order) || solver_.same_pattern(A)) return;
  if (options_.vertex_order) {
    std::vector<int> hint = vertex_order_hint(A);
    if (!hint.empty()) {
      solver_.set_ordering_hint(std::move(hint));
      return;
    }
  }
  if (!options_.wedge_ordering) return;
  solver_.set_ordering_hint(grouped_amd_ordering(
      A, parameterization_groups(cut_.wedges, reduction_.free_index, static_cast<int>(A.cols()))));
}

std::vector<int> ParamSolver::vertex_order_hint(const Eigen::SparseMatrix<double>& A) const {
  const std::vector<int>& order = *options_.vertex_order;
  const int m = static_cast<int>(A.cols());
  if (order.size() != static_cast<size_t>(n_vertices_) || reduction_.Z.cols() != m) return {};
  std::vector<int> rank(n_vertices_, -1);
  for (int k = 0; k < n_vertices_; ++k) {
    if (order[k] < 0 || order[k] >= n_vertices_ || rank[order[k]] >= 0) return {};
    rank[order[k]] = k;
  }
  // A wedge unknown's column holds its face neighbours' (about 7 entries; about 3 times that
  // where the cut's transitions merged the wedges on both sides of a seam). Longer columns (an
  // arc's node-connection unknowns, the seam translations) couple distant vertices: last, as
  // AMD orders dense rows.
  //
  // "Longer" is relative: at least 48 entries and 16 times the median wedge column. Where the
  // cut merges wedges along long seams, most merged columns hold about 70 entries (the pig of
  // `import-quads --refine 3`, 942 nodes: 18084 of 39605 unknowns). A fixed bound of 48 sent them
  // all last, unordered: 13 times AMD's fill, 340 times its flops, a 3.3 s factorization instead
  // of 0.06 s. With the relative bound only the columns that couple the whole mesh (seam
  // translations: thousands of entries) go last.
  constexpr int kLongColumnMin = 48, kLongColumnPerMedian = 16;
  constexpr long kLast = std::numeric_limits<long>::max();
  std::vector<long> place(m, kLast);
  const int wedge_variables =
      std::min(2 * cut_.wedges, static_cast<int>(reduction_.free_index.size()));
  auto column_length = [&](int a) { return A.outerIndexPtr()[a + 1] - A.outerIndexPtr()[a]; };
  std::vector<int> lengths;
  lengths.reserve(wedge_variables);
  for (int i = 0; i < wedge_variables; ++i)
    if (reduction_.free_index[i] >= 0) lengths.push_back(column_length(reduction_.free_index[i]));
  int long_column = kLongColumnMin;
  if (!lengths.empty()) {
    std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
    long_column = std::max(long_column, kLongColumnPerMedian * lengths[lengths.size() / 2]);
  }
  for (int i = 0; i < wedge_variables; ++i) {
    const int a = reduction_.free_index[i];
    if (a >= 0 && column_length(a) <= long_column) place[a] = rank[wedge_vertex_[i / 2]];
  }
  std::vector<int> hint(m);
  std::iota(hint.begin(), hint.end(), 0);
  std::stable_sort(hint.begin(), hint.end(), [&](int a, int b) { return place[a] < place[b]; });
  return hint;
}

std::vector<int> vertex_nested_dissection(const GeometryCache& g) {
  return vertex_nested_dissection(g.n_vertices, g.edge_vertices);
}

std::vector<int> vertex_nested_dissection(int n_vertices,
                                          const std::vector<std::array<int, 2>>& edges) {
  std::vector<int> start(n_vertices + 1, 0), adjacency(2 * edges.size());
  for (const auto& [a, b] : edges) {
    if (a < 0 || b < 0 || a >= n_vertices || b >= n_vertices) return {};
    ++start[a + 1], ++start[b + 1];
  }
  for (int v = 0; v < n_vertices; ++v) start[v + 1] += start[v];
  std::vector<int> next(start.begin(), start.end() - 1);
  for (const auto& [a, b] : edges) {
    adjacency[next[a]++] = b;
    adjacency[next[b]++] = a;
  }
  return nested_dissection_ordering(n_vertices, start, adjacency);
}

std::vector<double> ParamSolver::target_scales(const TriMesh& mesh, const GeometryCache& g,
                                               const std::vector<double>& theta) {
  std::vector<double> scale(g.n_faces, 1.0);
  if (!options_.sizing.enabled) {
    result_.sizing_log_scale.clear();
    return scale;
  }
  const std::vector<double>& frozen = options_.sizing.frozen_log_scale;
  if (!frozen.empty()) {
    if (static_cast<int>(frozen.size()) != g.n_faces)
      throw InvalidInputError("SizingOptions::frozen_log_scale has " +
                              std::to_string(frozen.size()) + " entries for " +
                              std::to_string(g.n_faces) + " faces");
    for (int f = 0; f < g.n_faces; ++f)
      if (!std::isfinite(frozen[f]))
        throw InvalidInputError("SizingOptions::frozen_log_scale of face " + std::to_string(f) +
                                " is not a finite number");
    result_.sizing_log_scale = frozen;
  } else {
    if (!sizing_) sizing_ = std::make_unique<SizingSolver>(mesh, g, options_.sizing);
    result_.sizing_log_scale = sizing_->solve(mesh, g, theta, period_jump_).log_scale;
  }
  for (int f = 0; f < g.n_faces; ++f) scale[f] = std::exp(result_.sizing_log_scale[f]);
  return scale;
}

const Parameterization& ParamSolver::solve(const TriMesh& mesh, const GeometryCache& g,
                                           const std::vector<double>& theta) {
  auto t0 = std::chrono::steady_clock::now();
  const int n = system_.variables;
  const double aniso = options_.anisotropic ? options_.anisotropy : 1.0;
  // A's pattern is fixed (ReducedAssembly): a new one is analyzed while the values are filled.
  begin_analysis();
  // Until factorize() collects it, the analysis reads A's pattern: wait for it on every exit.
  struct WaitForAnalysis {
    const SpdSolver& solver;
    ~WaitForAnalysis() { solver.wait_for_analysis(); }
  } wait_for_analysis{solver_};
  // Targets e^{s_t} u_t, e^{s_t} v_t (sizing): only the right-hand side and the constant change.
  // The orientation constraints (solve_oriented) use the field's directions only, which the
  // scale does not change; their QP gets the sized b.
  const std::vector<double> scale = target_scales(mesh, g, theta);
  assembly_.clear();
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  double constant = 0;
  check_face_gradients(g);
  for (int f = 0; f < g.n_faces; ++f) {
    Eigen::Matrix<double, 2, 3> G;
    double area;
    face_gradients(g, f, G, area);
    if (!options_.face_weights.empty()) area *= options_.face_weights[f];
    const Eigen::Vector2d u(std::cos(theta[f]), std::sin(theta[f])), v(-u.y(), u.x());
    const Eigen::Matrix2d Wu = u * u.transpose() + aniso * v * v.transpose();
    const Eigen::Matrix2d Wv = v * v.transpose() + aniso * u * u.transpose();
    const Eigen::Matrix3d Hu = area * G.transpose() * Wu * G;
    const Eigen::Matrix3d Hv = area * G.transpose() * Wv * G;
    const double sf = scale[f];
    const Eigen::Vector3d gu = sf * area * G.transpose() * u, gv = sf * area * G.transpose() * v;
    assembly_.add_face(f, Hu, Hv);
    for (int k = 0; k < 3; ++k) {
      const int w = cut_.corner_wedge[3 * f + k];
      rhs(2 * w) += gu(k);
      rhs(2 * w + 1) += gv(k);
    }
    constant += 2 * area * sf * sf;  // u_tᵀW_u u_t = v_tᵀW_v v_t = e^{2s}
  }
  assembly_.reduce();
  const Eigen::SparseMatrix<double>& H = assembly_.H();
  const Eigen::SparseMatrix<double>& Z = reduction_.Z;
  const Eigen::SparseMatrix<double>& A = assembly_.A();
  const Eigen::VectorXd b = reduction_.z0.isZero(0.0)
                                ? Eigen::VectorXd(Z.transpose() * rhs)
                                : Eigen::VectorXd(Z.transpose() * (rhs - H * reduction_.z0));
  result_.timings.assemble_s = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  hint_ordering(A);
  solver_.factorize(A);
  result_.timings.factorize_s = solver_.stats().factorize_s;
  result_.timings.analyze_s = solver_.stats().analyze_s;
  t0 = std::chrono::steady_clock::now();
  Eigen::VectorXd y = solver_.solve(b);
  auto energy_of = [&](const Eigen::VectorXd& yy) {
    const Eigen::VectorXd xx = Z * yy + reduction_.z0;
    return std::max(0.0, xx.dot(H * xx) - 2 * rhs.dot(xx) + constant);
  };
  result_.orientation = {};
  if (options_.orientation.enabled &&
      count_foldovers(cut_.corner_wedge, Z * y + reduction_.z0) > 0) {
    // Strict orientation constraints (docs/design.md, "Orientation constraints"); when they
    // fail, the unconstrained solution stays and the report says why.
    OrientationReport& rep = result_.orientation;
    try {
      // The normal matrices of its sparse rounds hold A's pattern and face couplings: the vertex
      // order fits them as it fits A.
      const std::vector<int> ordering =
          options_.vertex_order ? vertex_order_hint(A) : std::vector<int>{};
      const Eigen::VectorXd yo = solve_oriented(mesh, g, theta, cut_.corner_wedge, reduction_, A, b,
                                                y, options_.orientation, &rep, &solver_, &ordering);
      rep.energy_before = energy_of(y);
      rep.energy_after = energy_of(yo);
      if (rep.foldovers_after < rep.foldovers_before) {
        y = yo;
        rep.success = true;
      }
    } catch (const SolverError& e) {
      rep.message = e.what();
    }
    const int folds = rep.success ? rep.foldovers_after : rep.foldovers_before;
    if (options_.orientation.untangle && folds > 0) {
      UntangleOptions uo = options_.orientation.untangle_options;
      uo.observer = options_.orientation.observer;
      const Eigen::VectorXd yu =
          untangle(g, cut_.corner_wedge, reduction_, A, b, y, uo, &rep.untangle);
      rep.time_s += rep.untangle.time_s;
      if (rep.untangle.foldovers_after < folds) {
        if (!rep.success) rep.energy_before = energy_of(y);
        y = yu;
        rep.success = true;
        rep.foldovers_after = rep.untangle.foldovers_after;
        rep.energy_after = energy_of(yu);
      }
      rep.message += (rep.message.empty() ? "" : "; ") + std::string("untangling: ") +
                     std::to_string(folds) + " -> " + std::to_string(rep.untangle.foldovers_after) +
                     " fold-over(s) in " + std::to_string(rep.untangle.newton_steps) +
                     " Newton step(s)";
    }
  }
  const Eigen::VectorXd x = Z * y + reduction_.z0;
  result_.energy = std::max(0.0, x.dot(H * x) - 2 * rhs.dot(x) + constant);  // energy_of(y)
  result_.corner_uv.resize(3 * g.n_faces);
  result_.foldovers = 0;
  for (int f = 0; f < g.n_faces; ++f) {
    for (int k = 0; k < 3; ++k) {
      const int w = cut_.corner_wedge[3 * f + k];
      result_.corner_uv[3 * f + k] = {x(2 * w), x(2 * w + 1)};
    }
    result_.foldovers += param_signed_area2(result_.corner_uv, f) <= 0;
  }
  result_.timings.solve_s = seconds_since(t0);
  return result_;
}

double ParamSolver::optimal_field_rotation(const TriMesh& mesh, const GeometryCache& g,
                                           const std::vector<double>& theta) {
  const int n = system_.variables;
  const std::vector<double> scale = target_scales(mesh, g, theta);  // rotation-invariant s
  assembly_.clear();
  Eigen::VectorXd rhs0 = Eigen::VectorXd::Zero(n), rhs1 = Eigen::VectorXd::Zero(n);
  check_face_gradients(g);
  for (int f = 0; f < g.n_faces; ++f) {
    Eigen::Matrix<double, 2, 3> G;
    double area;
    face_gradients(g, f, G, area);
    if (!options_.face_weights.empty()) area *= options_.face_weights[f];
    const Eigen::Vector2d u(std::cos(theta[f]), std::sin(theta[f])), v(-u.y(), u.x());
    const Eigen::Matrix3d Hf = area * G.transpose() * G;
    const Eigen::Vector3d gu = scale[f] * area * G.transpose() * u,
                          gv = scale[f] * area * G.transpose() * v;
    assembly_.add_face(f, Hf, Hf);
    for (int k = 0; k < 3; ++k) {
      // φ = 0: targets (u, v); φ = 90°: targets (v, −u).
      const int w = cut_.corner_wedge[3 * f + k];
      rhs0(2 * w) += gu(k);
      rhs0(2 * w + 1) += gv(k);
      rhs1(2 * w) += gv(k);
      rhs1(2 * w + 1) -= gu(k);
    }
  }
  assembly_.reduce();
  const Eigen::SparseMatrix<double>& H = assembly_.H();
  const Eigen::SparseMatrix<double>& Z = reduction_.Z;
  const Eigen::SparseMatrix<double>& A = assembly_.A();
  // x(φ) = Z y + z0 minimizes ½xᵀHx − b(φ)ᵀx with b(φ) = cos φ·rhs0 + sin φ·rhs1, so
  // E(φ) = K − F(φ) with F(φ) = ½ qᵀA⁻¹q + b(φ)ᵀz0, q = Zᵀ(b(φ) − H z0) (K: φ-independent).
  // Homogeneous constraints (z0 = 0): F is a quadratic form in (cos φ, sin φ), maximized by
  // its leading eigenvector. Prescribed lengths (ParamOptions::arc_lengths) make z0 ≠ 0: then F
  // also has linear terms and is maximized over the whole circle.
  const Eigen::VectorXd Hz0 = H * reduction_.z0;
  Eigen::MatrixXd B(Z.cols(), 3);
  B.col(0) = Z.transpose() * rhs0;
  B.col(1) = Z.transpose() * rhs1;
  B.col(2) = -(Z.transpose() * Hz0);
  hint_ordering(A);
  solver_.factorize(A);
  const Eigen::MatrixXd Y = solver_.solve(B);
  Eigen::Matrix3d M = B.transpose() * Y;
  M = 0.5 * (M + M.transpose()).eval();
  const double l0 = rhs0.dot(reduction_.z0), l1 = rhs1.dot(reduction_.z0);
  const bool homogeneous = reduction_.z0.lpNorm<Eigen::Infinity>() == 0.0;
  if (homogeneous) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M.topLeftCorner<2, 2>());
    const Eigen::Vector2d best = eig.eigenvectors().col(1);
    double phi = std::atan2(best(1), best(0));
    if (phi > M_PI / 2) phi -= M_PI;
    if (phi <= -M_PI / 2) phi += M_PI;
    return phi;
  }
  const auto F = [&](double phi) {
    const Eigen::Vector3d t(std::cos(phi), std::sin(phi), 1.0);
    return 0.5 * t.dot(M * t) + l0 * t(0) + l1 * t(1);
  };
  // Dense sampling, then golden-section refinement around the best sample.
  constexpr int kSamples = 720;
  int best = 0;
  for (int i = 1; i < kSamples; ++i)
    if (F(-M_PI + 2 * M_PI * i / kSamples) > F(-M_PI + 2 * M_PI * best / kSamples)) best = i;
  double lo = -M_PI + 2 * M_PI * (best - 1) / kSamples,
         hi = -M_PI + 2 * M_PI * (best + 1) / kSamples;
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 60; ++it) {
    const double a = hi - ratio * (hi - lo), b = lo + ratio * (hi - lo);
    if (F(a) > F(b))
      hi = b;
    else
      lo = a;
  }
  double phi = 0.5 * (lo + hi);
  if (phi > M_PI) phi -= 2 * M_PI;
  if (phi <= -M_PI) phi += 2 * M_PI;
  return phi;
}

std::vector<double> face_energies(const TriMesh& /*mesh*/, const GeometryCache& g,
                                  const std::vector<double>& theta,
                                  const std::vector<std::array<double, 2>>& uv,
                                  const ParamOptions& options,
                                  const std::vector<double>& log_scale) {
  if (!log_scale.empty() && static_cast<int>(log_scale.size()) != g.n_faces)
    throw InvalidInputError("face_energies: " + std::to_string(log_scale.size()) +
                            " sizing log-scales for " + std::to_string(g.n_faces) + " faces");
  const double aniso = options.anisotropic ? options.anisotropy : 1.0;
  std::vector<double> out(g.n_faces);
  check_face_gradients(g);
  for (int f = 0; f < g.n_faces; ++f) {
    Eigen::Matrix<double, 2, 3> G;
    double area;
    face_gradients(g, f, G, area);
    const Eigen::Vector2d u(std::cos(theta[f]), std::sin(theta[f])), v(-u.y(), u.x());
    const double sf = log_scale.empty() ? 1.0 : std::exp(log_scale[f]);
    const Eigen::Vector3d cu(uv[3 * f][0], uv[3 * f + 1][0], uv[3 * f + 2][0]);
    const Eigen::Vector3d cv(uv[3 * f][1], uv[3 * f + 1][1], uv[3 * f + 2][1]);
    const Eigen::Vector2d ru = G * cu - sf * u, rv = G * cv - sf * v;
    const Eigen::Matrix2d Wu = u * u.transpose() + aniso * v * v.transpose();
    const Eigen::Matrix2d Wv = v * v.transpose() + aniso * u * u.transpose();
    out[f] = area * (ru.dot(Wu * ru) + rv.dot(Wv * rv));
  }
  return out;
}

}  // namespace qs
