// GeometryCache: per-face frames, normals, areas, corner angles, angle defects, and the
// discrete connection κ on dual edges (docs/design.md, "Field topology"). Built once per mesh
// state and passed down; never rebuilt inside loops.
#pragma once

#include <array>
#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

struct GeometryCache {
  int n_vertices = 0, n_faces = 0, n_edges = 0;

  // ---- connectivity (does not change when vertices move) ----
  //! Face corners in OpenMesh face-vertex order (size #F).
  std::vector<std::array<int, 3>> face_vertices;
  //! Per edge: the dual edge runs from face_i (holding halfedge a→b, a < b) to face_j (holding
  //! b→a); -1 on the missing side of a boundary edge. Size #E.
  std::vector<int> edge_face_i, edge_face_j;
  //! Per edge: its two vertices (a < b). Size #E.
  std::vector<std::array<int, 2>> edge_vertices;
  std::vector<char> vertex_on_boundary;  //!< size #V
  //! Per face: its three edges (size #F; update_geometry's incremental path).
  std::vector<std::array<int, 3>> face_edges;
  //! Faces around each vertex in increasing index order: vertex_faces[vertex_face_offset[v] ..
  //! vertex_face_offset[v + 1]) (CSR; offsets size #V + 1).
  std::vector<int> vertex_face_offset, vertex_faces;

  // ---- geometry ----
  std::vector<Vec3> face_normal;  //!< unit normals, size #F
  std::vector<Vec3> face_frame;   //!< reference direction r_t (unit, in the face plane), size #F
  //! r_t is the face's first edge direction rotated by this angle (radians) about the normal;
  //! 0 by default (tests use random offsets: nothing may depend on the frame choice). Size #F.
  std::vector<double> frame_offset;
  std::vector<double> face_area;  //!< size #F
  //! Per face f: the gradients of the linear hat functions of its three corners in the frame
  //! (r_f, n_f × r_f), from face_corners_2d: ∇φ_k = (face_gradient[f][2k],
  //! face_gradient[f][2k + 1]) (1/length), and [6] the area of those 2D corners (length²; equal
  //! to face_area up to rounding). Kept with the frames, so the energy assembly and its
  //! measurements do not recompute them for every solve. Size #F.
  std::vector<std::array<double, 7>> face_gradient;
  //! Corner angle (radians) at the k-th corner of face f: corner_angle[3f + k].
  std::vector<double> corner_angle;
  //! Angle defect Ω(v): 2π − Σ angles (interior), π − Σ angles (boundary). Size #V.
  std::vector<double> angle_defect;
  //! κ_ij on each interior edge (radians): a direction at angle φ from r_i becomes φ + κ_ij
  //! in face j. 0 on boundary edges. Size #E.
  std::vector<double> kappa;
  double mean_edge_length = 0;
  double bbox_diagonal = 0;
  //! The vertex positions this geometry was computed for (size #V) and each edge's length
  //! (size #E): update_geometry recomputes only around vertices that moved since.
  std::vector<Vec3> positions;
  std::vector<double> edge_length;

  //! Angle (radians, ccw about the face normal) of a 3D vector in face f, measured from r_f.
  double angle_in_face(int f, const Vec3& v) const;
  //! Unit vector of the direction at angle φ in face f.
  Vec3 direction_in_face(int f, double phi) const;
};

//! Builds the cache. Frames r_t are the unit direction of the face's first edge.
GeometryCache build_geometry(const TriMesh& mesh);

//! Recomputes the geometric part after vertices moved, keeping the frames' choice of edge and
//! continuing κ (κ_new = κ_old + wrap(κ_new − κ_old), never re-wrapped; docs/design.md,
//! "Continuing κ").
//! When few vertices moved since the last computation, only their faces, the vertices and
//! edges of those faces are recomputed; the result is bit-identical to the full computation,
//! except that κ of the other edges keeps its value (the full pass re-continues it, which can
//! change its last bits).
void update_geometry(const TriMesh& mesh, GeometryCache& geometry);

//! Corner positions of face f in its local 2D frame (r_f, n_f × r_f), corner 0 at the origin;
//! the frame every per-face gradient (energy, metrics, node gradient) is expressed in.
std::array<std::array<double, 2>, 3> face_corners_2d(const TriMesh& mesh,
                                                     const GeometryCache& geometry, int f);

//! Sets the frame offsets and recomputes frames and κ from scratch (not continued).
void set_frame_offsets(const TriMesh& mesh, GeometryCache& geometry, std::vector<double> offsets);

//! Wraps an angle into (−π, π].
double wrap_angle(double a);

}  // namespace qs
