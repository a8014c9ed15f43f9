#include "core/import/cage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// The patches of a quad complex on a quad mesh as a coarse quad mesh: one vertex per node (at
// its quad-mesh vertex), one face per patch. Returns false when that is not a manifold
// polygon mesh (a loop arc, two arcs joining the same nodes, a patch that is not 4-sided).
bool complex_to_mesh(const PolyMesh& quads, const QuadComplex& complex, PolyMesh& out) {
  out.clear();
  // Loop arcs and parallel arcs have no place in a polygon mesh (checked here rather than by
  // add_face, which reports on stderr).
  std::vector<std::pair<int, int>> ends;
  for (const auto& arc : complex.arcs) {
    if (arc.from == arc.to) return false;
    ends.emplace_back(std::min(arc.from, arc.to), std::max(arc.from, arc.to));
  }
  std::sort(ends.begin(), ends.end());
  if (std::adjacent_find(ends.begin(), ends.end()) != ends.end()) return false;
  const int n = static_cast<int>(complex.node_vertex.size());
  for (int v : complex.node_vertex) out.add_vertex(quads.point(VH(v)));
  // Position of each half-arc in its node's counter-clockwise list.
  const size_t n_half = 2 * complex.arcs.size();
  std::vector<int> node_of(n_half, -1), slot(n_half, -1);
  for (int node = 0; node < n; ++node) {
    const auto& list = complex.node_half_arcs[node];
    for (size_t i = 0; i < list.size(); ++i) {
      node_of[list[i]] = node;
      slot[list[i]] = static_cast<int>(i);
    }
  }
  for (size_t h = 0; h < n_half; ++h)
    if (node_of[h] < 0) return false;
  std::vector<char> used(n_half, 0);
  for (size_t h0 = 0; h0 < n_half; ++h0) {
    if (used[h0]) continue;
    std::vector<VH> corners;
    size_t h = h0;
    do {
      if (used[h] || corners.size() > 4) return false;
      used[h] = 1;
      corners.emplace_back(node_of[h]);
      // The face left of h continues at the other end with the half-arc clockwise before
      // h's reverse.
      const size_t back = h ^ 1;
      const auto& list = complex.node_half_arcs[node_of[back]];
      h = list[(slot[back] + list.size() - 1) % list.size()];
    } while (h != h0);
    if (corners.size() != 4 || !out.add_face(corners).is_valid()) return false;
  }
  return true;
}

// The complex of a coarse quad mesh split into a finer one (split_to_quads keeps the coarse
// vertices first, all new vertices have valence 4): every coarse vertex is a node, every coarse
// edge an arc (the straight chain of fine edges between its ends).
QuadComplex coarse_edge_complex(const PolyMesh& fine, int coarse_vertices, int coarse_faces) {
  QuadComplex qc;
  for (int v = 0; v < coarse_vertices; ++v) qc.node_vertex.push_back(v);
  qc.node_half_arcs.assign(coarse_vertices, {});
  std::vector<int> half_of(fine.n_halfedges(), -1);  // first fine halfedge -> half-arc
  for (int v = 0; v < coarse_vertices; ++v) {
    // Outgoing halfedges counter-clockwise.
    const auto start = fine.halfedge_handle(VH(v));
    auto h = start;
    do {
      if (half_of[h.idx()] < 0) {
        QuadComplex::Arc arc;
        arc.from = v;
        arc.path.push_back(v);
        auto g = h;
        while (true) {
          const int to = fine.to_vertex_handle(g).idx();
          arc.path.push_back(to);
          if (to < coarse_vertices) break;
          // Straight on through the valence-4 vertex: the opposite edge.
          const auto back = fine.opposite_halfedge_handle(g);
          auto next = fine.opposite_halfedge_handle(fine.prev_halfedge_handle(back));
          next = fine.opposite_halfedge_handle(fine.prev_halfedge_handle(next));
          g = next;
        }
        arc.to = arc.path.back();
        const int a = static_cast<int>(qc.arcs.size());
        half_of[h.idx()] = 2 * a;
        half_of[fine.opposite_halfedge_handle(g).idx()] = 2 * a + 1;
        qc.arcs.push_back(std::move(arc));
      }
      qc.node_half_arcs[v].push_back(half_of[h.idx()]);
      h = fine.opposite_halfedge_handle(fine.prev_halfedge_handle(h));
    } while (h != start);
    qc.valence.push_back(static_cast<int>(qc.node_half_arcs[v].size()));
    qc.irregular_vertices += qc.valence.back() != 4;
  }
  qc.num_patches = coarse_faces;
  return qc;
}

}  // namespace

namespace {

struct SimplifiedLayout {
  Layout layout;
  PolyMesh fine;        // the split coarse mesh on the surface
  QuadComplex complex;  // its coarse edges as arcs
  CageSimplifyStats stats;
};

// CageOptions::simplify: the complex on the fitted cage as a coarse quad mesh, its irregular
// vertices cancelled, split back down, smoothed on the surface and transferred.
// \throw InvalidInputError when the complex is no manifold mesh or the transfer fails.
SimplifiedLayout simplified_layout(const PolyMesh& cage, const QuadComplex& source,
                                   const TriMesh& mesh, const CageOptions& options) {
  PolyMesh coarse;
  if (!complex_to_mesh(cage, source, coarse))
    throw InvalidInputError("its patches do not form a manifold quad mesh");
  std::vector<Vec3> normals;
  for (int v : source.node_vertex) {
    const Vec3 n = cage_vertex_normal(cage, VH(v));
    normals.push_back(n / std::max(1e-12, n.norm()));
  }
  SimplifiedLayout out;
  out.stats = cancel_irregular_vertices(coarse, QuadSimplifyOptions{}, &normals);
  // Re-embedding alone only loses the cage's shape (its arcs become straight chains).
  if (out.stats.irregular_after == out.stats.irregular_before)
    throw InvalidInputError("no irregular node could be cancelled");
  // Merged nodes sit at midpoints: back onto the surface.
  CageFitOptions project = options.fit;
  project.presmoothing = 0;
  project.iterations = 0;
  fit_cage(coarse, mesh, project);
  const int nv = static_cast<int>(coarse.n_vertices());
  const int nf = static_cast<int>(coarse.n_faces());
  out.fine = coarse;
  for (int k = 0; k < std::max(0, options.simplify_splits); ++k) refine_fitted_cage(out.fine, mesh);
  relax_on_surface(out.fine, mesh, std::max(0, options.simplify_relaxation));
  const int folded = fit_cage(out.fine, mesh, project);
  out.complex = coarse_edge_complex(out.fine, nv, nf);
  try {
    out.layout = transfer_complex(out.fine, out.complex, mesh, options.transfer);
  } catch (const InvalidInputError& e) {
    std::string why = e.what();
    why = why.substr(0, why.find("; --coarsen"));
    throw InvalidInputError(std::to_string(out.stats.irregular_before) + " -> " +
                            std::to_string(out.stats.irregular_after) + " irregular nodes, " +
                            std::to_string(nf) + " patches, " + std::to_string(folded) +
                            " folded; transfer failed: " + why);
  }
  return out;
}

}  // namespace

CageResult cage_layout(const TriMesh& mesh, const CageOptions& options) {
  MeshReport mesh_report;
  count_topology(mesh, mesh_report);
  if (mesh_report.components != 1 || mesh_report.boundary_loops != 0) {
    throw InvalidInputError(
        "a cage layout needs a closed surface with one component (the mesh has " +
        std::to_string(mesh_report.components) + " component(s) and " +
        std::to_string(mesh_report.boundary_loops) + " boundary loop(s))");
  }
  CageResult result;
  std::vector<std::string> failures;
  BaseComplexOptions bc;
  bc.all_edges = options.all_edges;
  for (int attempt = 0; attempt < std::max(1, options.attempts); ++attempt) {
    const int resolution = options.resolution + attempt / 2;
    double shift = options.shift + (attempt % 2 ? 0.5 : 0.0);
    shift -= std::floor(shift);
    if (resolution > 200) break;
    char shift_text[32] = "";
    if (shift != 0) std::snprintf(shift_text, sizeof shift_text, " (shifted %.3g)", shift);
    const std::string name = "resolution " + std::to_string(resolution) + shift_text;
    PolyMesh cage;
    try {
      cage = voxel_cage(mesh, resolution, &result.voxels, shift, options.subsamples);
    } catch (const InvalidInputError& e) {
      failures.push_back(e.what());
      continue;
    }
    if (result.voxels.components != 1 || result.voxels.genus != mesh_report.genus) {
      failures.push_back(name + ": the voxel surface has " +
                         std::to_string(result.voxels.components) +
                         " component(s) of total genus " + std::to_string(result.voxels.genus) +
                         ", the mesh has genus " + std::to_string(mesh_report.genus));
      continue;
    }
    const int folded = fit_cage(cage, mesh, options.fit);
    int chosen = -1, refined = 0;
    bool simplified = false;
    QuadComplex complex;
    CoarsenStats stats;
    // Splitting adds arcs in all-edges mode (one patch per quad), so it is for complexes only.
    const int max_refine = options.all_edges ? 0 : std::max(0, options.max_refine);
    for (; refined <= max_refine && chosen < 0; ++refined) {
      if (refined > 0) refine_fitted_cage(cage, mesh);
      const std::string level = refined ? " (split " + std::to_string(refined) + "x)" : "";
      const QuadComplex full = base_complex(cage, bc);
      // The coarsened complex first (when asked for), then the cage's full complex.
      std::vector<std::pair<QuadComplex, CoarsenStats>> candidates;
      if (options.coarsen > 0 && !options.all_edges) {
        CoarsenOptions co;
        co.max_width = options.coarsen * result.voxels.grid.h;
        CoarsenStats coarse_stats;
        QuadComplex coarse = coarsen_complex(cage, full, co, &coarse_stats);
        if (options.simplify && refined == 0 && !simplified) {
          simplified = true;
          try {
            SimplifiedLayout sl = simplified_layout(
                cage, coarse_stats.chords_collapsed > 0 ? coarse : full, mesh, options);
            result.layout = std::move(sl.layout);
            result.simplify = sl.stats;
            result.simplified = true;
            complex = std::move(sl.complex);
            stats = coarse_stats;
            stats.nodes_after = static_cast<int>(complex.node_vertex.size());
            stats.arcs_after = static_cast<int>(complex.arcs.size());
            stats.patches_after = complex.num_patches;
            cage = std::move(sl.fine);
            chosen = 0;
          } catch (const InvalidInputError& e) {
            failures.push_back(name + ": simplified layout: " + e.what());
          }
        }
        if (coarse_stats.chords_collapsed > 0)
          candidates.emplace_back(std::move(coarse), coarse_stats);
      }
      CoarsenStats plain;
      plain.nodes_before = plain.nodes_after = static_cast<int>(full.node_vertex.size());
      plain.arcs_before = plain.arcs_after = static_cast<int>(full.arcs.size());
      plain.patches_before = plain.patches_after = full.num_patches;
      candidates.emplace_back(full, plain);
      for (size_t k = 0; k < candidates.size() && chosen < 0; ++k) {
        try {
          result.layout = transfer_complex(cage, candidates[k].first, mesh, options.transfer);
          chosen = static_cast<int>(k);
          complex = std::move(candidates[k].first);
          stats = candidates[k].second;
        } catch (const InvalidInputError& e) {
          // import-quads' hint about its --coarsen option does not apply here.
          std::string why = e.what();
          why = why.substr(0, why.find("; --coarsen"));
          failures.push_back(name + ": " + std::to_string(cage.n_faces()) + " cage quads" + level +
                             ", " + std::to_string(candidates[k].first.num_patches) + " patches" +
                             (candidates[k].second.chords_collapsed ? " (coarsened)" : "") + ", " +
                             std::to_string(folded) + " folded; transfer failed: " + why);
        }
      }
    }
    if (chosen < 0) continue;
    result.resolution = resolution;
    result.shift = shift;
    result.refined = refined - 1;
    result.folded_quads = folded;
    result.complex = std::move(complex);
    result.coarsen = stats;
    result.layout.mesh_vertices = static_cast<int>(mesh.n_vertices());
    result.layout.mesh_faces = static_cast<int>(mesh.n_faces());
    for (const auto& f : failures) result.warnings.push_back("skipped " + f);
    if (folded > 0) {
      result.warnings.push_back(
          std::to_string(folded) +
          " cage quad(s) were folded after fitting (the transferred layout still "
          "validated)");
    }
    result.cage = std::move(cage);
    return result;
  }
  std::string msg = "no voxel cage gave a valid layout on this mesh (genus " +
                    std::to_string(mesh_report.genus) + ", " + std::to_string(mesh.n_faces()) +
                    " faces); thin parts or narrow gaps need a finer resolution, dense cages "
                    "a finer mesh:";
  for (const auto& f : failures) msg += "\n  " + f.substr(0, 400);
  throw InvalidInputError(msg);
}

}  // namespace qs
