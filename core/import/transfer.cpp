#include "core/import/transfer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <string>

#include "core/base/errors.h"
#include "core/import/cage_projection.h"
#include "core/import/dense_cage.h"
#include "core/layout/validate.h"
#include "core/mesh/write_checks.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string join_ids(const std::vector<int>& ids, size_t max_count = 20) {
  std::ostringstream ss;
  for (size_t i = 0; i < ids.size() && i < max_count; ++i) ss << (i ? ", " : "") << ids[i];
  if (ids.size() > max_count) ss << ", ... (" << ids.size() << " in all)";
  return ss.str();
}

std::string format_length(double d) {
  std::ostringstream ss;
  ss.precision(3);
  ss << d;
  return ss.str();
}

double mean_edge_length(const TriMesh& mesh) {
  double sum = 0;
  for (const auto e : mesh.edges()) sum += mesh.calc_edge_length(e);
  return mesh.n_edges() > 0 ? sum / static_cast<double>(mesh.n_edges()) : 0.0;
}

double bbox_diagonal(const TriMesh& mesh) {
  const double inf = std::numeric_limits<double>::infinity();
  Vec3 lo(inf, inf, inf), hi(-inf, -inf, -inf);
  for (const auto v : mesh.vertices()) {
    lo.minimize(mesh.point(v));
    hi.maximize(mesh.point(v));
  }
  return mesh.n_vertices() > 0 ? (hi - lo).norm() : 0.0;
}

// Nodes and quads near the dense vertices farther than max_distance from the target.
void require_near(const DenseCage& dense, const ProjectedCage& projected,
                  const QuadComplex& complex, double max_distance, double fraction) {
  const PolyMesh& m = dense.mesh;
  std::vector<int> quads, nodes;
  double worst = 0;
  for (const auto v : m.vertices()) {
    const double d = projected.offset[v.idx()];
    if (!(d > max_distance)) continue;
    worst = std::max(worst, d);
    for (const auto f : m.vf_range(v)) quads.push_back(dense.quad_of_face[f.idx()]);
  }
  if (quads.empty()) return;
  for (size_t n = 0; n < complex.node_vertex.size(); ++n)
    if (projected.offset[complex.node_vertex[n]] > max_distance)
      nodes.push_back(static_cast<int>(n));
  std::sort(quads.begin(), quads.end());
  quads.erase(std::unique(quads.begin(), quads.end()), quads.end());
  std::string msg = "the quad mesh does not lie on the target mesh: parts of it are farther than " +
                    format_length(max_distance) + " (" + format_length(100 * fraction) +
                    "% of the target's bounding-box diagonal) from its surface, up to " +
                    format_length(worst) + ": quads " + join_ids(quads);
  if (!nodes.empty()) {
    msg += ";";
    for (size_t i = 0; i < nodes.size() && i < 10; ++i) {
      const int n = nodes[i];
      msg += std::string(i ? "," : "") + " node " + std::to_string(n) + " (quad vertex " +
             std::to_string(complex.node_vertex[n]) + ", " +
             format_length(projected.offset[complex.node_vertex[n]]) + " away)";
    }
    if (nodes.size() > 10) msg += ", ...";
  }
  throw InvalidInputError(msg);
}

void require_unfolded(const CageFolds& folds, const QuadComplex& complex, bool split) {
  if (folds.quads.empty() && folds.vertices.empty()) return;
  std::string msg = "the quad mesh folds when projected onto the target mesh";
  if (!folds.quads.empty()) {
    msg += ": quads " + join_ids(folds.quads) + " turn over" +
           (split ? " (quads of the cage's first Catmull-Clark step)" : "");
  }
  if (!folds.vertices.empty()) {
    std::vector<std::string> names;
    for (int v : folds.vertices) {
      const auto it = std::lower_bound(complex.node_vertex.begin(), complex.node_vertex.end(), v);
      const int n = static_cast<int>(it - complex.node_vertex.begin());
      names.push_back("node " + std::to_string(n) + " (quad vertex " + std::to_string(v) + ")");
    }
    msg += std::string(folds.quads.empty() ? ": " : "; ") +
           "the arcs around nodes do not keep their order: ";
    for (size_t i = 0; i < names.size() && i < 20; ++i) msg += (i ? ", " : "") + names[i];
    if (names.size() > 20) msg += ", ... (" + std::to_string(names.size()) + " in all)";
  }
  throw InvalidInputError(msg);
}

// The segments of the arcs' projected polylines in a uniform grid, for the distance from a
// point to the other arcs.
class SegmentGrid {
 public:
  SegmentGrid(const std::vector<std::vector<Vec3>>& polylines, double cell)
      : polylines_(polylines), cell_(cell) {
    for (size_t a = 0; a < polylines.size(); ++a) {
      for (size_t k = 0; k + 1 < polylines[a].size(); ++k) {
        const Vec3& p = polylines[a][k];
        const Vec3& q = polylines[a][k + 1];
        Vec3 lo = p, hi = p;
        lo.minimize(q);
        hi.maximize(q);
        for_cells(lo, hi, [&](const Key& key) {
          cells_[key].push_back({static_cast<int>(a), static_cast<int>(k)});
        });
      }
    }
  }

  //! Whether a segment of an arc other than \p arc passes within \p radius of \p x.
  bool near_other(const Vec3& x, double radius, int arc) const {
    const Vec3 r(radius, radius, radius);
    bool found = false;
    for_cells(x - r, x + r, [&](const Key& key) {
      if (found) return;
      const auto it = cells_.find(key);
      if (it == cells_.end()) return;
      for (const auto& [a, k] : it->second) {
        if (a == arc) continue;
        const Vec3& p = polylines_[a][k];
        const Vec3 d = polylines_[a][k + 1] - p;
        const double l2 = d.sqrnorm();
        const double t = l2 > 0 ? std::clamp(((x - p) | d) / l2, 0.0, 1.0) : 0.0;
        if ((x - (p + t * d)).norm() < radius) {
          found = true;
          return;
        }
      }
    });
    return found;
  }

 private:
  using Key = std::array<long, 3>;
  template <typename F>
  void for_cells(const Vec3& lo, const Vec3& hi, F&& f) const {
    Key a, b;
    for (int i = 0; i < 3; ++i) {
      a[i] = static_cast<long>(std::floor(lo[i] / cell_));
      b[i] = static_cast<long>(std::floor(hi[i] / cell_));
    }
    for (long x = a[0]; x <= b[0]; ++x)
      for (long y = a[1]; y <= b[1]; ++y)
        for (long z = a[2]; z <= b[2]; ++z) f(Key{x, y, z});
  }

  const std::vector<std::vector<Vec3>>& polylines_;
  double cell_;
  std::map<Key, std::vector<std::pair<int, int>>> cells_;
};

// The layout to embed: node points and arc polylines on the target. A polyline point that
// comes closer than a quarter of its dense edges' mean length to another arc's polyline is
// dropped (where arcs touch, e.g. the shared walks of a coarsened complex near merged nodes,
// the points do not tell which arc runs on which side; the routes decide), except on the
// target's boundary (boundary arcs keep their points to stay on it).
Layout surface_layout(const DenseCage& dense, const ProjectedCage& projected,
                      const QuadComplex& complex) {
  const PolyMesh& m = dense.mesh;
  std::vector<std::vector<Vec3>> polylines(complex.arcs.size());
  double mean_edge = 0;
  int segments = 0;
  for (size_t a = 0; a < complex.arcs.size(); ++a) {
    for (int v : dense.arc_chains[a]) polylines[a].push_back(projected.position[v]);
    for (size_t k = 0; k + 1 < polylines[a].size(); ++k, ++segments)
      mean_edge += (polylines[a][k + 1] - polylines[a][k]).norm();
  }
  mean_edge = segments > 0 ? mean_edge / segments : 1.0;
  const SegmentGrid grid(polylines, std::max(mean_edge, 1e-300));
  auto crowded = [&](int a, int v) {
    if (m.is_boundary(VH(v))) return false;
    double edge = 0;
    int n = 0;
    for (const auto u : m.vv_range(VH(v))) {
      edge += (projected.position[u.idx()] - projected.position[v]).norm();
      ++n;
    }
    return n > 0 && grid.near_other(projected.position[v], 0.1 * edge / n, a);
  };
  Layout layout;
  for (size_t n = 0; n < complex.node_vertex.size(); ++n) {
    LayoutNode node;
    node.id = static_cast<int>(n);
    node.point = projected.point[complex.node_vertex[n]];
    layout.nodes.push_back(node);
  }
  for (size_t a = 0; a < complex.arcs.size(); ++a) {
    const std::vector<int>& chain = dense.arc_chains[a];
    LayoutArc arc;
    arc.id = static_cast<int>(a);
    arc.from = complex.arcs[a].from;
    arc.to = complex.arcs[a].to;
    for (size_t k = 1; k + 1 < chain.size(); ++k)
      if (!crowded(static_cast<int>(a), chain[k])) arc.points.push_back(projected.point[chain[k]]);
    if (chain.size() == 2) {
      // A single boundary edge gets its midpoint, so that the arc is known to follow the
      // boundary (an interior edge may join two boundary vertices too).
      const auto h = m.find_halfedge(VH(chain[0]), VH(chain[1]));
      if (h.is_valid() && projected.boundary_midpoint[m.edge_handle(h).idx()].face >= 0)
        arc.points.push_back(projected.boundary_midpoint[m.edge_handle(h).idx()]);
    }
    layout.arcs.push_back(std::move(arc));
  }
  return layout;
}

// Patch count and cyclic orders of the embedded layout against the complex.
void require_same_structure(const TriMesh& mesh, const Layout& layout, const QuadComplex& complex,
                            bool reversed) {
  const LayoutTopology topo = build_topology(mesh, layout);
  std::vector<int> bad;
  for (size_t n = 0; n < complex.node_vertex.size(); ++n) {
    std::vector<int> expected = complex.node_half_arcs[n];
    if (reversed) std::reverse(expected.begin(), expected.end());
    if (!same_cycle(expected, topo.node_half_arcs[n])) bad.push_back(static_cast<int>(n));
  }
  if (!bad.empty()) {
    throw InvalidInputError(
        "the transferred layout changes the cyclic order of the arcs at nodes " + join_ids(bad));
  }
  if (static_cast<int>(topo.patches.size()) != complex.num_patches) {
    throw InvalidInputError("the transferred layout has " + std::to_string(topo.patches.size()) +
                            " patches, the quad mesh's layout " +
                            std::to_string(complex.num_patches));
  }
}

}  // namespace

void validate_transfer_options(const TransferOptions& options) {
  if (!(options.max_distance_fraction > 0 && options.max_distance_fraction <= 1))
    throw InvalidInputError("transfer: max_distance_fraction must be in (0, 1], got " +
                            std::to_string(options.max_distance_fraction));
  if (!(options.dense_edge_factor >= 0.5 && options.dense_edge_factor <= 100))
    throw InvalidInputError("transfer: dense_edge_factor must be in [0.5, 100], got " +
                            std::to_string(options.dense_edge_factor));
  validate_embed_options(options.embed);
}

TransferResult transfer_quads(const PolyMesh& cage, const PolyMesh& quads,
                              const QuadComplex& complex, std::shared_ptr<const TriMesh> target,
                              const TransferOptions& options) {
  validate_transfer_options(options);
  if (!target || target->n_faces() == 0) throw InvalidInputError("the target mesh has no faces");
  TransferResult result;
  TransferStats& stats = result.stats;
  stats.input_vertices = static_cast<int>(target->n_vertices());
  stats.input_faces = static_cast<int>(target->n_faces());

  auto t0 = Clock::now();
  DenseCageOptions dense_options;
  dense_options.max_mean_edge = options.dense_edge_factor * mean_edge_length(*target);
  dense_options.max_faces = 4 * target->n_faces() + 1024;
  const DenseCage dense = subdivide_cage(cage, quads, complex, dense_options);
  stats.levels = dense.levels;
  stats.dense_vertices = static_cast<int>(dense.mesh.n_vertices());
  stats.dense_faces = static_cast<int>(dense.mesh.n_faces());
  stats.subdivide_s = seconds_since(t0);

  t0 = Clock::now();
  const ProjectedCage projected = project_cage(dense, *target);
  const double diagonal = bbox_diagonal(*target);
  const double worst = *std::max_element(projected.offset.begin(), projected.offset.end());
  stats.max_offset = diagonal > 0 ? worst / diagonal : 0.0;
  stats.flow_steps = projected.flow_steps;
  require_near(dense, projected, complex, options.max_distance_fraction * diagonal,
               options.max_distance_fraction);
  const CageFolds folds = find_folds(dense, projected, *target, complex.node_vertex);
  stats.reversed = folds.reversed;
  stats.relaxed_vertices = projected.relaxed_vertices;
  require_unfolded(folds, complex, !is_pure_quad(cage));
  stats.project_s = seconds_since(t0);

  t0 = Clock::now();
  EmbedOptions embed = options.embed;
  embed.through_points = true;
  EmbeddedLayout e = embed_layout(target, surface_layout(dense, projected, complex), embed);
  stats.embed = e.stats;
  stats.embed_s = seconds_since(t0);

  t0 = Clock::now();
  const TriMesh& w = e.mesh->mesh();
  for (LayoutNode& node : e.layout.nodes) node.point.reset();
  e.layout.mesh_vertices = static_cast<int>(w.n_vertices());
  e.layout.mesh_faces = static_cast<int>(w.n_faces());
  require_valid_layout(w, e.layout, "the transferred layout");
  require_same_structure(w, e.layout, complex, stats.reversed);
  const MeshReport report = check_as_read(w);
  if (!report.ok()) throw InvalidInputError(rejection_message(report, "the working mesh"));
  stats.check_s = seconds_since(t0);

  stats.working_vertices = static_cast<int>(w.n_vertices());
  stats.working_faces = static_cast<int>(w.n_faces());
  stats.growth = e.mesh->growth();
  stats.max_origin_error = e.mesh->max_origin_error();
  stats.min_angle_deg = e.mesh->min_angle_deg();
  result.mesh = e.mesh;
  result.layout = std::move(e.layout);
  return result;
}

}  // namespace qs
