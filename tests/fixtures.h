// Synthetic meshes and layouts for tests (docs/design.md, "Test inputs"), plus paths to test data.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "core/extract/tracing.h"
#include "core/import/cage.h"
#include "core/layout/layout.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh.h"
#include "core/pipeline/pipeline.h"
#include "tests/jitter.h"

namespace qs::test {

//! Folder with the shared real meshes (../shared/data/meshes), or "" when it is absent.
std::string shared_meshes_dir();

//! The cage options that give fertility.obj (genus 4, 27954 faces) its layout: cells of 1/30
//! of the longest axis (6.6 units; the thinnest parts are 7 units thick, the narrowest gaps 3.4
//! units wide, the mean edge 2.2), classified by their inside fraction, grid shifted by half a
//! cell, chords up to 10 cells collapsed, the fitted cage split twice before the transfer.
CageOptions fertility_cage_options();
//! The same with CageOptions::simplify at resolution 34, unshifted (the coarsened cage's nearby
//! irregular vertices cancelled; without simplify no grid at 34 transfers).
CageOptions fertility_simplified_cage_options();
//! The repository's assets/ folder.
std::string assets_dir();
//! Path of the quadsketch-cli executable.
std::string cli_path();
//! A fresh empty temporary folder for one test (under the system temp dir, unique per process).
std::string temp_dir(const std::string& name);

//! Runs a shell command, returns its exit code and captures stdout+stderr into \p output.
int run_command(const std::string& command, std::string* output = nullptr);

struct MeshAndLayout {
  TriMesh mesh;
  Layout layout;
};

//! A layout node with user id \p id on mesh vertex \p vertex (unpinned).
LayoutNode make_node(int id, int vertex);
//! A layout arc with user id \p id between node ids \p from and \p to (-1: dangling) along
//! the vertex path \p path.
LayoutArc make_arc(int id, int from, int to, std::vector<int> path);

//! Cube split k×k per face (alternating diagonals), projected onto an ellipsoid with the given
//! radii (radii {1,1,1}: unit sphere; project=false keeps the cube [-1,1]^3). Layout: the 8
//! cube corners (valence 3) and the 12 cube edges (each a path of k mesh edges): 6 patches.
MeshAndLayout cube_sphere(int k, Vec3 radii = Vec3(1, 1, 1), bool project = true);
//! cube_sphere(24) rounded halfway to the sphere (0.3 cube + 0.7 sphere) with a bumpy surface
//! (radial sin·sin·sin bumps of 1.5 %): its natural cross field has dozens of close
//! singularity pairs besides the corners.
MeshAndLayout bumpy_rounded_cube();

//! Icosahedron subdivided \p subdivisions times (each triangle into 4), projected onto the
//! ellipsoid with the given radii: 20·4^subdivisions faces, vertices of valence 5 and 6 that
//! follow no cube or layout structure.
TriMesh icosphere(int subdivisions, Vec3 radii = Vec3(1, 1, 1));

//! The layout of \p source moved onto \p target, a different mesh of the same surface: each node
//! goes to the target vertex nearest to its source vertex (3D distance), each arc is routed
//! (route_layout) through the target vertices nearest to every second interior vertex of its
//! source path. \throw InvalidInputError if an arc cannot be routed or the result is invalid.
Layout transfer_layout(const MeshAndLayout& source, const TriMesh& target);

//! Torus (radii R, r) with an nu×nv quad grid (split into triangles). Layout: a pu×pv grid of
//! valence-4 nodes with arcs along grid lines (nu % pu == 0, nv % pv == 0). Genus 1, no
//! singularities.
MeshAndLayout torus_grid(int nu, int nv, int pu, int pv, double R = 2.0, double r = 0.7);

//! Flat rectangle [0,nx]×[0,ny] (unit grid, triangulated) with a boundary-aligned px×py patch
//! layout: nodes at grid points (i % (nx/px) == 0 and j % (ny/py) == 0), including boundary
//! corners, arcs along grid lines including the boundary.
MeshAndLayout disk_grid(int nx, int ny, int px, int py);

//! Flat square [0,12]² (unit grid, triangulated) with a 3 × 3 hole at [6,9]×[5,8], and a star of
//! four dangling arcs along grid lines from the node at (3, 6): into the hole, up, left and down
//! to the outer boundary. The hole is a free boundary loop; the layout's exact
//! parameterization is the identity (E = 0) when the field turns around the hole as around a
//! regular point (FreeLoopTurning::kCap).
MeshAndLayout flat_square_with_free_hole();

//! Boundary surface of a union of unit voxels (x, y, z integer cells), each voxel face split
//! k×k and triangulated. Layout: nodes at every lattice point of the voxel grid on the
//! surface, arcs along every voxel edge on the surface (one patch per voxel face). Sharp 90°
//! edges everywhere along the arcs; flat patches. The voxel set must give a manifold surface.
MeshAndLayout voxel_surface(const std::vector<std::array<int, 3>>& voxels, int k);

//! The genus-2 polycube of docs/design.md, "Test inputs": a 5×3×1 voxel block minus two separated
//! columns (nodes of valence 3, 4 and 5).
MeshAndLayout genus2_polycube(int k);

//! The quad cube k = 2 imported with refine 2 (arcs of 4 edges), its layout displaced two rings
//! (perturb_layout) by the first seed from 1 that puts nodes on each other's 1-ring so that
//! separate_nodes moves at least two of them: `layout` is that crowded layout.
MeshAndLayout crowded_refined_cube();

//! Surface of the box [0,sx]×[0,sy]×[0,sz] (size {sx, sy, sz}) as a unit quad grid per side,
//! outward oriented, shifted by \p offset.
PolyMesh quad_box(std::array<int, 3> size, Vec3 offset = Vec3(0, 0, 0));

//! Surface of the cube [0,k]^3 as a k×k quad grid per side, outward oriented, shifted by
//! \p offset (quad_box with size {k, k, k}).
PolyMesh quad_cube(int k, Vec3 offset = Vec3(0, 0, 0));

//! nu × nv quad grid on a torus (radii 2 and 0.7; no irregular vertex).
PolyMesh quad_torus(int nu, int nv);

//! Flat nx × ny quad grid [0,nx]×[0,ny] (a disk); its 4 corners have valence 2.
PolyMesh quad_disk(int nx, int ny);

//! Flat n × n quad grid without its top-right cell: a disk with one concave corner whose two
//! separatrices cut thin strips (one cell wide) off the top and right sides.
PolyMesh notched_disk(int n);

//! A layout of one node at \p center with one dangling arc (to = -1) per target boundary vertex,
//! routed in order as shortest paths that avoid the arcs before them and touch the boundary
//! only at their end. An arc that cannot be routed is kept with its (short) path: callers check
//! that every path has at least 2 vertices (this file is also linked into the benchmarks, so it
//! does not use GoogleTest).
Layout dangling_star_layout(const TriMesh& mesh, int center, const std::vector<int>& targets);

//! Node and dangling-arc targets of a star on a mesh with three boundary loops, like
//! mask_confmap.obj (a face with two eye holes), for dangling_star_layout.
struct MaskStar {
  size_t boundary_loops = 0;  //!< number of boundary loops of the mesh (the star needs 3)
  int center = -1;            //!< interior vertex nearest to the midpoint of the eye centroids
  std::vector<int> targets;   //!< eye 1 (nearest to center), up, eye 2 (nearest), down
};

//! The star of MaskStar on \p mesh (center and targets left unset unless it has three boundary
//! loops). Loops sorted largest first: the outer boundary, then the eyes. Up and down are the
//! outer-boundary vertices farthest from the center on either side of the eye axis (with the
//! area-weighted mesh normal).
MaskStar mask_star(const TriMesh& mesh);

//! Writes a mesh as OBJ text (full precision) — for fixtures only.
void write_obj(const TriMesh& mesh, const std::string& path);
//! The same for a polygon mesh (one `f` line per face, any number of corners).
void write_obj(const PolyMesh& mesh, const std::string& path);

//! Singularities of a cross field measured on the field alone (field_quarter_indices:
//! principal matching + angle defect, independent of the layout's period jumps), compared with
//! the layout: index (4 − valence)/4 at every interior node vertex, 0 at every other interior
//! vertex.
struct FieldIndexCheck {
  int wrong = 0;      //!< interior vertices whose measured index differs from the expected one
  int spurious = 0;   //!< of them, vertices that are not node vertices
  int sum = 0;        //!< sum of the measured indices over all vertices (quarter turns)
  int irregular = 0;  //!< nodes of valence != 4
  std::vector<std::string> examples;  //!< the first 5 wrong vertices, described
};

//! \p theta: the field per face (CrossField::theta), size #F.
FieldIndexCheck check_field_indices(const TriMesh& mesh, const GeometryCache& geometry,
                                    const Layout& layout, const LayoutTopology& topology,
                                    const std::vector<double>& theta);

//! Embedding checks of issue #4 on traced arcs (no GoogleTest: callers assert).
struct EmbeddingCheck {
  //! Worst ratio (smaller / larger parameter change) between consecutive samples of a traced
  //! arc inside one face, in that face's chart: 0 for exact iso-lines.
  double iso_violation = 0;
  //! Worst |l0 − l2| / max(l0, l2) over the opposite sides of every 4-sided patch (parametric
  //! arc lengths).
  double side_mismatch = 0;
  int sides_checked = 0;  //!< pairs of opposite sides compared
};

//! \p corner_uv: Parameterization::corner_uv (size 3·#F).
EmbeddingCheck check_embedding(const TriMesh& mesh, const GeometryCache& geometry,
                               const LayoutTopology& topology, const Extraction& extraction,
                               const std::vector<std::array<double, 2>>& corner_uv);
//! The same for a solved Pipeline: its extraction (extract(), run if needed) and its
//! parameterization's corner_uv. \pre compute_parameterization() has run.
EmbeddingCheck check_embedding(Pipeline& pipeline);

//! The vertices at exactly \p rings edge hops from vertex \p v (breadth-first search).
std::vector<int> ring_vertices(const TriMesh& mesh, int v, int rings);

//! Per vertex (size #V): edge hops to the nearest vertex of \p sources; -1 when unreachable.
std::vector<int> ring_distances(const TriMesh& mesh, const std::vector<int>& sources);

//! The least of \p dist (per vertex, as ring_distances gives) over the vertices of face \p f.
int face_ring_distance(const TriMesh& mesh, const std::vector<int>& dist, int f);

//! \p layout with every unpinned node moved to a vertex \p rings edge rings away (the choice
//! rotates with \p seed; vertices other nodes or arcs forbid are skipped), its arcs re-routed:
//! a valid layout with the same structure.
Layout displace_nodes(const TriMesh& mesh, Layout layout, int rings, int seed);

//! Energy of a moved mesh: (mesh, its geometry, the frozen field θ per face).
using MovedEnergy =
    std::function<double(const TriMesh&, const GeometryCache&, const std::vector<double>&)>;
//! Central finite-difference gradient (tangent plane of vertex \p v, two directions) of
//! \p energy when v moves by ±\p eps (length units), with the field frozen across the move
//! (freeze_field_after_move). Units: energy per length.
Vec3 frozen_field_difference(const TriMesh& mesh, const GeometryCache& geometry,
                             const std::vector<double>& theta, int v, double eps,
                             const MovedEnergy& energy);

//! The bundled example (assets/example/ellipsoid.obj with the displaced sketch layout), its
//! mesh jittered under QS_TEST_JITTER (jitter.h).
MeshAndLayout ellipsoid_example();

//! How far the fields of two Pipelines on the same mesh are apart (both computed).
struct FieldGap {
  bool same_singularities = false;  //!< same vertices and quarter indices, same order
  double max_theta = 0;  //!< max over faces of |θ_a − θ_b| modulo quarter turns (rad)
};
FieldGap field_gap(const Pipeline& a, const Pipeline& b);

}  // namespace qs::test
