#include "core/field/cross_field.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/field/matching_repair.h"

namespace qs {

namespace {

constexpr double kQuarter = M_PI / 2;

bool interior(const GeometryCache& g, int e) {
  return g.edge_face_i[e] >= 0 && g.edge_face_j[e] >= 0;
}

}  // namespace

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

namespace {

// Quarter turns of the boundary constraints on the boundary loops that layout arcs cover
// entirely (aligned boundaries, docs/design.md, "Cross field"), as the layout prescribes them.
//
// Rounding each constraint against the angle carried to it (propagate_clusters' rule) lets the
// field follow the tangent through smooth stretches and keep its direction through sharp
// turns: right when the layout's boundary corners sit on the mesh's corners, wrong otherwise (a
// corner node on a smooth stretch of face.obj's rim, or an arc around a square's corner, gave
// E 180–2500 and thousands of fold-overs). The layout fixes it exactly: walking the loop with
// the interior on the left, the tangent turns against the field by (2 − s)·90° at a node with
// s interior sectors (s = valence − 1) and not at all elsewhere, so the field turns against the
// transport by τ − (2 − s)·90° (τ: the boundary's turn at the vertex, its geodesic curvature).
// Writing the field on each boundary edge as tangent + m·90°, m changes across vertex w by
// P_w − (2 − s_w), with P_w the period jumps crossed around w: integers, no rounding.
//
// Result per constraint: its quarter turn relative to the first constraint of its loop in the
// walk (INT_MIN off such loops), and the loop's index (-1 off them). A loop whose m does not
// come back to its start (a layout whose boundary turning contradicts the period jumps) keeps
// the rounding rule.
void aligned_boundary_turns(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                            const LayoutTopology& topology, const std::vector<int>& period_jump,
                            const std::vector<int>& constraint_at, const std::vector<double>& c,
                            std::vector<int>& preset_q, std::vector<int>& loop_of) {
  const int nc = static_cast<int>(c.size());
  preset_q.assign(nc, INT_MIN);
  loop_of.assign(nc, -1);
  const std::vector<char> on_arc = arc_edge_mask(mesh, layout);
  std::vector<int> turn(mesh.n_vertices(), 0);  // 2 − s at boundary node vertices
  for (size_t n = 0; n < layout.nodes.size() && n < topology.valence.size(); ++n) {
    const auto vh = mesh.vertex_handle(layout.nodes[n].vertex);
    if (mesh.is_boundary(vh)) turn[vh.idx()] = 2 - (topology.valence[n] - 1);
  }
  // Carries angle a from face f across edge e (κ, plus the period jump when with_p).
  auto carry = [&](double a, int f, int e, bool with_p) {
    const double step = g.kappa[e] + (with_p ? kQuarter * period_jump[e] : 0.0);
    return g.edge_face_i[e] == f ? a + step : a - step;
  };
  auto wrap = [](double a) { return a - 2 * M_PI * std::round(a / (2 * M_PI)); };
  std::vector<char> done(mesh.n_halfedges(), 0);
  int loops = 0;
  for (auto start : mesh.halfedges()) {
    // Face-side halfedges of boundary edges: the interior on their left.
    if (done[start.idx()] || mesh.is_boundary(start) ||
        !mesh.is_boundary(mesh.opposite_halfedge_handle(start)))
      continue;
    std::vector<OpenMesh::SmartHalfedgeHandle> walk;  // the loop in order
    bool covered = true;
    for (auto h = start;;) {
      done[h.idx()] = 1;
      walk.push_back(h);
      covered = covered && on_arc[h.edge().idx()];
      // The next boundary edge at h's end: around to_vertex through the interior faces.
      auto cur = h;
      while (!mesh.is_boundary(cur.next().opp())) cur = cur.next().opp();
      h = cur.next();
      if (h == start || walk.size() > mesh.n_halfedges()) break;
    }
    if (!covered) continue;
    // m per visited boundary edge: the field is the edge's tangent + m·90° in its face.
    std::vector<std::pair<int, int>> q;  // (constraint, its quarter turn relative to the start)
    double phi = 0, tangent = 0;         // field and tangent angles in the current face
    int face = -1, m = 0;
    bool ok = true;
    for (size_t i = 0; i <= walk.size() && ok; ++i) {
      const auto h = walk[i % walk.size()];
      const int f = h.face().idx();
      const Vec3 d = mesh.point(h.to()) - mesh.point(h.from());
      const double t = g.angle_in_face(f, d);
      if (face < 0) {
        m = 0;
      } else {
        // Around h.from() from the previous edge's face to f, carrying the field (with p) and
        // the tangent (without).
        auto cur = walk[i - 1];
        int at = face;
        while (cur.face().idx() != f) {
          const auto out = cur.next();
          const int e = out.edge().idx();
          phi = carry(phi, at, e, true);
          tangent = carry(tangent, at, e, false);
          cur = out.opp();
          at = cur.face().idx();
          if (cur.is_boundary()) {
            ok = false;
            break;
          }
        }
        if (!ok) break;
        const double tau = wrap(t - tangent);
        const double next = phi + tau - kQuarter * turn[h.from().idx()];
        m = static_cast<int>(std::lround((next - t) / kQuarter));
        if (i == walk.size()) {
          ok = m == 0;  // back at the start: the loop closes
          break;
        }
      }
      face = f;
      tangent = t;
      phi = t + kQuarter * m;
      const int k = constraint_at[f];
      if (k < 0) continue;
      // The face's constraint follows this edge (a face with two boundary edges follows one).
      if (std::abs(std::sin(c[k] - t)) > 1e-6) continue;
      q.push_back({k, static_cast<int>(std::lround((phi - c[k]) / kQuarter))});
    }
    if (!ok) continue;
    for (const auto& [k, qk] : q) {
      preset_q[k] = qk;
      loop_of[k] = loops;
    }
    ++loops;
  }
}

}  // namespace

void CrossFieldSolver::propagate_clusters(const TriMesh& mesh, const GeometryCache& g,
                                          const Layout& layout, const LayoutTopology& topology) {
  const int nf = g.n_faces;
  const int nc = static_cast<int>(field_.constraints.face.size());
  const std::vector<double> c = constraint_angles(g);
  std::vector<int> preset_q, loop_of;
  aligned_boundary_turns(mesh, g, layout, topology, field_.period_jump, constraint_at_, c, preset_q,
                         loop_of);
  // Per aligned loop: its presets' offset in the cluster reached first (INT_MIN: not yet).
  std::vector<int> loop_offset;
  for (int l : loop_of)
    if (l >= static_cast<int>(loop_offset.size())) loop_offset.resize(l + 1, INT_MIN);
  cluster_of_.assign(nc, -1);
  relative_q_.assign(nc, 0);
  cluster_size_.clear();
  std::vector<double> carried(nf, 0.0);
  std::vector<char> visited(nf, 0);
  std::vector<int> queue;
  queue.reserve(nf);
  const bool split = options_.max_cluster_faces > 0;
  // Split mode, first the feature and boundary clusters (their rings carry the angle between
  // their constraints, docs/design.md, "Cross field", also across faces with curvature
  // constraints), then the curvature clusters over the curvature-constrained faces, each of at most
  // max_cluster_faces faces. Otherwise one pass: connected regions of every kind.
  for (int phase = 0; phase < (split ? 2 : 1); ++phase) {
    const bool curvature_phase = split && phase == 1;
    if (split) std::fill(visited.begin(), visited.end(), 0);
    for (int k0 = 0; k0 < nc; ++k0) {
      const int f0 = field_.constraints.face[k0];
      if (split && (cluster_of_[k0] >= 0 || is_curvature(k0) != curvature_phase)) continue;
      if (visited[f0]) continue;
      const int cl = static_cast<int>(cluster_size_.size());
      cluster_size_.push_back(0);
      visited[f0] = 1;
      carried[f0] = c[k0];
      queue.assign(1, f0);
      for (size_t head = 0; head < queue.size(); ++head) {
        const int f = queue[head];
        const int k = constraint_at_[f];
        if (k >= 0 && (!split || is_curvature(k) == curvature_phase)) {
          relative_q_[k] = static_cast<int>(std::lround((carried[f] - c[k]) / kQuarter));
          if (loop_of[k] >= 0) {
            int& offset = loop_offset[loop_of[k]];
            if (offset == INT_MIN) offset = relative_q_[k] - preset_q[k];
            relative_q_[k] = preset_q[k] + offset;
          }
          carried[f] = c[k] + kQuarter * relative_q_[k];
          cluster_of_[k] = cl;
          ++cluster_size_[cl];
        }
        for (auto h : mesh.fh_range(mesh.face_handle(f))) {
          const auto opp = mesh.opposite_halfedge_handle(h);
          if (mesh.is_boundary(opp)) continue;
          const int f2 = mesh.face_handle(opp).idx();
          if (visited[f2] || !carrier_[f2]) continue;
          if (split && !curvature_phase && !structural_carrier_[f2]) continue;
          if (curvature_phase) {
            const int k2 = constraint_at_[f2];
            if (k2 < 0 || !is_curvature(k2) || cluster_of_[k2] >= 0) continue;
            if (cluster_size_[cl] >= options_.max_cluster_faces) continue;
          }
          const int e = mesh.edge_handle(h).idx();
          const double step = g.kappa[e] + kQuarter * field_.period_jump[e];
          carried[f2] = (g.edge_face_i[e] == f) ? carried[f] + step : carried[f] - step;
          visited[f2] = 1;
          queue.push_back(f2);
        }
      }
    }
  }
  field_.clusters = static_cast<int>(cluster_size_.size());
}

void CrossFieldSolver::warm_start(const GeometryCache& g, bool allow_factorization,
                                  const ReferenceRotation& reference_rotation) {
  reference_theta_.resize(0);
  if (field_.clusters <= 1) return;
  const auto t0 = std::chrono::steady_clock::now();
  const double factorize_before = field_.timings.factorize_s;
  const double rotation_before = field_.timings.reference_rotation_s;
  const int nc = static_cast<int>(field_.constraints.face.size());
  const double lambda = options_.constraint_weight;
  const std::vector<double> c = constraint_angles(g);
  int largest = -1;
  for (int cl = 0; cl < field_.clusters; ++cl)
    if (cluster_active_[cl] && (largest < 0 || cluster_size_[cl] > cluster_size_[largest]))
      largest = cl;
  std::vector<int> others;  // active clusters whose rotation is relaxed
  std::vector<int> column(field_.clusters, -1);
  for (int cl = 0; cl < field_.clusters; ++cl)
    if (cl != largest && cluster_active_[cl]) {
      column[cl] = static_cast<int>(others.size());
      others.push_back(cl);
    }
  // The relaxed system needs one dense right-hand side per relaxed cluster (#F doubles each):
  // bounded by the cluster count and by 8M entries (64 MB). Beyond that, Relaxed falls back to
  // LayoutField (the largest cluster's field twisted a bunny cage layout's field by quarter
  // turns against the arcs: 40% fold-overs, arcs running backwards).
  const bool relaxed_fits = static_cast<int>(others.size()) <= options_.max_relaxed_clusters &&
                            static_cast<double>(others.size()) * g.n_faces <= 8e6;
  ClusterWarmStart mode = options_.warm_start;
  if (mode == ClusterWarmStart::Relaxed && !relaxed_fits) mode = ClusterWarmStart::LayoutField;
  // Split curvature clusters are judged against the layout's own field
  // (release_deviating_clusters): it is the warm start then.
  const bool split_reference =
      options_.max_cluster_faces > 0 && options_.max_cluster_deviation_deg > 0;
  if (split_reference) mode = ClusterWarmStart::LayoutField;
  if (mode == ClusterWarmStart::LayoutField && arc_gauge_face_ < 0)
    mode = ClusterWarmStart::LargestCluster;  // no arc to pin the reference field along
  if (mode == ClusterWarmStart::LayoutField) {
    // The reference field's matrix L0 (no direction constraints, one face pinned) is
    // factorized once and kept in reference_: the edge terms of the right-hand side sum to
    // zero, so the soft pin holds exactly and pinning another face only rotates the whole
    // field. update_layout solves it for the new period jumps and rotates the result onto the
    // new layout's arc gauge.
    if (!reference_.factorized()) {
      if (!allow_factorization) return;  // keep the offsets
      Eigen::SparseMatrix<double> L0 = matrix_;
      for (int k = 0; k < nc; ++k)
        if (active(k))
          L0.coeffRef(field_.constraints.face[k], field_.constraints.face[k]) -= lambda;
      if (field_.gauge_face >= 0) L0.coeffRef(field_.gauge_face, field_.gauge_face) -= lambda;
      L0.coeffRef(arc_gauge_face_, arc_gauge_face_) += lambda;
      factorize(reference_, L0);
      reference_face_ = arc_gauge_face_;
    }
    Eigen::VectorXd b = Eigen::VectorXd::Zero(g.n_faces);
    for (int e = 0; e < g.n_edges; ++e) {
      if (g.edge_face_i[e] < 0 || g.edge_face_j[e] < 0) continue;
      const double k = g.kappa[e] + kQuarter * field_.period_jump[e];
      b(g.edge_face_i[e]) -= k;
      b(g.edge_face_j[e]) += k;
    }
    const bool same_face = reference_face_ == arc_gauge_face_;
    b(reference_face_) += lambda * (same_face ? arc_gauge_angle_ : 0.0);
    ++field_.timings.solves;
    Eigen::VectorXd reference = reference_.solve(b);
    if (!same_face) reference.array() += arc_gauge_angle_ - reference(arc_gauge_face_);
    if (split_reference)
      reference.array() += choose_reference_rotation(reference, reference_rotation);
    std::fill(cluster_offset_.begin(), cluster_offset_.end(), 0);
    round_clusters(c, reference);
    reference_theta_ = std::move(reference);
    field_.timings.warm_start_s += seconds_since(t0) -
                                   (field_.timings.factorize_s - factorize_before) -
                                   (field_.timings.reference_rotation_s - rotation_before);
    return;
  }
  // (The layout's own field above is needed also when no cluster is in force: the structural
  // pass may have released every feature and boundary cluster, and the curvature clusters are
  // rounded against it.)
  if (largest < 0) return;
  const bool relaxed = mode == ClusterWarmStart::Relaxed;
  if (!relaxed && !allow_factorization) return;
  std::fill(cluster_offset_.begin(), cluster_offset_.end(), 0);
  if (others.empty()) return;
  Eigen::VectorXd theta;
  if (relaxed) {
    // E(θ, o) = θᵀLθ − 2θᵀ(b₀ + S o) + Σ_f λ(t_f + (π/2)o_cl(f))², with t_f = c_f + (π/2)q_f
    // and S = λ(π/2)·(cluster indicators). θ(o) = θ₀ + Y o with Y = L⁻¹S, and the reduced
    // system is (λ(π/2)²·diag(n) − SᵀY) o = Sᵀθ₀ − λ(π/2)·Σ_cluster t_f.
    const int m = static_cast<int>(others.size());
    make_current();
    const Eigen::VectorXd theta0 = back_substitute(rhs(g, c));
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(g.n_faces, m);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(m);
    Eigen::MatrixXd M = Eigen::MatrixXd::Zero(m, m);
    for (int k = 0; k < nc; ++k) {
      const int j = column[cluster_of_[k]];
      if (j < 0 || !active(k)) continue;
      const int f = field_.constraints.face[k];
      S(f, j) = lambda * kQuarter;
      r(j) += lambda * kQuarter * (theta0(f) - (c[k] + kQuarter * relative_q_[k]));
      M(j, j) += lambda * kQuarter * kQuarter;
    }
    ++field_.timings.solves;
    const Eigen::MatrixXd Y = solver_.solve(S);
    M.noalias() -= S.transpose() * Y;
    const Eigen::VectorXd o = M.ldlt().solve(r);
    theta = theta0 + Y * o;
  } else {
    // The smoothest field held only by the largest cluster (same pattern: the spare solver's
    // analysis is reused later by the conflict trials).
    Eigen::SparseMatrix<double> L0 = matrix_;
    Eigen::VectorXd b = rhs(g, c);
    for (int k = 0; k < nc; ++k) {
      if (cluster_of_[k] == largest || !active(k)) continue;
      const int f = field_.constraints.face[k];
      L0.coeffRef(f, f) -= lambda;
      b(f) -= lambda * (c[k] + kQuarter * relative_q_[k]);
    }
    factorize(spare_, L0);
    ++field_.timings.solves;
    theta = spare_.solve(b);
  }
  round_clusters(c, theta);
  field_.timings.warm_start_s +=
      seconds_since(t0) - (field_.timings.factorize_s - factorize_before);
}

int CrossFieldSolver::count_mismatches(const GeometryCache& g) const {
  int bad = 0;
  for (int e = 0; e < g.n_edges; ++e) {
    if (!interior(g, e)) continue;
    const double d = field_.theta[g.edge_face_j[e]] - field_.theta[g.edge_face_i[e]] - g.kappa[e];
    bad += std::lround(d / kQuarter) != field_.period_jump[e];
  }
  return bad;
}

void CrossFieldSolver::drop_conflicting_clusters(const TriMesh& mesh, const GeometryCache& g,
                                                 int tolerated, bool curvature_only) {
  const int nf = g.n_faces;
  const int nc = static_cast<int>(field_.constraints.face.size());
  if (nc == 0 || options_.max_conflict_passes <= 0) return;
  const auto t0 = std::chrono::steady_clock::now();
  const double factorize_before = field_.timings.factorize_s;
  const double lambda = options_.constraint_weight;
  int rings = options_.conflict_rings;
  int mismatches = count_mismatches(g);
  std::vector<int> dist(nf), queue;
  std::vector<char> in_drop(field_.clusters, 0);
  for (int pass = 0; pass < options_.max_conflict_passes && mismatches > tolerated; ++pass) {
    // Clusters within `rings` face rings of an edge the field steps over by more than 45°.
    const std::vector<int> matching = principal_matching(g, field_.theta);
    std::fill(dist.begin(), dist.end(), -1);
    queue.clear();
    for (int e = 0; e < g.n_edges; ++e) {
      if (!interior(g, e) || matching[e] == field_.period_jump[e]) continue;
      for (int f : {g.edge_face_i[e], g.edge_face_j[e]})
        if (dist[f] < 0) dist[f] = 0, queue.push_back(f);
    }
    if (queue.empty()) break;
    // Constraints whose λ is removed in this trial: whole clusters, or (Faces mode) only the
    // constrained faces near the steep edges.
    const bool by_faces = options_.conflict_drop == ConflictDrop::Faces;
    std::vector<int> drop, removed;
    for (size_t head = 0; head < queue.size(); ++head) {
      const int f = queue[head];
      const int k = constraint_at_[f];
      if (k >= 0 && active(k) && (!curvature_only || is_curvature(k))) {
        if (by_faces) {
          removed.push_back(k);
        } else if (!in_drop[cluster_of_[k]]) {
          in_drop[cluster_of_[k]] = 1;
          drop.push_back(cluster_of_[k]);
        }
      }
      if (dist[f] >= rings) continue;
      for (auto h : mesh.fh_range(mesh.face_handle(f))) {
        const auto opp = mesh.opposite_halfedge_handle(h);
        if (mesh.is_boundary(opp)) continue;
        const int f2 = mesh.face_handle(opp).idx();
        if (dist[f2] < 0) dist[f2] = dist[f] + 1, queue.push_back(f2);
      }
    }
    if (drop.empty() && removed.empty()) {
      // The conflicting constraints are farther away: widen the search (bounded).
      if (rings >= 64 * options_.conflict_rings) break;
      rings *= 4;
      --pass;
      continue;
    }
    // Trial: factorize without the removed constraints in the spare solver; the current
    // factorization stays available if the trial is rejected.
    for (int k = 0; k < nc; ++k)
      if (in_drop[cluster_of_[k]] && active(k)) removed.push_back(k);
    for (int cl : drop) cluster_active_[cl] = 0;
    for (int k : removed) {
      if (by_faces) constraint_active_[k] = 0;
      const int f = field_.constraints.face[k];
      matrix_.coeffRef(f, f) -= lambda;
    }
    field_.dropped_constraints += static_cast<int>(removed.size());
    const int gauge_before = field_.gauge_face;
    const double gauge_angle_before = gauge_angle_;
    pin_gauge_if_unconstrained();
    // The trial's solve re-rounds the cluster offsets: kept for the restore below.
    const std::vector<int> offsets_before = cluster_offset_;
    factorize_as_current();
    solve_system(g);
    ++field_.timings.conflict_passes;
    const int now = count_mismatches(g);
    if (now >= mismatches) {
      // Dropping did not help: these steps are not caused by constraints (e.g. the smoothest
      // field itself turns by more than 45° across an edge). Restore the constraints, go back
      // to the previous factorization (kept in the spare solver) and stop.
      std::swap(solver_, spare_);
      for (int cl : drop) cluster_active_[cl] = 1;
      for (int k : removed) {
        constraint_active_[k] = 1;
        const int f = field_.constraints.face[k];
        matrix_.coeffRef(f, f) += lambda;
      }
      field_.dropped_constraints -= static_cast<int>(removed.size());
      if (field_.gauge_face != gauge_before) {
        matrix_.coeffRef(field_.gauge_face, field_.gauge_face) -= lambda;
        field_.gauge_face = gauge_before;
        gauge_angle_ = gauge_angle_before;
      }
      for (int cl : drop) in_drop[cl] = 0;
      // Two fields with every constraint back in force: the one before the trial (its cluster
      // offsets), and the one from the offsets the trial re-rounded (the clusters freed by the
      // drop can turn to quarter rotations that fit the layout better). The fewer mismatching
      // edges win, then the lower energy: on the joint (QuadWild import) both keep 1 mismatch
      // but the re-rounded field's parameterization has E 3.20 and 191 fold-overs, the other's
      // 9.51 and 956; on a bunny cage layout the re-rounded one has 2 mismatches instead of 1.
      const std::vector<int> offsets_trial = cluster_offset_;
      cluster_offset_ = offsets_before;
      solve_system(g);
      if (offsets_trial != offsets_before) {
        const int kept_mismatches = count_mismatches(g);
        const double kept_energy = energy(g);
        const CrossField kept = field_;
        const std::vector<int> kept_offsets = cluster_offset_;
        cluster_offset_ = offsets_trial;
        solve_system(g);
        const int m = count_mismatches(g);
        if (m > kept_mismatches || (m == kept_mismatches && energy(g) >= kept_energy)) {
          field_ = kept;
          cluster_offset_ = kept_offsets;
        }
      }
      break;
    }
    for (int cl : drop) in_drop[cl] = 0;
    mismatches = now;
  }
  recount_dropped_clusters();
  field_.timings.conflicts_s += seconds_since(t0) - (field_.timings.factorize_s - factorize_before);
}

bool CrossFieldSolver::structural_pass_applies() const {
  const int nc = static_cast<int>(field_.constraints.face.size());
  if (options_.max_cluster_faces <= 0 || nc == 0 || options_.max_conflict_passes <= 0) return false;
  bool any_structural = false, any_curvature = false;
  for (int k = 0; k < nc; ++k) {
    if (!active(k)) continue;
    (is_curvature(k) ? any_curvature : any_structural) = true;
  }
  return any_structural && any_curvature;
}

bool CrossFieldSolver::drop_structural_conflicts(const TriMesh& mesh, const GeometryCache& g,
                                                 int tolerated, bool allow_factorization,
                                                 const ReferenceRotation& reference_rotation) {
  if (!structural_pass_applies()) return false;
  const int nc = static_cast<int>(field_.constraints.face.size());
  // Curvature clusters in force (split mode: a cluster has constraints of one class only).
  std::vector<char> curvature(field_.clusters, 0);
  for (int k = 0; k < nc; ++k)
    if (active(k) && is_curvature(k)) curvature[cluster_of_[k]] = 1;
  const double lambda = options_.constraint_weight;
  const int gauge_before = field_.gauge_face;
  const double gauge_angle_before = gauge_angle_;
  const int dropped_before = field_.dropped_constraints;
  std::vector<int> lifted;  // curvature constraints set aside
  for (int k = 0; k < nc; ++k) {
    if (!active(k) || !curvature[cluster_of_[k]]) continue;
    const int f = field_.constraints.face[k];
    matrix_.coeffRef(f, f) -= lambda;
    lifted.push_back(k);
  }
  for (int cl = 0; cl < field_.clusters; ++cl)
    if (curvature[cl]) cluster_active_[cl] = 0;
  // The feature and boundary clusters with a face the last pass dropped are dropped again
  // before the first factorization (whole clusters, or those faces in ConflictDrop::Faces).
  const bool by_faces = options_.conflict_drop == ConflictDrop::Faces;
  if (structural_dropped_.size() == static_cast<size_t>(g.n_faces)) {
    std::vector<char> again(field_.clusters, 0);
    for (int k = 0; k < nc; ++k) {
      if (!active(k) || !structural_dropped_[field_.constraints.face[k]]) continue;
      if (by_faces) {
        constraint_active_[k] = 0;
        const int f = field_.constraints.face[k];
        matrix_.coeffRef(f, f) -= lambda;
        ++field_.dropped_constraints;
      } else {
        again[cluster_of_[k]] = 1;
      }
    }
    for (int k = 0; k < nc; ++k) {
      if (!again[cluster_of_[k]] || !constraint_active_[k]) continue;
      const int f = field_.constraints.face[k];
      matrix_.coeffRef(f, f) -= lambda;
      ++field_.dropped_constraints;
    }
    for (int cl = 0; cl < field_.clusters; ++cl)
      if (again[cl]) cluster_active_[cl] = 0;
    pin_gauge_if_unconstrained();
  }
  // The matrix of the feature and boundary constraints alone changes only when their drops do:
  // update_layout after a descent step usually factorizes the last step's matrix again.
  if (structural_.factorized() && structural_.same_pattern(matrix_) &&
      std::equal(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros(),
                 structural_values_.begin(), structural_values_.end())) {
    std::swap(solver_, spare_);
    solver_ = structural_;  // shared (copy-on-write)
    current_ = true;
    ++field_.timings.reused_factorizations;
  } else {
    factorize_as_current();
  }
  // The rotations of the feature and boundary clusters start as in a run without curvature
  // constraints: from their own warm start, not from the offsets left by an earlier layout or
  // zero (which twisted the clusters of a boundary-aligned layout against each other, and the
  // pass released them all).
  warm_start(g, allow_factorization, reference_rotation);
  solve_system(g);
  drop_conflicting_clusters(mesh, g, tolerated);
  if (current_) {  // the structural matrix after its drops, for the next pass
    structural_ = solver_;
    structural_values_.assign(matrix_.valuePtr(), matrix_.valuePtr() + matrix_.nonZeros());
  }
  structural_dropped_.assign(g.n_faces, 0);
  for (int k = 0; k < nc; ++k)
    if (!is_curvature(k) && !active(k)) structural_dropped_[field_.constraints.face[k]] = 1;
  // The curvature clusters back in force.
  for (int cl = 0; cl < field_.clusters; ++cl)
    if (curvature[cl]) cluster_active_[cl] = 1;
  // The next solve factorizes the matrix with the curvature constraints back (after the
  // deviation release has changed it too).
  if (field_.dropped_constraints == dropped_before) {
    // Nothing dropped: every constraint in force, as before the pass (setup and update_layout
    // call it with the full matrix).
    matrix_ = full_matrix_;
    current_ = false;
    if (full_factorized_) {
      solver_ = full_;
      current_ = true;
    }
  } else {
    for (int k : lifted) {
      const int f = field_.constraints.face[k];
      matrix_.coeffRef(f, f) += lambda;
    }
    // A gauge the passes pinned when nothing was left in force is not needed any more.
    if (field_.gauge_face != gauge_before && field_.gauge_face >= 0)
      matrix_.coeffRef(field_.gauge_face, field_.gauge_face) -= lambda;
    current_ = false;
  }
  field_.gauge_face = gauge_before;
  gauge_angle_ = gauge_angle_before;
  recount_dropped_clusters();
  return true;
}

double CrossFieldSolver::choose_reference_rotation(const Eigen::VectorXd& reference,
                                                   const ReferenceRotation& reference_rotation) {
  double phi = 0;
  if (reference_rotation) {
    const auto t0 = std::chrono::steady_clock::now();
    phi = reference_rotation(
        field_.period_jump,
        std::vector<double>(reference.data(), reference.data() + reference.size()));
    field_.timings.reference_rotation_s += seconds_since(t0);
    if (!std::isfinite(phi)) phi = 0;
  } else if (rotation_anchor_.size() == reference.size()) {
    // The rotation that best maps this field onto the anchor up to quarter turns: the mean
    // direction of 4(anchor − reference) on the circle, divided by 4.
    double sin_sum = 0, cos_sum = 0;
    for (Eigen::Index f = 0; f < reference.size(); ++f) {
      sin_sum += std::sin(4 * (rotation_anchor_(f) - reference(f)));
      cos_sum += std::cos(4 * (rotation_anchor_(f) - reference(f)));
    }
    phi = std::atan2(sin_sum, cos_sum) / 4;
  } else {
    return 0;  // the arc gauge
  }
  rotation_anchor_ = reference.array() + phi;
  return phi;
}

void CrossFieldSolver::release_deviating_clusters(const GeometryCache& g) {
  const int nc = static_cast<int>(field_.constraints.face.size());
  if (options_.max_cluster_faces <= 0 || options_.max_cluster_deviation_deg <= 0 ||
      reference_theta_.size() != g.n_faces || nc == 0)
    return;
  const auto t0 = std::chrono::steady_clock::now();
  const double factorize_before = field_.timings.factorize_s;
  // Mean angle (radians, 0..π/4) between each curvature cluster's targets (its current
  // rotation) and the layout's own field, up to quarter turns.
  const std::vector<double> c = constraint_angles(g);
  std::vector<double> sum(field_.clusters, 0.0);
  std::vector<int> count(field_.clusters, 0);
  for (int k = 0; k < nc; ++k) {
    if (!active(k) || !is_curvature(k)) continue;
    const int cl = cluster_of_[k];
    const double target = c[k] + kQuarter * (relative_q_[k] + cluster_offset_[cl]);
    sum[cl] +=
        std::abs(std::remainder(reference_theta_(field_.constraints.face[k]) - target, kQuarter));
    ++count[cl];
  }
  const double limit = options_.max_cluster_deviation_deg * M_PI / 180.0;
  const double lambda = options_.constraint_weight;
  bool released = false;
  for (int cl = 0; cl < field_.clusters; ++cl) {
    if (count[cl] == 0 || sum[cl] / count[cl] <= limit) continue;
    cluster_active_[cl] = 0;
    released = true;
  }
  if (!released) return;
  for (int k = 0; k < nc; ++k) {
    const int cl = cluster_of_[k];
    if (cluster_active_[cl] || count[cl] == 0 || !constraint_active_[k]) continue;
    const int f = field_.constraints.face[k];  // in a cluster released just now
    matrix_.coeffRef(f, f) -= lambda;
    ++field_.dropped_constraints;
  }
  pin_gauge_if_unconstrained(&reference_theta_);
  recount_dropped_clusters();
  current_ = false;  // the caller's solve factorizes
  field_.timings.conflicts_s += seconds_since(t0) - (field_.timings.factorize_s - factorize_before);
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
