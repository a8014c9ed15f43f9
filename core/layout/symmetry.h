// Mirror symmetry of a mesh and of a layout on it: a mirror plane (an axis plane through the
// mesh centre, or fitted to the mesh), reflection of surface points, mirror pairs of nodes and
// arcs, and the symmetrization of proposed node targets for the node optimizer.
#pragma once

#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/layout/routing.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh.h"
#include "core/mesh/surface_point.h"

namespace qs {

//! The plane normal · x = offset (unit normal; offset in mesh length units).
struct MirrorPlane {
  Vec3 normal{1, 0, 0};
  double offset = 0;
  //! Signed distance of \p x from the plane (positive on the normal's side).
  double signed_distance(const Vec3& x) const { return OpenMesh::dot(normal, x) - offset; }
  //! The mirror image of \p x.
  Vec3 reflect(const Vec3& x) const { return x - 2.0 * signed_distance(x) * normal; }
  //! The orthogonal projection of \p x onto the plane.
  Vec3 project(const Vec3& x) const { return x - signed_distance(x) * normal; }
};

//! "normal (1, 0, 0), offset 0.25" for messages.
std::string describe_plane(const MirrorPlane& plane);

//! How the mirror plane is chosen: the plane x, y or z = const through the centre of the mesh's
//! bounding box, or fitted to the mesh (fit_mirror_plane).
enum class SymmetryAxis { X, Y, Z, Auto };

//! "x", "y", "z" or "auto".
const char* to_string(SymmetryAxis axis);
//! The axis named "x", "y", "z" or "auto". \throw InvalidInputError naming \p name otherwise.
SymmetryAxis parse_symmetry_axis(const std::string& name);

struct SymmetryFitOptions {
  //! Vertices used as samples (every k-th vertex when the mesh has more). >= 16.
  int max_samples = 2000;
  //! Closest-point (ICP-style) refinement iterations per candidate plane. In [0, 1000].
  int iterations = 30;
};

//! \throw InvalidInputError naming the option when a value is out of range.
void validate_symmetry_fit_options(const SymmetryFitOptions& options);

//! A mirror plane and how well it maps the mesh onto itself: the distances from the reflected
//! samples (mesh vertices, weighted by their area) to the surface.
struct SymmetryFit {
  MirrorPlane plane;
  double rms = 0;       //!< area-weighted root mean square distance (mesh length units)
  double max = 0;       //!< largest distance (mesh length units)
  double relative = 0;  //!< rms / bounding-box diagonal
};

//! The plane x (axis 0), y (1) or z (2) = const through the centre of the mesh's bounding box.
//! \throw InvalidInputError for another axis or a mesh without vertices.
MirrorPlane axis_plane(const TriMesh& mesh, int axis);

//! The residual of \p plane on \p mesh (\p tree: a ClosestPointTree of the same mesh).
SymmetryFit measure_symmetry(const TriMesh& mesh, const ClosestPointTree& tree,
                             const MirrorPlane& plane, const SymmetryFitOptions& options = {});

//! The mirror plane that maps the mesh onto itself best: candidates through the area-weighted
//! centroid of the vertex samples, normal to each principal axis of their covariance and to each
//! coordinate axis, each refined by closest-point iterations (reflect every sample p, take the
//! closest surface point q): first bisector steps (the plane normal to the dominant direction of
//! p − q, through the mean of the midpoints), then point-to-plane Gauss-Newton steps (the plane
//! change that moves the reflections onto the tangent planes at q), kept when they lower the
//! residual. The candidate with the least rms residual wins. Deterministic.
//! \throw InvalidInputError for a mesh without faces or invalid options.
SymmetryFit fit_mirror_plane(const TriMesh& mesh, const ClosestPointTree& tree,
                             const SymmetryFitOptions& options = {});

//! axis_plane (measured) for X, Y, Z; fit_mirror_plane for Auto.
SymmetryFit mirror_plane(const TriMesh& mesh, const ClosestPointTree& tree, SymmetryAxis axis,
                         const SymmetryFitOptions& options = {});

//! The 3D position of surface point \p p of \p mesh. \throw InvalidInputError for a face out
//! of range.
Vec3 surface_point_position(const TriMesh& mesh, const SurfacePoint& p);

//! A surface point as the closest point of the mesh to a 3D point.
struct ProjectedPoint {
  SurfacePoint point;
  Vec3 position{0, 0, 0};
  double distance = 0;  //!< from the 3D point to the surface (mesh length units)
};

//! The closest surface point to \p x.
ProjectedPoint project_to_surface(const ClosestPointTree& tree, const Vec3& x);

//! The mirror image of surface point \p p: its 3D point reflected, then the closest point of the
//! mesh (exact up to rounding on a mesh whose tessellation is symmetric).
ProjectedPoint reflect_surface_point(const TriMesh& mesh, const ClosestPointTree& tree,
                                     const MirrorPlane& plane, const SurfacePoint& p);

//! The vertex nearest to the mirror image of vertex \p v: among the corners of the face closest
//! to the reflected point and their neighbours. \throw InvalidInputError for a bad vertex.
int mirror_vertex(const TriMesh& mesh, const ClosestPointTree& tree, const MirrorPlane& plane,
                  int v);

//! A vertex on (or nearest to) the plane near \p x: among the corners of the face closest to
//! x's projection onto the plane and their neighbours, the one with the least distance from
//! the plane (ties within 1e-9 of the diagonal: the one nearest to the projection).
int plane_vertex(const TriMesh& mesh, const ClosestPointTree& tree, const MirrorPlane& plane,
                 const Vec3& x);

//! The mirror image of the vertex path \p path: every vertex mirrored (mirror_vertex; the ends
//! replaced by \p first / \p last when they are >= 0), consecutive duplicates dropped, and
//! consecutive vertices joined by shortest paths that avoid \p obstacles (routing.h rules; the
//! ends may be blocked) and the path's own earlier vertices. On a symmetrically tessellated mesh
//! the mirror of an edge path is again an edge path and is returned as is. Empty when a piece
//! cannot be joined.
std::vector<int> mirror_path(const TriMesh& mesh, const ClosestPointTree& tree,
                             const MirrorPlane& plane, const std::vector<int>& path,
                             const RoutingObstacles& obstacles, int first = -1, int last = -1);

struct SymmetryPairOptions {
  //! Nodes pair when the reflection of one lies within the tolerance of the other; arcs when
  //! every reflected vertex of one lies within it of the other's polyline. The tolerance is
  //! the larger of `tolerance` × the bounding-box diagonal and `edge_lengths` × the mean edge
  //! length: a node on a vertex can be no closer to its mirror image than the tessellation
  //! allows (the editor's mirrored sketching pairs within 1.5 mean edges). `tolerance` in
  //! (0, 1], `edge_lengths` ≥ 0 (0: the diagonal's fraction alone).
  double tolerance = 1e-2;
  double edge_lengths = 1.5;
};

//! Mirror pairs of a layout's nodes and arcs. Node positions are their vertices' (their `point`
//! when the vertex is -1).
struct SymmetryPairs {
  //! Per node index: the index of its mirror node (itself for a node on the plane), -1 when
  //! unpaired. Size #nodes.
  std::vector<int> node_mirror;
  //! Per arc index: the index of its mirror arc (itself for an arc that is its own mirror
  //! image, e.g. one crossing the plane between a pair of nodes), -1 when unpaired.
  std::vector<int> arc_mirror;
  //! Largest distance between a paired node's reflection and its mirror, and between a paired
  //! arc's reflected vertices and its mirror's polyline, as fractions of the diagonal.
  double node_error = 0;
  double arc_error = 0;
  //! Index of the first node / arc (layout order) without a mirror, -1 when all are paired.
  int first_unpaired_node = -1;
  int first_unpaired_arc = -1;
  //! Why the first unpaired node or arc has no mirror ("" when the layout is symmetric).
  std::string problem;
  bool symmetric() const { return first_unpaired_node < 0 && first_unpaired_arc < 0; }
};

//! Pairs each node with the node nearest to its reflection when the pairing is mutual and
//! within the tolerance, and each arc with the arc joining its ends' mirrors that follows its
//! reflection best (within the tolerance). Never throws for asymmetric layouts (unpaired: -1);
//! \throw InvalidInputError for a tolerance outside (0, 1] or a node without a valid vertex
//! or point.
SymmetryPairs match_mirror_pairs(const TriMesh& mesh, const Layout& layout,
                                 const MirrorPlane& plane, const SymmetryPairOptions& options = {});

//! match_mirror_pairs for a layout that must be symmetric. \throw InvalidInputError
//! "the layout is not mirror symmetric about the plane (…): node 7 (vertex 123) has no mirror
//! node …" naming the first unpaired node, else the first unpaired arc.
SymmetryPairs find_mirror_pairs(const TriMesh& mesh, const Layout& layout, const MirrorPlane& plane,
                                const SymmetryPairOptions& options = {});

//! Symmetric node targets for the node optimizer. \p targets: per node index, a proposed
//! target (surface point of \p mesh); \p node_mirror: SymmetryPairs::node_mirror (-1: the node
//! keeps its target); \p fixed (empty, or per node): nodes that keep their target (pinned). For
//! a pair (i, j): c = (x_i + R(x_j)) / 2, and i goes to the surface point closest to c, j to the
//! surface point closest to the reflection of i's new target (when one of them is fixed, the
//! other goes to the reflection of the fixed one's target; both fixed: unchanged). A node that
//! is its own mirror goes to the point of the curve where the plane cuts the surface nearest to
//! the projection of its target onto the plane (unless fixed).
//! \throw InvalidInputError when the sizes differ, a mirror index is out of range, or the
//! pairing is not mutual (node_mirror[node_mirror[i]] != i).
std::vector<SurfacePoint> symmetrize_targets(const TriMesh& mesh, const ClosestPointTree& tree,
                                             const MirrorPlane& plane,
                                             const std::vector<int>& node_mirror,
                                             const std::vector<SurfacePoint>& targets,
                                             const std::vector<char>& fixed = {});

}  // namespace qs
