#include "core/field/natural_field.h"

#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <functional>
#include <queue>
#include <string>
#include <tuple>
#include <utility>

#include "core/base/errors.h"
#include "core/base/spd_solver.h"
#include "core/field/cross_field.h"

namespace qs {

void validate_natural_field_options(const NaturalFieldOptions& options) {
  if (!(options.constraint_weight > 0.0) || !std::isfinite(options.constraint_weight))
    throw InvalidInputError("natural field constraint_weight must be a positive number, got " +
                            std::to_string(options.constraint_weight));
  if (!(options.curvature_weight > 0.0) || !std::isfinite(options.curvature_weight))
    throw InvalidInputError("natural field curvature_weight must be a positive number, got " +
                            std::to_string(options.curvature_weight));
  if (options.iterations < 1 || options.iterations > 1000)
    throw InvalidInputError("natural field iterations must be in [1, 1000], got " +
                            std::to_string(options.iterations));
  if (!(options.constraints.sharp_angle_deg >= 0.0 && options.constraints.sharp_angle_deg <= 180.0))
    throw InvalidInputError("natural field sharp_angle_deg must be in [0, 180]");
}

NaturalField compute_natural_field(const TriMesh& mesh, const GeometryCache& g,
                                   const NaturalFieldOptions& options) {
  validate_natural_field_options(options);
  const int nf = g.n_faces;
  NaturalField out;
  if (nf == 0) return out;
  Curvature curvature;
  if (options.constraints.curvature)
    curvature = compute_curvature(mesh, g, options.constraints.curvature_options);
  out.constraints = collect_constraints(mesh, g, nullptr, options.constraints,
                                        options.constraints.curvature ? &curvature : nullptr);

  // Real form of the Hermitian system: unknowns (Re z_f, Im z_f) at 2f, 2f + 1; a complex entry
  // a + ib is the block [[a, −b], [b, a]].
  double mean_area = 0.0;
  for (double a : g.face_area) mean_area += a;
  mean_area = std::max(mean_area / nf, 1e-300);
  std::vector<Eigen::Triplet<double>> t;
  t.reserve(std::size_t(g.n_edges) * 8 + std::size_t(nf) * 2);
  std::vector<Vec3> centroid(nf);
  for (int f = 0; f < nf; ++f) {
    const auto& c = g.face_vertices[f];
    centroid[f] = (mesh.point(mesh.vertex_handle(c[0])) + mesh.point(mesh.vertex_handle(c[1])) +
                   mesh.point(mesh.vertex_handle(c[2]))) /
                  3.0;
  }
  std::vector<double> diagonal(nf, 0.0);
  for (int e = 0; e < g.n_edges; ++e) {
    const int i = g.edge_face_i[e], j = g.edge_face_j[e];
    if (i < 0 || j < 0) continue;
    const double dual = std::max((centroid[i] - centroid[j]).norm(), 1e-12 * g.bbox_diagonal);
    const double w = g.edge_length[e] / dual;
    const double c = std::cos(4.0 * g.kappa[e]), s = std::sin(4.0 * g.kappa[e]);
    diagonal[i] += w;
    diagonal[j] += w;
    // Row j, column i: −w·ρ; row i, column j: −w·conj(ρ), ρ = e^{4iκ}.
    t.emplace_back(2 * j, 2 * i, -w * c);
    t.emplace_back(2 * j, 2 * i + 1, w * s);
    t.emplace_back(2 * j + 1, 2 * i, -w * s);
    t.emplace_back(2 * j + 1, 2 * i + 1, -w * c);
    t.emplace_back(2 * i, 2 * j, -w * c);
    t.emplace_back(2 * i, 2 * j + 1, -w * s);
    t.emplace_back(2 * i + 1, 2 * j, w * s);
    t.emplace_back(2 * i + 1, 2 * j + 1, -w * c);
  }
  const double lambda = options.constraint_weight;
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * nf);
  for (std::size_t k = 0; k < out.constraints.face.size(); ++k) {
    const int f = out.constraints.face[k];
    const double phi = g.angle_in_face(f, out.constraints.direction[k]);
    const double weight =
        out.constraints.kind[k] == ConstraintKind::Curvature ? options.curvature_weight : lambda;
    diagonal[f] += weight;
    rhs[2 * f] = weight * std::cos(4.0 * phi);
    rhs[2 * f + 1] = weight * std::sin(4.0 * phi);
  }
  // A small multiple of the (normalized) mass keeps the matrix definite where a parallel field
  // exists (a flat disk, a torus).
  constexpr double kShift = 1e-8;
  Eigen::VectorXd mass(2 * nf);
  for (int f = 0; f < nf; ++f) {
    mass[2 * f] = mass[2 * f + 1] = g.face_area[f] / mean_area;
    t.emplace_back(2 * f, 2 * f, diagonal[f] + kShift * mass[2 * f]);
    t.emplace_back(2 * f + 1, 2 * f + 1, diagonal[f] + kShift * mass[2 * f]);
  }
  Eigen::SparseMatrix<double> A(2 * nf, 2 * nf);
  A.setFromTriplets(t.begin(), t.end());
  SpdSolver solver("natural cross field");
  solver.set_full_storage(true);
  solver.factorize(A);
  Eigen::VectorXd z;
  if (!out.constraints.face.empty()) {
    z = solver.solve(rhs);
  } else {
    // Inverse iteration towards the smallest eigenvector (mass-normalized); the start is the
    // constant angle 0 in every face frame, deterministic.
    z = Eigen::VectorXd::Zero(2 * nf);
    for (int f = 0; f < nf; ++f) z[2 * f] = 1.0;
    for (int it = 0; it < options.iterations; ++it) {
      z = solver.solve(Eigen::VectorXd(mass.cwiseProduct(z)));
      const double norm = std::sqrt(z.dot(mass.cwiseProduct(z)));
      if (!(norm > 0.0) || !std::isfinite(norm))
        throw SolverError("natural cross field: the inverse iteration lost its vector");
      z /= norm;
    }
  }
  out.theta.resize(nf);
  for (int f = 0; f < nf; ++f) out.theta[f] = 0.25 * std::atan2(z[2 * f + 1], z[2 * f]);
  out.direction = field_directions(g, out.theta);
  out.bbox_diagonal = g.bbox_diagonal;
  out.quarter_index = field_quarter_indices(g, out.theta);
  for (int v = 0; v < g.n_vertices; ++v)
    if (out.quarter_index[v] != 0) out.singularities.push_back({v, out.quarter_index[v]});
  return out;
}

std::vector<FieldSingularity> cancel_close_pairs(const TriMesh& mesh,
                                                 const std::vector<FieldSingularity>& singularities,
                                                 double radius) {
  if (!std::isfinite(radius))
    throw InvalidInputError("singularity pairing radius must be a finite number");
  const int nv = static_cast<int>(mesh.n_vertices());
  std::vector<int> at_vertex(nv, -1);  // singularity index per vertex, -1 for none
  for (std::size_t k = 0; k < singularities.size(); ++k) {
    const int v = singularities[k].vertex;
    if (v < 0 || v >= nv)
      throw InvalidInputError("singularity at vertex " + std::to_string(v) +
                              " is not a vertex of the mesh (" + std::to_string(nv) + " vertices)");
    at_vertex[v] = static_cast<int>(k);
  }
  if (!(radius > 0.0) || singularities.size() < 2) return singularities;

  // Candidate pairs (distance, k, l) with k < l and opposite indices, from a Dijkstra ball of
  // the radius around every singularity; the work arrays are reset through `touched`.
  std::vector<std::tuple<double, int, int>> pairs;
  std::vector<double> dist(nv, radius);
  std::vector<int> touched;
  using Item = std::pair<double, int>;
  for (std::size_t k = 0; k < singularities.size(); ++k) {
    const int source = singularities[k].vertex;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    dist[source] = 0.0;
    touched.push_back(source);
    queue.emplace(0.0, source);
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > dist[v]) continue;
      const int l = at_vertex[v];
      if (l > static_cast<int>(k) && singularities[l].index == -singularities[k].index)
        pairs.emplace_back(d, static_cast<int>(k), l);
      const auto vh = OpenMesh::VertexHandle(v);
      for (const auto w : mesh.vv_range(vh)) {
        const double nd = d + (mesh.point(w) - mesh.point(vh)).norm();
        if (nd < dist[w.idx()]) {
          if (dist[w.idx()] == radius) touched.push_back(w.idx());
          dist[w.idx()] = nd;
          queue.emplace(nd, w.idx());
        }
      }
    }
    for (int v : touched) dist[v] = radius;
    touched.clear();
  }
  std::sort(pairs.begin(), pairs.end(), [&](const auto& a, const auto& b) {
    const auto key = [&](const auto& p) {
      const int va = singularities[std::get<1>(p)].vertex,
                vb = singularities[std::get<2>(p)].vertex;
      return std::make_tuple(std::get<0>(p), std::min(va, vb), std::max(va, vb));
    };
    return key(a) < key(b);
  });
  std::vector<char> cancelled(singularities.size(), 0);
  for (const auto& [d, k, l] : pairs) {
    if (cancelled[k] || cancelled[l]) continue;
    cancelled[k] = cancelled[l] = 1;
  }
  std::vector<FieldSingularity> kept;
  for (std::size_t k = 0; k < singularities.size(); ++k)
    if (!cancelled[k]) kept.push_back(singularities[k]);
  return kept;
}

}  // namespace qs
