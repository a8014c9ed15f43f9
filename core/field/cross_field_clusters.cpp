// The constraint clusters of CrossFieldSolver (docs/design.md, "Cross field"): the quarter turns
// the layout prescribes on the boundary loops its arcs cover, the clusters and the relative
// rotations of their constraints by propagation over the carrier faces, the warm start of
// the cluster rotations (ClusterWarmStart) and the rotation of the layout's own field in split
// mode.
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <climits>
#include <cmath>
#include <vector>

#include "core/base/timing.h"
#include "core/field/cross_field.h"
#include "core/field/cross_field_impl.h"

namespace qs {

using cross_field_detail::kQuarter;

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

}  // namespace qs
