// WorkingMesh: a triangle mesh W refined from an input mesh by exact local edits (edge splits,
// face splits, flips inside one input face, collapses of refinement vertices, vertex moves
// inside their carrier), so that W always covers exactly the input surface (docs/design.md,
// "Working mesh").
#pragma once

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/mesh/mesh.h"
#include "core/mesh/surface_point.h"

namespace qs {

struct WorkingMeshOptions {
  //! insert_point reuses a vertex, or splits an edge at the projected point, when it lies
  //! within snap × (mean edge length of the W face that contains the point). In [0, 0.5].
  double snap = 0.1;
  //! Quality bar (degrees) for insert_point's choice between candidates and for
  //! can_move_vertex. In [0, 60).
  double min_angle_deg = 1.0;
};

//! \throw InvalidInputError naming the option when a value is out of range or not finite.
void validate_working_mesh_options(const WorkingMeshOptions& options);

//! The working mesh W of an input triangle mesh (docs/design.md, "Working mesh").
//!
//! Representation:
//! - W vertices 0..n-1 are the n input vertices in input order, never moved or removed.
//!   Every other vertex is a refinement vertex.
//! - Every W vertex has an origin: an input face and barycentric coordinates w.r.t. its corners
//!   (OpenMesh face-vertex order of the input face). W's position of a vertex is always
//!   position(origin), computed from the input corners (bit-identical, never interpolated from
//!   W positions). Input vertices have the corner of an incident input face as origin.
//! - Every W face has a host: the input face it lies in. The W faces of one host tile it
//!   exactly (in barycentric coordinates every W face is positively oriented), so the union of
//!   all W faces is the input surface as a point set.
//! - Barycentric coordinates that are exactly 0 encode the carrier of a vertex: one zero = on
//!   the interior of an input edge (valid in both adjacent input faces), two zeros = an input
//!   vertex. Geometric predicates use barycentric triple products, which are exactly 0 for
//!   points of one input edge, so vertices on input edges stay exactly on them.
//!
//! Indices: editing never changes the index of an existing vertex, face or edge (removed
//! elements are only marked deleted until compact()). Face-vertex order of an edited face may
//! rotate. Location results, and the references origin() and hosted_faces() return, are valid
//! until the next edit. locate() and insert_point() scan the W faces of one host: O(number of
//! W faces in that input face).
//!
//! Errors: element indices out of range or deleted, parameters outside the element (t outside
//! (0,1), barycentrics outside the face or not summing to 1) throw InvalidInputError naming the
//! element. Operations that would break exactness or orientation return false and change
//! nothing.
class WorkingMesh {
 public:
  //! W starts as a copy of \p input (same vertex, edge, halfedge and face indices; host(f) = f).
  //! \throw InvalidInputError if input is null, has no faces, has deleted elements or a vertex
  //! without faces, or if the options are invalid.
  explicit WorkingMesh(std::shared_ptr<const TriMesh> input, WorkingMeshOptions options = {});

  //! W. Between remove_vertex() and compact() it holds elements marked deleted.
  const TriMesh& mesh() const { return mesh_; }
  const TriMesh& input() const { return *input_; }
  std::shared_ptr<const TriMesh> input_ptr() const { return input_; }
  const WorkingMeshOptions& options() const { return options_; }
  //! n: W vertices 0..n-1 are the input vertices.
  int input_vertices() const { return n_input_; }
  bool is_input_vertex(int v) const { return v >= 0 && v < n_input_; }
  //! Input face + barycentrics reproducing W's position of vertex v.
  const SurfacePoint& origin(int v) const;
  //! The input face that W face f lies in.
  int host(int f) const;
  //! The live W faces whose host is \p input_face (in no particular order).
  const std::vector<int>& hosted_faces(int input_face) const;
  //! The point of the input surface at \p p (exact at input corners and on input edges: zero
  //! weights are skipped, so a point of an input edge has the same position in both faces).
  //! \throw InvalidInputError for a face out of range.
  Vec3 position(const SurfacePoint& p) const;

  //! Where an input surface point lies in W: a W face and barycentrics w.r.t. its corners
  //! (OpenMesh face-vertex order of the W face, valid until the next edit). A point on a W edge
  //! or vertex gets one incident face; a point on an input edge gets a face with an edge along
  //! that input edge and an exact 0 for the opposite corner.
  struct Location {
    int face = -1;
    std::array<double, 3> bary{};
  };
  //! Points given to locate, insert_point and move_vertex are normalized first: components
  //! in [-1e-9, 0) are clamped to 0, and all are divided by their sum when it is more than 1e-12
  //! from 1 (an exact 0 stays 0).
  //! \throw InvalidInputError if p's face is out of range or its barycentrics are outside the
  //! face (a component below -1e-9, non-finite, or a sum more than 1e-6 from 1).
  Location locate(const SurfacePoint& p) const;
  //! The input surface point of the point with barycentrics \p bary (w.r.t. the corners of W
  //! face \p face, face-vertex order): a point of the face's host. Weights are clamped to
  //! [0, 1] and normalized. \throw InvalidInputError for an invalid face.
  SurfacePoint input_point(int face, const std::array<double, 3>& bary) const;
  //! Barycentrics of W vertex v in input face f (v must lie on f's closure, else nullopt).
  std::optional<std::array<double, 3>> bary_in_input_face(int v, int input_face) const;
  //! Barycentrics of surface point p in input face f (p on f's closure, else nullopt).
  std::optional<std::array<double, 3>> point_in_input_face(const SurfacePoint& p,
                                                           int input_face) const;

  //! Where W vertex v lies on the input: an input vertex, the interior of an input edge, or the
  //! interior of an input face (its host).
  enum class Carrier { kInputVertex, kInputEdge, kInputFace };
  Carrier carrier(int v) const;
  //! For a vertex on an input edge: the edge's input vertices (a < b); otherwise nullopt.
  std::optional<std::array<int, 2>> input_edge_of(int v) const;

  // ---- exact edits (local: O(valence) each) ----

  //! New vertex at (1-t)·a + t·b (in barycentric coordinates of a host of the edge), where
  //! a = from(halfedge(edge, 0)), b = to(halfedge(edge, 0)). Both adjacent faces are split (one
  //! on the boundary). The edge index stays on the half (new vertex, b). Returns the new
  //! vertex. A split of a W edge along an input edge gives a vertex on that input edge.
  //! \throw InvalidInputError if the edge is invalid, t is not in (0, 1), or a split triangle
  //! would not be positively oriented (t too close to 0 or 1 to separate the vertices).
  int split_edge(int edge, double t);
  //! 1→3 split at barycentrics \p bary w.r.t. the face's corners (face-vertex order); returns
  //! the new vertex (bary is normalized like a point, see locate). \throw InvalidInputError if the
  //! face is invalid, or bary has a component <= 0, is non-finite or does not sum to 1 within 1e-6
  //! (points on edges: split_edge), or a new triangle would not be positively oriented.
  int split_face(int face, const std::array<double, 3>& bary);

  //! Result of insert_point: the vertex at (or near) p, whether it lies exactly at p (origin
  //! equal to the normalized p in p's face), and whether it was created.
  struct Inserted {
    int vertex = -1;
    bool exact = true;
    bool created = false;
  };
  //! A vertex at surface point p. With f the W face containing p and ε = snap × the mean edge
  //! length of f, the candidates are, in order of preference:
  //! 1. the nearest vertex within ε of p (3D distance) among f's corners and their neighbours
  //!    for which may_reuse(v) is true (an empty may_reuse allows every vertex, input vertices
  //!    included); nothing is created;
  //! 2. a split of the nearest edge of f within ε of p at p's projection onto it (exact when p
  //!    lies on the edge);
  //! 3. the exact 1→3 split of f at p.
  //! The first candidate whose new triangles are positively oriented with smallest angle
  //! >= min(min_angle_deg, smallest angle of the faces it splits) is taken. When no candidate
  //! meets that bar (p close to a vertex that may not be reused or an edge that may not be
  //! split, or on an edge near its end), p is moved a quarter, a half, then three quarters of the
  //! way towards the centre of f (of its edge, when p lies on one of f's edges), never further
  //! than the snap distance ε, and the first of those splits that meets the bar is taken (not
  //! exact); failing that, the valid split with the
  //! largest smallest angle (inside an already bad face).
  //! Edges for which \p may_split (when given) returns false are never split (an arc's edges):
  //! p then gets a face split even when it is within ε of such an edge.
  //! \throw InvalidInputError for an invalid p, or when no vertex can be placed (p coincides
  //! with a vertex that may not be reused, or lies on an edge that may not be split).
  Inserted insert_point(const SurfacePoint& p, const std::function<bool(int)>& may_reuse = {},
                        const std::function<bool(int)>& may_split = {});

  //! Flips an edge whose two faces have the same host and form a strictly convex quad (in the
  //! host's barycentric coordinates), when the new edge does not exist yet. False (nothing
  //! changed) otherwise, including boundary edges and edges between two hosts.
  bool flip_edge(int edge);

  //! Whether move_vertex(v, p) would succeed: v is a refinement vertex and either
  //! - v is interior to its host, and p is strictly inside the same input face, or
  //! - v is on the interior of an input edge, and p is on the interior of the same input edge
  //!   (an exact 0 weight in p's face for the corner off the edge);
  //! and every triangle of v's star stays positively oriented and keeps a smallest angle of at
  //! least min_angle_deg or at least the star's smallest angle before the move.
  //! \throw InvalidInputError for an invalid vertex or point.
  bool can_move_vertex(int v, const SurfacePoint& p) const;
  //! Moves v to p (origin = the normalized p) when can_move_vertex allows it; false: nothing
  //! changed.
  bool move_vertex(int v, const SurfacePoint& p);

  //! Removes a refinement vertex by collapsing it into a neighbour u such that every remaining
  //! triangle of its star stays in its host and positively oriented: for a vertex interior to
  //! its host any neighbour, for a vertex on an input edge a neighbour on the same closed input
  //! edge. Among valid neighbours, the one giving the largest smallest angle is chosen; it must
  //! reach min(min_angle_deg, the star's smallest angle before). False (nothing changed) when v
  //! is an input vertex or no collapse is valid. Marks v, the faces
  //! beside edge (v, u) and the edges merged away deleted; call compact() afterwards.
  //! \p min_angle_deg >= 0 replaces the quality bar (0: any valid collapse, for a caller that
  //! repairs angles afterwards, e.g. with improve()).
  bool remove_vertex(int v, double min_angle_deg = -1);

  //! Maps from old to new indices (-1 for removed elements): vertex (size #V before), edge
  //! (size #E before), face (size #F before).
  struct Compaction {
    std::vector<int> vertex, edge, face;
  };
  //! Removes the deleted elements. Input vertices keep their indices; others may be reordered.
  Compaction compact();

  //! Lawson flips (Delaunay criterion: the two angles opposite an edge sum to more than π)
  //! inside hosts, starting from the edges of \p faces (all faces when empty) and continuing
  //! from the edges of every flipped quad, so as to raise small angles. Never flips an edge for
  //! which protect(edge) is true, a boundary edge or an edge between two hosts. Returns the
  //! number of flips. Face indices do not change.
  int improve(const std::vector<int>& faces = {}, const std::function<bool(int)>& protect = {});

  // ---- measures ----

  //! Number of live faces of W.
  int live_faces() const { return live_faces_; }
  //! |F(W)| / |F(input)| (live faces).
  double growth() const;
  //! Max over live W vertices of |W position − position(origin)| / input bounding-box diagonal.
  double max_origin_error() const;
  //! Smallest corner angle of W's live faces (degrees).
  double min_angle_deg() const;
  //! Smallest corner angle of W face f (degrees).
  double face_min_angle_deg(int f) const;
  //! Bounding-box diagonal of the input (length unit of the mesh).
  double bbox_diagonal() const { return bbox_diagonal_; }

 private:
  using Bary = std::array<double, 3>;

  // Validation of arguments (throw InvalidInputError).
  void check_vertex(int v, const char* what) const;
  void check_face(int f, const char* what) const;
  void check_edge(int e, const char* what) const;
  SurfacePoint checked_point(const SurfacePoint& p, const char* what) const;

  // Orientation threshold: a triangle is valid when det3 of its corners' barycentrics in its
  // host (twice its area as a fraction of the host's area) exceeds this.
  static constexpr double kMinDet = 1e-14;
  // a · (b × c): exactly 0 when the three share a zero component (points of one input edge).
  static double det3(const Bary& a, const Bary& b, const Bary& c);
  static double triangle_min_angle_deg(const Vec3& a, const Vec3& b, const Vec3& c);
  static int zero_count(const Bary& b);

  std::array<int, 3> corners(int f) const;
  Bary host_bary(int v, int host) const;            // bary_in_input_face that must succeed
  Location locate_in(const SurfacePoint& p) const;  // p already checked

  // A hypothetical split: the new vertex's origin, the triangles it would create (W vertex
  // indices, -1 for the new vertex) with their hosts, and the faces it replaces; evaluated
  // without changing W.
  struct Candidate;
  bool evaluate(Candidate& c) const;
  Candidate edge_split_candidate(int edge, const SurfacePoint& o) const;
  Candidate face_split_candidate(int face, const SurfacePoint& o) const;
  SurfacePoint edge_point(int edge, double t) const;
  SurfacePoint face_point(int face, const Bary& bary) const;

  // Committed edits from a known origin.
  int split_edge_at(int edge, const SurfacePoint& o);
  int split_face_at(int face, const SurfacePoint& o);
  int add_vertex(const SurfacePoint& o);
  void adopt_new_faces(int first_new_face, int v);  // hosts of faces split off around v
  void add_hosted(int f, int host);
  void remove_hosted(int f);

  std::shared_ptr<const TriMesh> input_;
  WorkingMeshOptions options_;
  TriMesh mesh_;
  int n_input_ = 0;
  int live_faces_ = 0;
  double bbox_diagonal_ = 0;
  std::vector<std::array<int, 3>> input_corners_;  // per input face, face-vertex order
  std::vector<SurfacePoint> origin_;               // per W vertex
  std::vector<int> host_;                          // per W face
  std::vector<int> slot_;                          // per W face: its index in hosted_[host]
  std::vector<std::vector<int>> hosted_;           // per input face
};

}  // namespace qs
