// Closest points on a triangle mesh: a bounding volume hierarchy over its faces.
#pragma once

#include <array>
#include <functional>
#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

//! Closest point on a triangle (Euclidean). bary[k] is the weight of the k-th corner.
struct TrianglePoint {
  Vec3 point{0, 0, 0};
  std::array<double, 3> bary{{1, 0, 0}};
  double distance = 0;  //!< same length unit as the mesh coordinates
};

//! The point of triangle (a, b, c) closest to \p p (degenerate triangles are handled: the
//! result is then on one of their edges).
TrianglePoint closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

//! A surface point of the mesh closest to a query.
struct ClosestPoint {
  int face = -1;                          //!< face index
  std::array<double, 3> bary{{1, 0, 0}};  //!< w.r.t. the face's vertices in fv order
  Vec3 point{0, 0, 0};
  double distance = 0;
};

//! Bounding volume hierarchy (axis-aligned boxes, median splits, a few faces per leaf) over
//! the faces of a triangle mesh, for closest-point queries in O(log #F) typical time. The tree
//! copies the face corners, so the mesh may be destroyed afterwards (not moved vertices: then
//! build a new tree).
class ClosestPointTree {
 public:
  //! \pre every face of \p mesh is a triangle with finite coordinates.
  explicit ClosestPointTree(const TriMesh& mesh);

  //! The closest surface point to \p p (ties: the face found first). face == -1 only for a
  //! mesh without faces.
  ClosestPoint closest(const Vec3& p) const;
  //! The closest surface point to \p p among the faces for which \p accept(face) is true
  //! (face == -1 when there is none).
  ClosestPoint closest(const Vec3& p, const std::function<bool(int)>& accept) const;

 private:
  struct Node {
    Vec3 lo, hi;    // bounding box
    int begin = 0;  // range in order_ for leaves
    int end = 0;
    int left = -1;  // children (-1 for a leaf)
    int right = -1;
  };
  int build(int begin, int end);
  static double box_distance_sq(const Node& node, const Vec3& p);

  std::vector<std::array<Vec3, 3>> corners_;  // per face
  std::vector<int> order_;                    // face indices, grouped by leaf
  std::vector<Node> nodes_;
};

}  // namespace qs
