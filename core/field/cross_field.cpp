// CrossFieldSolver's setup, matrix, factorizations, solve and update_layout, and the free
// functions on fields (docs/design.md, "Cross field"). The constraint clusters are in
// cross_field_clusters.cpp, the release of contradicting constraints in cross_field_conflicts.cpp
// (cross_field_impl.h).
#include "core/field/cross_field.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/field/cross_field_impl.h"
#include "core/field/matching_repair.h"

namespace qs {

using cross_field_detail::interior;
using cross_field_detail::kQuarter;

CrossFieldSolver::CrossFieldSolver(const TriMesh& mesh, const GeometryCache& g,
                                   const Layout& layout, const LayoutTopology& topology,
                                   const CrossFieldOptions& options,
                                   const ReferenceRotation& reference_rotation)
    : options_(options) {
  const auto t_setup = std::chrono::steady_clock::now();
  FieldConstraints constraints = current_constraints(mesh, g, layout);
  field_.timings.curvature_s = seconds_since(t_setup);
  setup(mesh, g, layout, topology, std::move(constraints), 0, reference_rotation);
  field_.timings.setup_s = seconds_since(t_setup);
}

const Curvature* CrossFieldSolver::curvature_at(const TriMesh& mesh,
                                                const CurvatureOptions& options) const {
  const CurvatureCache& c = curvature_cache_;
  if (!options_.constraints.curvature || c.options != options ||
      c.points.size() != mesh.n_vertices() ||
      c.curvature.k_max.size() != static_cast<size_t>(mesh.n_faces()))
    return nullptr;
  for (auto v : mesh.vertices())
    if (c.points[v.idx()] != mesh.point(v)) return nullptr;
  return &c.curvature;
}

FieldConstraints CrossFieldSolver::current_constraints(const TriMesh& mesh, const GeometryCache& g,
                                                       const Layout& layout) {
  Curvature curvature;
  if (options_.constraints.curvature)
    curvature = update_curvature(mesh, g, options_.constraints.curvature_options, curvature_cache_);
  return collect_constraints(mesh, g, &layout, options_.constraints,
                             options_.constraints.curvature ? &curvature : nullptr);
}

void CrossFieldSolver::setup(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                             const LayoutTopology& topology, FieldConstraints constraints,
                             int tolerated, const ReferenceRotation& reference_rotation,
                             const PeriodJumpSource& period_jumps) {
  const CrossFieldOptions& options = options_;
  // Everything but the kept factorizations starts over (update_layout after the constraint set
  // changed calls this on a used solver).
  field_.constraints = std::move(constraints);
  field_.gauge_face = -1;
  field_.dropped_clusters = 0;
  field_.dropped_constraints = 0;
  gauge_angle_ = 0;
  auto t0 = std::chrono::steady_clock::now();
  field_.period_jump = period_jumps ? period_jumps(&field_.topology)
                                    : compute_period_jumps(mesh, g, layout, topology,
                                                           &field_.topology, options_.free_loops);
  field_.timings.period_jumps_s = seconds_since(t0);

  t0 = std::chrono::steady_clock::now();
  const int nf = g.n_faces;
  const int nc = static_cast<int>(field_.constraints.face.size());
  constraint_dir_ = field_.constraints.direction;

  // Clusters: constrained faces connected through the constrained faces and the faces touching
  // boundary/feature curves (the "ring" that carries the angle between alternating constrained
  // faces, docs/design.md, "Cross field").
  constraint_at_.assign(nf, -1);
  for (int k = 0; k < nc; ++k) constraint_at_[field_.constraints.face[k]] = k;
  carrier_.assign(nf, 0);
  structural_carrier_.assign(nf, 0);
  for (int k = 0; k < nc; ++k) {
    const int f = field_.constraints.face[k];
    carrier_[f] = 1;
    if (field_.constraints.kind[k] == ConstraintKind::Curvature) continue;
    for (int v : g.face_vertices[f])
      for (auto f2 : mesh.vf_range(mesh.vertex_handle(v)))
        carrier_[f2.idx()] = structural_carrier_[f2.idx()] = 1;
  }
  propagate_clusters(mesh, g, layout, topology);
  cluster_offset_.assign(field_.clusters, 0);
  cluster_active_.assign(field_.clusters, 1);
  constraint_active_.assign(nc, 1);

  // Matrix: dual-graph Laplacian + λ on constrained faces (+ a gauge face if unconstrained).
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(3 * g.n_edges + nc + 1);
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
  choose_arc_gauge(mesh, g, layout);
  if (arc_gauge_face_ >= 0) {
    if (nc == 0) {
      field_.gauge_face = arc_gauge_face_;
      gauge_angle_ = arc_gauge_angle_;
      triplets.emplace_back(field_.gauge_face, field_.gauge_face, lambda);
    }
  }
  matrix_.resize(nf, nf);
  matrix_.setFromTriplets(triplets.begin(), triplets.end());
  field_.timings.assemble_s = seconds_since(t0);

  // Kept for update_layout, which starts again from every constraint (shared with solver_ until
  // a drop pass factorizes: SpdSolver copies are copy-on-write).
  full_matrix_ = matrix_;
  full_gauge_face_ = field_.gauge_face;
  full_factorized_ = false;
  current_ = false;
  // The only factorization needed when no cluster contradicts the layout, made by the first
  // solve: in split mode the structural pass and the deviation release change the matrix
  // before it (one factorization for both).
  settle_and_warm_start(mesh, g, tolerated, /*allow_factorization=*/true, reference_rotation);
  residual_mismatches_ = count_mismatches(g);
  field_.active_constraints = nc - field_.dropped_constraints;
  repair_matching(g);
}

CrossFieldSolver::~CrossFieldSolver() = default;

void CrossFieldSolver::settle_and_warm_start(const TriMesh& mesh, const GeometryCache& g,
                                             int tolerated, bool allow_factorization,
                                             const ReferenceRotation& reference_rotation) {
  const bool structural =
      drop_structural_conflicts(mesh, g, tolerated, allow_factorization, reference_rotation);
  if (structural) {
    // The feature and boundary clusters keep the rotations their pass settled; the curvature
    // clusters start from the layout's own field (the warm start's reference), else from the
    // field the feature and boundary constraints alone hold (the pass's last solve).
    std::vector<char> curvature(field_.clusters, 0);
    for (int k = 0; k < static_cast<int>(field_.constraints.face.size()); ++k)
      if (is_curvature(k)) curvature[cluster_of_[k]] = 1;
    const Eigen::VectorXd theta =
        reference_theta_.size() == g.n_faces
            ? reference_theta_
            : Eigen::Map<const Eigen::VectorXd>(field_.theta.data(), g.n_faces);
    round_clusters(constraint_angles(g), theta, &curvature);
  } else {
    warm_start(g, allow_factorization, reference_rotation);
  }
  release_deviating_clusters(g);
  solve_system(g);
  // After the structural pass only curvature clusters are released: the feature and boundary
  // constraints it kept agree with the layout.
  drop_conflicting_clusters(mesh, g, tolerated, /*curvature_only=*/structural);
}

void CrossFieldSolver::choose_arc_gauge(const TriMesh& mesh, const GeometryCache& g,
                                        const Layout& layout) {
  arc_gauge_face_ = -1;
  arc_gauge_angle_ = 0;
  if (layout.arcs.empty()) return;
  // A face next to the middle of the longest arc, along that arc (away from nodes).
  int best_arc = 0;
  for (size_t a = 0; a < layout.arcs.size(); ++a)
    if (layout.arcs[a].path.size() > layout.arcs[best_arc].path.size())
      best_arc = static_cast<int>(a);
  const auto& path = layout.arcs[best_arc].path;
  const size_t m = (path.size() - 1) / 2;
  const auto h = mesh.find_halfedge(mesh.vertex_handle(path[m]), mesh.vertex_handle(path[m + 1]));
  const auto fh = mesh.is_boundary(h) ? mesh.face_handle(mesh.opposite_halfedge_handle(h))
                                      : mesh.face_handle(h);
  arc_gauge_face_ = fh.idx();
  arc_gauge_angle_ = g.angle_in_face(arc_gauge_face_, mesh.point(mesh.vertex_handle(path[m + 1])) -
                                                          mesh.point(mesh.vertex_handle(path[m])));
}

void CrossFieldSolver::factorize(SpdSolver& solver, const Eigen::SparseMatrix<double>& A) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!solver.same_pattern(A)) {
    // Every matrix of this stage has the pattern of the dual graph (constraints only change
    // the diagonal): the other solver's analysis is reused instead of ordering again.
    SpdSolver& other = &solver == &solver_ ? spare_ : solver_;
    if (other.same_pattern(A)) solver.copy_analysis_from(other);
  }
  solver.factorize(A);
  field_.timings.factorize_s += seconds_since(t0);
  ++field_.timings.factorizations;
}

void CrossFieldSolver::factorize_as_current() {
  factorize(spare_, matrix_);
  std::swap(solver_, spare_);
  current_ = true;
}

void CrossFieldSolver::make_current() {
  if (current_) return;
  factorize_as_current();
  if (!full_factorized_ && field_.dropped_constraints == 0 &&
      field_.gauge_face == full_gauge_face_) {
    full_ = solver_;  // shared (copy-on-write): update_layout starts from it
    full_factorized_ = true;
  }
}

void CrossFieldSolver::pin_gauge_if_unconstrained(const Eigen::VectorXd* theta) {
  if (field_.gauge_face >= 0) return;
  for (int k = 0; k < static_cast<int>(field_.constraints.face.size()); ++k)
    if (active(k)) return;
  // Nothing left to fix the global rotation on a closed surface: pin one face (it is re-chosen
  // to minimize the energy by the parameterization stage).
  field_.gauge_face = field_.constraints.face[0];
  gauge_angle_ = theta ? (*theta)(field_.gauge_face) : field_.theta[field_.gauge_face];
  matrix_.coeffRef(field_.gauge_face, field_.gauge_face) += options_.constraint_weight;
}

void CrossFieldSolver::recount_dropped_clusters() {
  // A cluster counts as dropped when none of its constraints is in force any more.
  std::vector<char> any_active(field_.clusters, 0);
  for (int k = 0; k < static_cast<int>(field_.constraints.face.size()); ++k)
    if (active(k)) any_active[cluster_of_[k]] = 1;
  field_.dropped_clusters = 0;
  for (int cl = 0; cl < field_.clusters; ++cl) {
    cluster_active_[cl] = any_active[cl];
    field_.dropped_clusters += !any_active[cl];
  }
}

Eigen::VectorXd CrossFieldSolver::back_substitute(const Eigen::VectorXd& b) {
  ++field_.timings.solves;
  return solver_.solve(b);
}

double CrossFieldSolver::energy(const GeometryCache& g) const {
  double e = 0;
  for (int edge = 0; edge < g.n_edges; ++edge) {
    if (!interior(g, edge)) continue;
    const double d = field_.theta[g.edge_face_j[edge]] - field_.theta[g.edge_face_i[edge]] -
                     g.kappa[edge] - kQuarter * field_.period_jump[edge];
    e += d * d;
  }
  const double lambda = options_.constraint_weight;
  const std::vector<double> c = constraint_angles(g);
  for (size_t k = 0; k < c.size(); ++k) {
    if (!active(k)) continue;
    const int q = relative_q_[k] + cluster_offset_[cluster_of_[k]];
    const double d = field_.theta[field_.constraints.face[k]] - (c[k] + kQuarter * q);
    e += lambda * d * d;
  }
  if (field_.gauge_face >= 0) {
    const double d = field_.theta[field_.gauge_face] - gauge_angle_;
    e += lambda * d * d;
  }
  return e;
}

std::vector<double> CrossFieldSolver::constraint_angles(const GeometryCache& g) const {
  const int nc = static_cast<int>(field_.constraints.face.size());
  std::vector<double> c(nc);
  for (int k = 0; k < nc; ++k)
    c[k] = g.angle_in_face(field_.constraints.face[k], constraint_dir_[k]);
  return c;
}

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
    if (!active(k)) continue;
    const int q = relative_q_[k] + cluster_offset_[cluster_of_[k]];
    b(field_.constraints.face[k]) += lambda * (c[k] + kQuarter * q);
  }
  if (field_.gauge_face >= 0) b(field_.gauge_face) += lambda * gauge_angle_;
  return b;
}

void CrossFieldSolver::round_clusters(const std::vector<double>& c, const Eigen::VectorXd& theta,
                                      const std::vector<char>* only) {
  std::vector<double> sum(field_.clusters, 0.0), weight(field_.clusters, 0.0);
  for (size_t k = 0; k < c.size(); ++k) {
    if (!constraint_active_[k]) continue;  // released faces (a dropped cluster still rounds)
    const int f = field_.constraints.face[k];
    const int cl = cluster_of_[k];
    if (only && !(*only)[cl]) continue;
    // Offset of the cluster rotation that best matches θ here, in quarter turns.
    sum[cl] += (theta(f) - c[k]) / kQuarter - relative_q_[k];
    weight[cl] += 1;
  }
  for (int cl = 0; cl < field_.clusters; ++cl)
    if (weight[cl] > 0) cluster_offset_[cl] = static_cast<int>(std::lround(sum[cl] / weight[cl]));
}

const CrossField& CrossFieldSolver::solve(const GeometryCache& g) {
  solve_system(g);
  repair_matching(g);
  return field_;
}

void CrossFieldSolver::repair_matching(const GeometryCache& g) {
  // The faces the constraints in force (and the gauge) hold keep their θ.
  std::vector<char> fixed(g.n_faces, 0);
  for (size_t k = 0; k < field_.constraints.face.size(); ++k)
    if (active(static_cast<int>(k))) fixed[field_.constraints.face[k]] = 1;
  if (field_.gauge_face >= 0) fixed[field_.gauge_face] = 1;
  repair_principal_matching(g, field_.period_jump, fixed, field_.theta);
}

const CrossField& CrossFieldSolver::solve_system(const GeometryCache& g) {
  if (g.n_faces != matrix_.rows())
    throw InvalidInputError("cross field: the geometry has " + std::to_string(g.n_faces) +
                            " faces, the solver was built for " + std::to_string(matrix_.rows()));
  make_current();  // timed as a factorization
  const auto t0 = std::chrono::steady_clock::now();
  const int nc = static_cast<int>(field_.constraints.face.size());
  const std::vector<double> c = constraint_angles(g);
  Eigen::VectorXd theta = back_substitute(rhs(g, c));
  field_.timings.rounding_passes = 0;
  for (int pass = 0; nc > 0 && pass < options_.max_rounding_passes; ++pass) {
    const std::vector<int> before = cluster_offset_;
    round_clusters(c, theta);
    if (before == cluster_offset_) break;
    theta = back_substitute(rhs(g, c));
    ++field_.timings.rounding_passes;
  }
  field_.theta.assign(theta.data(), theta.data() + theta.size());
  field_.constraint_q.resize(nc);
  for (int k = 0; k < nc; ++k)
    field_.constraint_q[k] = relative_q_[k] + cluster_offset_[cluster_of_[k]];
  field_.constraint_active.resize(nc);
  for (int k = 0; k < nc; ++k) field_.constraint_active[k] = active(k) ? 1 : 0;
  field_.timings.solve_s = seconds_since(t0);
  return field_;
}

const CrossField& CrossFieldSolver::update_layout(const TriMesh& mesh, const GeometryCache& g,
                                                  const Layout& layout,
                                                  const LayoutTopology& topology,
                                                  const PeriodJumpSource& period_jumps) {
  if (g.n_faces != matrix_.rows() || static_cast<int>(mesh.n_faces()) != g.n_faces)
    throw InvalidInputError("cross field: the mesh changed size since the solver was built");
  auto t0 = std::chrono::steady_clock::now();
  // The constraints of the current geometry and layout, as a fresh construction collects them
  // (relocated vertices change the curvature around them, re-routed arcs the boundary faces).
  FieldConstraints constraints = current_constraints(mesh, g, layout);
  field_.timings.curvature_s = seconds_since(t0);
  if (constraints.face != field_.constraints.face || constraints.kind != field_.constraints.kind) {
    // Another constraint set: other clusters and another matrix diagonal. Set up as the
    // constructor does; the analyses (same pattern) and the reference factorization are kept.
    // Its drop passes tolerate as many mismatching edges as the previous solve left, as the
    // same-face path below does: a pass would not remove them, and each costs a factorization.
    // (A fresh construction drops until a pass stops helping.)
    setup(mesh, g, layout, topology, std::move(constraints), residual_mismatches_, {},
          period_jumps);
    return field_;
  }
  // Same faces: only the directions moved (the matrix and the clusters are unchanged).
  field_.constraints.direction = constraints.direction;
  constraint_dir_ = std::move(constraints.direction);
  t0 = std::chrono::steady_clock::now();
  field_.period_jump = period_jumps ? period_jumps(&field_.topology)
                                    : compute_period_jumps(mesh, g, layout, topology,
                                                           &field_.topology, options_.free_loops);
  field_.timings.period_jumps_s = seconds_since(t0);
  // Cluster membership depends on the constraint set only; the relative rotations on p.
  const std::vector<int> old_cluster = cluster_of_;
  propagate_clusters(mesh, g, layout, topology);
  if (cluster_of_ != old_cluster)
    throw QsError("internal error: constraint clusters changed in update_layout");
  choose_arc_gauge(mesh, g, layout);
  // Every constraint in force again, as in the constructor (the construction's factorization):
  // clusters dropped for the previous layout may agree with this one.
  const int nc = static_cast<int>(field_.constraints.face.size());
  if (nc > 0 && field_.dropped_constraints > 0) {
    matrix_ = full_matrix_;
    // Not factorized yet: the next solve factorizes.
    current_ = full_factorized_;
    if (full_factorized_) solver_ = full_;
    cluster_active_.assign(field_.clusters, 1);
    constraint_active_.assign(nc, 1);
    field_.dropped_constraints = 0;
    field_.dropped_clusters = 0;
    field_.gauge_face = full_gauge_face_;
  }
  // Clusters that contradict the new layout (steps across edges that disagree with the new
  // period jumps) are dropped as in the constructor; this factorizes only when there are any.
  // As many mismatches as the constructor's passes left (the smoothest field itself turns by
  // more than 45° there) are tolerated: a pass would not remove them.
  settle_and_warm_start(mesh, g, residual_mismatches_, /*allow_factorization=*/false);
  field_.active_constraints =
      static_cast<int>(field_.constraints.face.size()) - field_.dropped_constraints;
  repair_matching(g);
  return field_;
}

void CrossFieldSolver::unshare_solvers() {
  for (SpdSolver* s : {&solver_, &spare_, &reference_, &full_, &structural_}) s->unshare();
}

void CrossFieldSolver::rotate(double phi) {
  for (double& t : field_.theta) t += phi;
  if (field_.gauge_face >= 0) gauge_angle_ += phi;
}

CrossField compute_cross_field(const TriMesh& mesh, const GeometryCache& geometry,
                               const Layout& layout, const LayoutTopology& topology,
                               const CrossFieldOptions& options) {
  CrossFieldSolver solver(mesh, geometry, layout, topology, options);
  return solver.field();
}

ConstraintSummary summarize_constraints(const CrossField& field) {
  ConstraintSummary s;
  const FieldConstraints& c = field.constraints;
  for (size_t k = 0; k < c.face.size() && k < c.kind.size(); ++k) {
    const int kind = static_cast<int>(c.kind[k]);
    if (kind < 0 || kind > 2) continue;
    ++s.constrained[kind];
    // Before the first solve constraint_active is empty: every constraint is in force then.
    if (k >= field.constraint_active.size() || field.constraint_active[k]) ++s.in_force[kind];
  }
  s.clusters = field.clusters;
  s.dropped_clusters = field.dropped_clusters;
  return s;
}

std::string released_constraints_warning(const CrossField& field, double min_in_force) {
  const ConstraintSummary s = summarize_constraints(field);
  const int total = s.total_constrained(), in_force = s.total_in_force();
  if (total == 0 || in_force >= min_in_force * total) return {};
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.1f", 100.0 * in_force / total);
  const std::string clusters = s.dropped_clusters > 0
                                   ? " (" + std::to_string(s.dropped_clusters) + " of " +
                                         std::to_string(s.clusters) + " constraint clusters)"
                                   : "";
  return std::to_string(in_force) + " of " + std::to_string(total) + " constrained faces (" +
         percent + " %) are in force: the others contradict the layout's topology and were " +
         "released" + clusters +
         ", so the field follows the layout rather than the curvature and features there (a "
         "layout whose arcs follow them keeps more)";
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
