#include "core/nodeopt/symmetric_step.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/base/errors.h"

namespace qs {

namespace {

double diagonal(const TriMesh& mesh) {
  bool first = true;
  Vec3 lo(0, 0, 0), hi(0, 0, 0);
  for (const auto vh : mesh.vertices()) {
    const Vec3& p = mesh.point(vh);
    if (first) {
      lo = hi = p;
      first = false;
    } else {
      lo.minimize(p);
      hi.maximize(p);
    }
  }
  return (hi - lo).norm();
}

// \throw InvalidInputError unless \p mirror has one mutual entry per node of \p layout.
void check_node_mirror(const std::vector<int>& mirror, const Layout& layout) {
  const int n = int(layout.nodes.size());
  if (int(mirror.size()) != n)
    throw InvalidInputError("node symmetry: " + std::to_string(mirror.size()) +
                            " mirror indices for a layout of " + std::to_string(n) + " nodes");
  for (int i = 0; i < n; ++i) {
    const int j = mirror[i];
    if (j < 0 || j >= n || mirror[j] != i)
      throw InvalidInputError("node symmetry: node " + std::to_string(layout.nodes[i].id) +
                              " has no mutual mirror node (mirror index " + std::to_string(j) +
                              ")");
  }
}

// The positions of the nodes' vertices.
std::vector<Vec3> node_points(const TriMesh& mesh, const Layout& layout) {
  std::vector<Vec3> out;
  out.reserve(layout.nodes.size());
  for (const LayoutNode& node : layout.nodes)
    out.push_back(mesh.point(OpenMesh::VertexHandle(node.vertex)));
  return out;
}

}  // namespace

std::optional<GeodesicTrace> symmetric_trace(const SymmetricTarget& target) {
  if (!target.moves) return std::nullopt;
  GeodesicTrace trace;
  trace.end = target.point;
  trace.end_position = target.position;
  return trace;
}

std::shared_ptr<const NodeSymmetry> make_node_symmetry(const TriMesh& mesh, const Layout& layout,
                                                       const MirrorPlane& plane,
                                                       const SymmetryPairOptions& options) {
  const SymmetryPairs pairs = find_mirror_pairs(mesh, layout, plane, options);
  auto out = std::make_shared<NodeSymmetry>();
  out->plane = plane;
  out->node_mirror = pairs.node_mirror;
  return out;
}

NodeOptOptions symmetric_node_options(const NodeOptOptions& options) {
  if (!options.moves.symmetry) return options;
  NodeOptOptions out = options;
  out.polish.enabled = false;
  out.moves.slide_on_curves = false;
  out.moves.separate_crowded_nodes = false;
  return out;
}

SymmetricStepper::SymmetricStepper(const TriMesh& original, const Layout& layout,
                                   std::shared_ptr<const NodeSymmetry> symmetry)
    : original_(original),
      symmetry_(std::move(symmetry)),
      tree_(original),
      tolerance_(1e-12 * diagonal(original)) {
  if (!symmetry_) throw InvalidInputError("node symmetry: none given");
  check_node_mirror(symmetry_->node_mirror, layout);
}

std::vector<SymmetricTarget> SymmetricStepper::targets(
    const std::vector<SurfacePoint>& anchors, const std::vector<int>& movable,
    const std::function<std::optional<SurfacePoint>(std::size_t)>& propose) const {
  const std::size_t n = anchors.size();
  std::vector<SurfacePoint> proposed = anchors;
  std::vector<char> fixed(n, 1);
  for (std::size_t i = 0; i < movable.size(); ++i) {
    fixed[movable[i]] = 0;
    if (const std::optional<SurfacePoint> p = propose(i)) proposed[movable[i]] = *p;
  }
  const std::vector<SurfacePoint> symmetric = symmetrize_targets(
      original_, tree_, symmetry_->plane, symmetry_->node_mirror, proposed, fixed);
  std::vector<SymmetricTarget> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    SymmetricTarget& t = out[k];
    t.point = symmetric[k];
    t.position = surface_point_position(original_, t.point);
    t.moves = !fixed[k] &&
              (t.position - surface_point_position(original_, anchors[k])).norm() > tolerance_;
  }
  return out;
}

bool SymmetricStepper::hold_unmatched(const TriMesh& before_mesh, const Layout& before_layout,
                                      const TriMesh& after_mesh, const Layout& after_layout,
                                      std::vector<SymmetricTarget>& targets) const {
  const std::vector<int>& mirror = symmetry_->node_mirror;
  const std::vector<Vec3> before = node_points(before_mesh, before_layout);
  const std::vector<Vec3> after = node_points(after_mesh, after_layout);
  const MirrorPlane& plane = symmetry_->plane;
  const auto near = [&](const Vec3& a, const Vec3& b) { return (a - b).norm() <= tolerance_; };
  const auto reached = [&](int k) { return near(after[k], targets[k].position); };
  const auto stayed = [&](int k) { return near(after[k], before[k]); };
  bool changed = false;
  for (int i = 0; i < int(mirror.size()); ++i) {
    const int j = mirror[i];
    if (j < i || (!targets[i].moves && !targets[j].moves)) continue;
    const bool matched =
        j == i ? reached(i) || stayed(i) || std::abs(plane.signed_distance(after[i])) <= tolerance_
               : (reached(i) && reached(j)) || (stayed(i) && stayed(j)) ||
                     near(plane.reflect(after[i]), after[j]);
    if (matched) continue;
    targets[i].moves = targets[j].moves = false;
    changed = true;
  }
  return changed;
}

NodeSymmetryMeasure measure_node_symmetry(const TriMesh& mesh, const Layout& layout,
                                          const NodeSymmetry& symmetry) {
  const std::vector<int>& mirror = symmetry.node_mirror;
  if (mirror.size() != layout.nodes.size())
    throw InvalidInputError("node symmetry: " + std::to_string(mirror.size()) +
                            " mirror indices for a layout of " +
                            std::to_string(layout.nodes.size()) + " nodes");
  const int nv = int(mesh.n_vertices());
  const auto position = [&](int k) {
    const int v = layout.nodes[k].vertex;
    if (v < 0 || v >= nv)
      throw InvalidInputError("node symmetry: node " + std::to_string(layout.nodes[k].id) +
                              " has no vertex of the mesh");
    return mesh.point(OpenMesh::VertexHandle(v));
  };
  const double d = std::max(diagonal(mesh), 1e-300);
  NodeSymmetryMeasure m;
  for (int i = 0; i < int(mirror.size()); ++i) {
    const int j = mirror[i];
    if (j < i) continue;
    if (j == i) {
      ++m.plane_nodes;
      m.max_plane_error =
          std::max(m.max_plane_error, std::abs(symmetry.plane.signed_distance(position(i))) / d);
    } else {
      ++m.pairs;
      m.max_pair_error = std::max(m.max_pair_error,
                                  (symmetry.plane.reflect(position(i)) - position(j)).norm() / d);
    }
  }
  return m;
}

}  // namespace qs
