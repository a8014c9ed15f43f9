// Principal curvature directions per face (normal-cycle tensor) and the direction constraints
// that guide the cross field: reliable curvature regions, sharp features and boundaries
// (paper §4.2; docs/design.md, "Curvature constraints").
#pragma once

#include <Eigen/Core>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"

namespace qs {

struct CurvatureOptions {
  //! Neighbourhood of the per-face tensor: vertices within this many edge rings of the face.
  int rings = 2;
  //! A face is reliable when |κ1 − κ2| ≥ min_anisotropy · s95, where s95 is the 95th
  //! percentile of max(|κ1|, |κ2|) over all faces (normalised anisotropy, as QuadWild's 0.4)…
  double min_anisotropy = 0.4;
  //! …and |κ1 − κ2| ≥ min_ratio · (|κ1| + |κ2|) (clearly anisotropic, not umbilic).
  double min_ratio = 0.5;
  //! Reliable regions with fewer faces than this are dropped as noise.
  int min_region_faces = 8;
  bool operator==(const CurvatureOptions&) const = default;
};

//! Per-face principal curvatures (1/length units) and directions (unit, in the face plane).
struct Curvature {
  std::vector<double> k_max, k_min;  //!< signed, k_max ≥ k_min; size #F
  std::vector<Vec3> dir_max;         //!< direction of k_max; dir_min = n × dir_max; size #F
  std::vector<char> reliable;        //!< size #F
  int reliable_faces = 0;
};

//! What compute_curvature keeps for update_curvature: the positions it was computed at and
//! its per-vertex tensors and areas at every smoothing level (level 0 raw, size `rings`).
struct CurvatureCache {
  std::vector<Vec3> points;                          //!< size #V
  std::vector<std::vector<Eigen::Matrix3d>> tensor;  //!< per level, size #V each
  std::vector<std::vector<double>> area;             //!< per level, size #V each
  std::vector<double> magnitude;                     //!< per face: max(|κ1|, |κ2|)
  Curvature curvature;                               //!< the result
  CurvatureOptions options;
};

//! Normal-cycle curvature tensor (Cohen-Steiner & Morvan) per face over a ring neighbourhood.
//! With \p cache, also fills it for update_curvature.
Curvature compute_curvature(const TriMesh& mesh, const GeometryCache& geometry,
                            const CurvatureOptions& options = {}, CurvatureCache* cache = nullptr);

//! compute_curvature after vertices moved (same connectivity, \p geometry updated): only the
//! tensors and faces within reach of moved vertices are recomputed (the reliable set, which
//! depends on a global percentile, is redone); bit-identical to compute_curvature. Falls back to
//! a full computation when \p cache does not match the mesh or the options. Updates \p cache.
Curvature update_curvature(const TriMesh& mesh, const GeometryCache& geometry,
                           const CurvatureOptions& options, CurvatureCache& cache);

//! Edges whose dihedral angle (between face normals) exceeds \p sharp_angle_deg, plus the
//! layout's feature edges. Boundary edges are not included. Size #E flags.
std::vector<char> sharp_edges(const TriMesh& mesh, const GeometryCache& geometry,
                              double sharp_angle_deg, const Layout* layout = nullptr);

enum class ConstraintKind : char { Curvature = 0, Feature = 1, Boundary = 2 };

//! Direction constraints on faces: the field's first direction should be (mod 90°) `direction`.
struct FieldConstraints {
  std::vector<int> face;
  std::vector<Vec3> direction;  //!< unit, in the face plane (original geometry)
  std::vector<ConstraintKind> kind;
  int count(ConstraintKind k) const;
};

struct ConstraintOptions {
  bool curvature = true;  //!< false for the alignment-oblivious baseline (--no-align)
  bool features = true;
  bool boundary = true;
  double sharp_angle_deg = 35.0;
  CurvatureOptions curvature_options;
};

//! Collects constraints: faces with a boundary edge that an arc runs along follow it (other
//! boundary edges are left free: trimmed patches), faces with a sharp/feature edge
//! follow that edge (boundary and feature constraints override curvature), reliable faces follow
//! their principal directions.
FieldConstraints collect_constraints(const TriMesh& mesh, const GeometryCache& geometry,
                                     const Layout* layout, const ConstraintOptions& options,
                                     const Curvature* curvature = nullptr);

}  // namespace qs
