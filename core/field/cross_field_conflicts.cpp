// Releasing the direction constraints that contradict the layout (docs/design.md, "Cross
// field"): the drop passes over the clusters (or faces) near the edges where the field steps
// against its period jump, the structural pass of split mode (feature and boundary clusters
// alone first), and the release of curvature clusters that deviate from the layout's own
// field. Part of CrossFieldSolver.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>
#include <vector>

#include "core/base/timing.h"
#include "core/field/cross_field.h"
#include "core/field/cross_field_impl.h"

namespace qs {

using cross_field_detail::interior;
using cross_field_detail::kQuarter;

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

}  // namespace qs
