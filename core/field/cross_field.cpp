#include "core/field/cross_field.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>

#include "core/base/errors.h"

namespace qs {

namespace {

constexpr double kQuarter = M_PI / 2;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

bool interior(const GeometryCache& g, int e) {
  return g.edge_face_i[e] >= 0 && g.edge_face_j[e] >= 0;
}

}  // namespace

CrossFieldSolver::CrossFieldSolver(const TriMesh& mesh, const GeometryCache& g,
                                   const Layout& layout, const LayoutTopology& topology,
                                   const CrossFieldOptions& options)
    : options_(options) {
  auto t0 = std::chrono::steady_clock::now();
  Curvature curvature;
  if (options.constraints.curvature)
    curvature = compute_curvature(mesh, g, options.constraints.curvature_options);
  field_.constraints = collect_constraints(mesh, g, &layout, options.constraints,
                                           options.constraints.curvature ? &curvature : nullptr);
  field_.timings.curvature_s = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  field_.period_jump = compute_period_jumps(mesh, g, layout, topology, &field_.topology);
  field_.timings.period_jumps_s = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  const int nf = g.n_faces;
  const int nc = static_cast<int>(field_.constraints.face.size());
  constraint_dir_ = field_.constraints.direction;

  // Clusters: BFS over constrained faces and the faces touching boundary/feature curves (the
  // "ring" that carries the angle between alternating constrained faces, algorithm.md §3.2).
  std::vector<int> constraint_at(nf, -1);
  for (int k = 0; k < nc; ++k) constraint_at[field_.constraints.face[k]] = k;
  std::vector<char> carrier(nf, 0);
  for (int k = 0; k < nc; ++k) {
    const int f = field_.constraints.face[k];
    carrier[f] = 1;
    if (field_.constraints.kind[k] == ConstraintKind::Curvature) continue;
    for (auto v : mesh.fv_range(mesh.face_handle(f)))
      for (auto f2 : mesh.vf_range(v)) carrier[f2.idx()] = 1;
  }
  std::vector<double> c(nc);
  for (int k = 0; k < nc; ++k)
    c[k] = g.angle_in_face(field_.constraints.face[k], constraint_dir_[k]);
  cluster_of_.assign(nc, -1);
  relative_q_.assign(nc, 0);
  std::vector<double> carried(nf, 0.0);
  std::vector<char> visited(nf, 0);
  std::vector<int> cluster_size;
  for (int k0 = 0; k0 < nc; ++k0) {
    const int f0 = field_.constraints.face[k0];
    if (visited[f0]) continue;
    const int cl = static_cast<int>(cluster_size.size());
    cluster_size.push_back(0);
    visited[f0] = 1;
    carried[f0] = c[k0];
    std::deque<int> queue{f0};
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      const int k = constraint_at[f];
      if (k >= 0) {
        relative_q_[k] = static_cast<int>(std::lround((carried[f] - c[k]) / kQuarter));
        carried[f] = c[k] + kQuarter * relative_q_[k];
        cluster_of_[k] = cl;
        ++cluster_size[cl];
      }
      for (auto h : mesh.fh_range(mesh.face_handle(f))) {
        const auto opp = mesh.opposite_halfedge_handle(h);
        if (mesh.is_boundary(opp)) continue;
        const int f2 = mesh.face_handle(opp).idx();
        if (visited[f2] || !carrier[f2]) continue;
        const int e = mesh.edge_handle(h).idx();
        const double step = g.kappa[e] + kQuarter * field_.period_jump[e];
        carried[f2] = (g.edge_face_i[e] == f) ? carried[f] + step : carried[f] - step;
        visited[f2] = 1;
        queue.push_back(f2);
      }
    }
  }
  field_.clusters = static_cast<int>(cluster_size.size());
  cluster_offset_.assign(field_.clusters, 0);
  cluster_active_.assign(field_.clusters, 1);

  // Matrix: dual-graph Laplacian + λ on constrained faces (+ a gauge face if unconstrained).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(4 * g.n_edges + nc + 1);
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior(g, e)) continue;
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    triplets.emplace_back(i, i, 1.0);
    triplets.emplace_back(j, j, 1.0);
    triplets.emplace_back(std::max(i, j), std::min(i, j), -1.0);
  }
  const double lambda = options.constraint_weight;
  for (int k = 0; k < nc; ++k)
    triplets.emplace_back(field_.constraints.face[k], field_.constraints.face[k], lambda);
  if (nc == 0) {
    // Gauge: pin a face next to the middle of the longest arc, along that arc (away from nodes).
    int best_arc = 0;
    for (size_t a = 0; a < layout.arcs.size(); ++a)
      if (layout.arcs[a].path.size() > layout.arcs[best_arc].path.size())
        best_arc = static_cast<int>(a);
    const auto& path = layout.arcs[best_arc].path;
    const size_t m = (path.size() - 1) / 2;
    const auto h = mesh.find_halfedge(mesh.vertex_handle(path[m]), mesh.vertex_handle(path[m + 1]));
    const auto fh = mesh.is_boundary(h) ? mesh.face_handle(mesh.opposite_halfedge_handle(h))
                                        : mesh.face_handle(h);
    field_.gauge_face = fh.idx();
    triplets.emplace_back(field_.gauge_face, field_.gauge_face, lambda);
    gauge_angle_.resize(1);
    gauge_angle_(0) =
        g.angle_in_face(field_.gauge_face, mesh.point(mesh.vertex_handle(path[m + 1])) -
                                               mesh.point(mesh.vertex_handle(path[m])));
  }
  Eigen::SparseMatrix<double> L(nf, nf);
  L.setFromTriplets(triplets.begin(), triplets.end());
  field_.timings.assemble_s = seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  if (field_.clusters > 1) {
    // Warm start for the cluster rotations: the smoothest field held only by the largest
    // cluster (same pattern, so the symbolic analysis is shared), then round every other
    // cluster against it (algorithm.md §3.2).
    const int largest = static_cast<int>(
        std::max_element(cluster_size.begin(), cluster_size.end()) - cluster_size.begin());
    Eigen::SparseMatrix<double> L0 = L;
    for (int k = 0; k < nc; ++k)
      if (cluster_of_[k] != largest)
        L0.coeffRef(field_.constraints.face[k], field_.constraints.face[k]) -= lambda;
    solver_.factorize(L0);
    Eigen::VectorXd b = rhs(g, c);
    // rhs() added λ·target for every constraint; only the largest cluster's stay.
    for (int k = 0; k < nc; ++k) {
      if (cluster_of_[k] == largest) continue;
      const int q = relative_q_[k] + cluster_offset_[cluster_of_[k]];
      b(field_.constraints.face[k]) -= lambda * (c[k] + kQuarter * q);
    }
    const Eigen::VectorXd theta0 = solver_.solve(b);
    round_clusters(g, c, theta0);
  }
  solver_.factorize(L);
  solve(g);
  // Drop constraint clusters that contradict the layout's topology, then re-solve.
  int rings = options.conflict_rings;
  auto count_mismatches = [&] {
    const std::vector<int> m = principal_matching(g, field_.theta);
    int bad = 0;
    for (int e = 0; e < g.n_edges; ++e) bad += interior(g, e) && m[e] != field_.period_jump[e];
    return bad;
  };
  int mismatches = count_mismatches();
  for (int pass = 0; pass < options.max_conflict_passes && nc > 0 && mismatches > 0; ++pass) {
    const std::vector<int> matching = principal_matching(g, field_.theta);
    std::vector<int> dist(nf, -1);
    std::deque<int> queue;
    for (int e = 0; e < g.n_edges; ++e) {
      if (!interior(g, e) || matching[e] == field_.period_jump[e]) continue;
      for (int f : {g.edge_face_i[e], g.edge_face_j[e]})
        if (dist[f] < 0) dist[f] = 0, queue.push_back(f);
    }
    if (queue.empty()) break;
    std::vector<int> drop;
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      const int k = constraint_at[f];
      if (k >= 0 && cluster_active_[cluster_of_[k]] &&
          std::find(drop.begin(), drop.end(), cluster_of_[k]) == drop.end())
        drop.push_back(cluster_of_[k]);
      if (dist[f] >= rings) continue;
      for (auto h : mesh.fh_range(mesh.face_handle(f))) {
        const auto opp = mesh.opposite_halfedge_handle(h);
        if (mesh.is_boundary(opp)) continue;
        const int f2 = mesh.face_handle(opp).idx();
        if (dist[f2] < 0) dist[f2] = dist[f] + 1, queue.push_back(f2);
      }
    }
    if (drop.empty()) {
      // The conflicting clusters are farther away: widen the search (bounded).
      if (rings >= 64 * options.conflict_rings) break;
      rings *= 4;
      --pass;
      continue;
    }
    for (int cl : drop) {
      cluster_active_[cl] = 0;
      ++field_.dropped_clusters;
    }
    for (int k = 0; k < nc; ++k) {
      if (cluster_active_[cluster_of_[k]] ||
          std::find(drop.begin(), drop.end(), cluster_of_[k]) == drop.end())
        continue;
      L.coeffRef(field_.constraints.face[k], field_.constraints.face[k]) -= lambda;
      ++field_.dropped_constraints;
    }
    if (std::find(cluster_active_.begin(), cluster_active_.end(), 1) == cluster_active_.end() &&
        field_.gauge_face < 0) {
      // Nothing left to fix the global rotation on a closed surface: pin one face (it is
      // re-chosen to minimize the energy by the parameterization stage).
      field_.gauge_face = field_.constraints.face[0];
      gauge_angle_.resize(1);
      gauge_angle_(0) = field_.theta[field_.gauge_face];
      L.coeffRef(field_.gauge_face, field_.gauge_face) += lambda;
    }
    solver_.factorize(L);
    solve(g);
    const int now = count_mismatches();
    if (now >= mismatches) {
      // Dropping did not help: these steps are not caused by constraints (e.g. the smoothest
      // field itself turns by more than 45° across an edge). Restore the clusters and stop.
      for (int cl : drop) {
        cluster_active_[cl] = 1;
        --field_.dropped_clusters;
      }
      for (int k = 0; k < nc; ++k) {
        if (std::find(drop.begin(), drop.end(), cluster_of_[k]) == drop.end()) continue;
        L.coeffRef(field_.constraints.face[k], field_.constraints.face[k]) += lambda;
        --field_.dropped_constraints;
      }
      solver_.factorize(L);
      solve(g);
      break;
    }
    mismatches = now;
  }
  field_.active_constraints = nc - field_.dropped_constraints;
  field_.timings.factorize_s = seconds_since(t0);
}

CrossFieldSolver::~CrossFieldSolver() = default;

Eigen::VectorXd CrossFieldSolver::rhs(const GeometryCache& g, const std::vector<double>& c) const {
  Eigen::VectorXd b = Eigen::VectorXd::Zero(g.n_faces);
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior(g, e)) continue;
    const double k = g.kappa[e] + kQuarter * field_.period_jump[e];
    b(g.edge_face_i[e]) -= k;
    b(g.edge_face_j[e]) += k;
  }
  const double lambda = options_.constraint_weight;
  for (size_t k = 0; k < c.size(); ++k) {
    if (!cluster_active_[cluster_of_[k]]) continue;
    const int q = relative_q_[k] + cluster_offset_[cluster_of_[k]];
    b(field_.constraints.face[k]) += lambda * (c[k] + kQuarter * q);
  }
  if (field_.gauge_face >= 0) b(field_.gauge_face) += lambda * gauge_angle_(0);
  return b;
}

void CrossFieldSolver::round_clusters(const GeometryCache& g, const std::vector<double>& c,
                                      const Eigen::VectorXd& theta) {
  (void)g;
  std::vector<double> sum(field_.clusters, 0.0), weight(field_.clusters, 0.0);
  for (size_t k = 0; k < c.size(); ++k) {
    const int f = field_.constraints.face[k];
    const int cl = cluster_of_[k];
    // Offset of the cluster rotation that best matches θ here, in quarter turns.
    double d = (theta(f) - c[k]) / kQuarter - relative_q_[k];
    sum[cl] += d;
    weight[cl] += 1;
  }
  for (int cl = 0; cl < field_.clusters; ++cl)
    if (weight[cl] > 0) cluster_offset_[cl] = static_cast<int>(std::lround(sum[cl] / weight[cl]));
}

const CrossField& CrossFieldSolver::solve(const GeometryCache& g) {
  const auto t0 = std::chrono::steady_clock::now();
  const int nc = static_cast<int>(field_.constraints.face.size());
  std::vector<double> c(nc);
  for (int k = 0; k < nc; ++k)
    c[k] = g.angle_in_face(field_.constraints.face[k], constraint_dir_[k]);
  Eigen::VectorXd theta;
  if (nc == 0) {
    theta = solver_.solve(rhs(g, c));
  } else {
    theta = solver_.solve(rhs(g, c));
    for (int pass = 0; pass < options_.max_rounding_passes; ++pass) {
      const std::vector<int> before = cluster_offset_;
      round_clusters(g, c, theta);
      if (before == cluster_offset_) break;
      theta = solver_.solve(rhs(g, c));
    }
  }
  solved_once_ = true;
  field_.theta.assign(theta.data(), theta.data() + theta.size());
  field_.constraint_q.resize(nc);
  for (int k = 0; k < nc; ++k)
    field_.constraint_q[k] = relative_q_[k] + cluster_offset_[cluster_of_[k]];
  field_.timings.solve_s = seconds_since(t0);
  return field_;
}

void CrossFieldSolver::rotate(double phi) {
  for (double& t : field_.theta) t += phi;
  if (field_.gauge_face >= 0) gauge_angle_(0) += phi;
}

CrossField compute_cross_field(const TriMesh& mesh, const GeometryCache& geometry,
                               const Layout& layout, const LayoutTopology& topology,
                               const CrossFieldOptions& options) {
  CrossFieldSolver solver(mesh, geometry, layout, topology, options);
  return solver.field();
}

std::vector<int> principal_matching(const GeometryCache& g, const std::vector<double>& theta) {
  std::vector<int> p(g.n_edges, 0);
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior(g, e)) continue;
    const double d = theta[g.edge_face_j[e]] - theta[g.edge_face_i[e]] - g.kappa[e];
    p[e] = static_cast<int>(std::lround(d / kQuarter));
  }
  return p;
}

std::vector<int> field_quarter_indices(const GeometryCache& g, const std::vector<double>& theta) {
  std::vector<double> sum(g.n_vertices, 0.0);
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior(g, e)) continue;
    const double d = theta[g.edge_face_j[e]] - theta[g.edge_face_i[e]] - g.kappa[e];
    const double eps = d - kQuarter * std::round(d / kQuarter);  // rotation against transport
    const auto [a, b] = g.edge_vertices[e];
    // ccw step around a crosses e along the orientation iff b < a.
    sum[a] += (b < a ? 1 : -1) * eps;
    sum[b] += (a < b ? 1 : -1) * eps;
  }
  std::vector<int> idx(g.n_vertices, 0);
  for (int v = 0; v < g.n_vertices; ++v) {
    if (g.vertex_on_boundary[v]) continue;
    idx[v] = static_cast<int>(std::lround(4 * (g.angle_defect[v] + sum[v]) / (2 * M_PI)));
  }
  return idx;
}

std::vector<Vec3> field_directions(const GeometryCache& g, const std::vector<double>& theta) {
  std::vector<Vec3> d(g.n_faces);
  for (int f = 0; f < g.n_faces; ++f) d[f] = g.direction_in_face(f, theta[f]);
  return d;
}

}  // namespace qs
