#include "core/field/matching_repair.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <utility>

#include "core/base/errors.h"

namespace qs {

namespace {

constexpr double kQuarter = M_PI / 2;

bool interior(const GeometryCache& g, int e) {
  return g.edge_face_i[e] >= 0 && g.edge_face_j[e] >= 0;
}

// The field's turn across edge e against the transport and the period jump (radians).
double turn(const GeometryCache& g, const std::vector<int>& p, const std::vector<double>& theta,
            int e) {
  return theta[g.edge_face_j[e]] - theta[g.edge_face_i[e]] - g.kappa[e] - kQuarter * p[e];
}

int count_beyond(const GeometryCache& g, const std::vector<int>& p,
                 const std::vector<double>& theta, double limit) {
  int n = 0;
  for (int e = 0; e < g.n_edges; ++e)
    if (interior(g, e) && std::abs(turn(g, p, theta, e)) > limit) ++n;
  return n;
}

// The faces within `rings` dual-graph steps of the faces of `seeds` (edges).
std::vector<int> region_around(const GeometryCache& g, const std::vector<int>& seeds, int rings) {
  std::vector<int> depth(g.n_faces, -1), out;
  for (int e : seeds)
    for (int f : {g.edge_face_i[e], g.edge_face_j[e]})
      if (depth[f] < 0) depth[f] = 0, out.push_back(f);
  for (size_t head = 0; head < out.size(); ++head) {
    const int f = out[head];
    if (depth[f] >= rings) continue;
    for (int e : g.face_edges[f]) {
      if (!interior(g, e)) continue;
      const int h = g.edge_face_i[e] == f ? g.edge_face_j[e] : g.edge_face_i[e];
      if (depth[h] < 0) depth[h] = depth[f] + 1, out.push_back(h);
    }
  }
  return out;
}

}  // namespace

MatchingRepairResult repair_principal_matching(const GeometryCache& g,
                                               const std::vector<int>& period_jump,
                                               const std::vector<char>& fixed,
                                               std::vector<double>& theta,
                                               const MatchingRepairOptions& options) {
  if (static_cast<int>(theta.size()) != g.n_faces ||
      static_cast<int>(period_jump.size()) != g.n_edges ||
      static_cast<int>(fixed.size()) != g.n_faces)
    throw InvalidInputError("repair_principal_matching: sizes do not match the geometry");
  MatchingRepairResult result;
  std::vector<int> steep;
  for (int e = 0; e < g.n_edges; ++e)
    if (interior(g, e) && std::abs(turn(g, period_jump, theta, e)) > options.trigger)
      steep.push_back(e);
  result.mismatched_before = static_cast<int>(steep.size());
  if (steep.empty()) return result;

  const std::vector<double> original = theta;
  // The attempt with the fewest edges beyond 45° when no region holds the target.
  std::vector<double> best = original;
  int best_count = count_beyond(g, period_jump, original, M_PI / 4);
  for (const int rings : options.rings) {
    theta = original;
    std::vector<int> unknown_of(g.n_faces, -1), unknowns;
    for (int f : region_around(g, steep, rings))
      if (!fixed[f]) unknown_of[f] = static_cast<int>(unknowns.size()), unknowns.push_back(f);
    if (unknowns.empty()) continue;
    // The edges whose energy terms hold an unknown θ.
    std::vector<int> edges;
    std::vector<char> seen(g.n_edges, 0);
    for (int f : unknowns)
      for (int e : g.face_edges[f])
        if (interior(g, e) && !seen[e]) seen[e] = 1, edges.push_back(e);
    std::vector<double> weight(edges.size(), 1.0);
    const int n = static_cast<int>(unknowns.size());
    bool held = false;
    for (int round = 0; round < options.max_rounds && !held; ++round) {
      // Normal equations of Σ w_e (θ_j − θ_i − k_e)² in the unknown θ, the others held; a tiny
      // pull towards the current θ keeps a region without held faces definite.
      std::vector<Eigen::Triplet<double>> triplets;
      Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
      for (int u = 0; u < n; ++u) {
        triplets.emplace_back(u, u, 1e-9);
        b(u) += 1e-9 * theta[unknowns[u]];
      }
      for (size_t t = 0; t < edges.size(); ++t) {
        const int e = edges[t];
        const double w = weight[t];
        const double k = g.kappa[e] + kQuarter * period_jump[e];
        const int i = g.edge_face_i[e], j = g.edge_face_j[e];
        const int ui = unknown_of[i], uj = unknown_of[j];
        if (ui >= 0) {
          triplets.emplace_back(ui, ui, w);
          b(ui) -= w * k;
          if (uj >= 0)
            triplets.emplace_back(ui, uj, -w);
          else
            b(ui) += w * theta[j];
        }
        if (uj >= 0) {
          triplets.emplace_back(uj, uj, w);
          b(uj) += w * k;
          if (ui >= 0)
            triplets.emplace_back(uj, ui, -w);
          else
            b(uj) += w * theta[i];
        }
      }
      Eigen::SparseMatrix<double> A(n, n);
      A.setFromTriplets(triplets.begin(), triplets.end());
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
      if (ldlt.info() != Eigen::Success) break;
      const Eigen::VectorXd x = ldlt.solve(b);
      if (ldlt.info() != Eigen::Success || !x.allFinite()) break;
      for (int u = 0; u < n; ++u) theta[unknowns[u]] = x(u);
      held = true;
      for (size_t t = 0; t < edges.size(); ++t)
        if (std::abs(turn(g, period_jump, theta, edges[t])) > options.target) {
          held = false;
          weight[t] *= options.weight_growth;
        }
    }
    const int count = count_beyond(g, period_jump, theta, M_PI / 4);
    if (held || count < best_count) best = theta, best_count = count;
    if (held) break;
  }
  theta = std::move(best);
  for (int f = 0; f < g.n_faces; ++f) result.changed_faces += theta[f] != original[f];
  result.mismatched_after = best_count;
  return result;
}

}  // namespace qs
