// Reading and writing meshes (OBJ, OFF, PLY, STL), in double precision, with full checking.
#pragma once

#include <string>
#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

//! Largest accepted coordinate magnitude. Beyond it, squared lengths and areas of the mesh's
//! own extent overflow a double (e.g. (2 * 1e155)^2 = 4e310), so no geometry can be trusted.
constexpr double kMaxCoordinateMagnitude = 1e150;

//! Raw content of a mesh file before any connectivity is built.
struct PolygonSoup {
  std::vector<Vec3> points;             //!< one per file vertex, in file order
  std::vector<std::vector<int>> faces;  //!< 0-based vertex indices, one entry per file face
  std::vector<int> face_lines;          //!< 1-based source line of each face (0 if unknown)
  std::vector<int> point_lines;         //!< 1-based source line of each vertex (0 if unknown)
  std::vector<std::string> warnings;    //!< non-fatal remarks of the reader (ignored statements)
  //! Faces the format's reader skipped without telling which (OpenMesh's binary STL reader
  //! drops triangles with coinciding corners); each one is a degenerate face.
  int skipped_degenerate_faces = 0;
};

//! Why a face could not be added to the halfedge mesh (see MeshReport::dropped_faces).
enum class DropReason {
  kNonManifoldEdge,          //!< one of its edges already has two faces
  kInconsistentOrientation,  //!< an edge is already used in the same direction by a neighbour
  kNonManifoldVertex,        //!< OpenMesh refused it at a vertex ("complex vertex")
  kDuplicate,                //!< same vertex cycle as an earlier face (either direction)
};

//! Everything found while loading and checking a mesh. Counts refer to the loaded mesh.
struct MeshReport {
  std::string path;
  int vertices = 0;
  int faces = 0;  //!< triangles after triangulation (polygons for load_poly_mesh)
  int edges = 0;
  int input_faces = 0;         //!< faces in the file
  int triangulated_faces = 0;  //!< input faces with more than 3 vertices that were split
  int components = 0;
  int boundary_loops = 0;
  int euler_characteristic = 0;  //!< V - E + F
  int genus = 0;  //!< from V - E + F = 2 - 2g - b (single component; summed over components)
  // Problems (each is fatal for load_mesh).
  // All ids are 0-based: vertex ids are file vertex indices, face ids are file face indices.
  std::vector<int> dropped_faces;         //!< file face indices that could not be added
  std::vector<DropReason> drop_reasons;   //!< parallel to dropped_faces
  std::vector<int> nonmanifold_vertices;  //!< vertex indices whose faces do not form one fan
  std::vector<int> degenerate_faces;      //!< file face indices with zero area or repeated vertices
  std::vector<int> nonfinite_vertices;    //!< vertex indices with NaN or infinite coordinates
  //! Vertex indices with a finite coordinate of magnitude above kMaxCoordinateMagnitude.
  std::vector<int> out_of_range_vertices;
  std::vector<int> unreferenced_vertices;  //!< vertex indices used by no face
  std::vector<int> bad_index_faces;        //!< file face indices referring to missing vertices
  std::vector<int> non_triangle_faces;     //!< file faces with > 3 vertices (triangulate off)
  //! File faces with > 3 vertices that have no triangulation keeping their orientation (their
  //! outline crosses or touches itself in their plane; see triangulate_polygon).
  std::vector<int> untriangulable_faces;
  int skipped_degenerate_faces = 0;          //!< see PolygonSoup::skipped_degenerate_faces
  bool multiple_components_allowed = false;  //!< copied from LoadMeshOptions
  std::vector<int> face_lines;               //!< source line per file face (0 if unknown)
  std::vector<int> vertex_lines;             //!< source line per file vertex (0 if unknown)
  std::vector<std::string> warnings;         //!< non-fatal remarks (e.g. triangulated faces)

  //! True when there is no fatal problem (one component is also required unless
  //! multiple_components_allowed; a mesh without faces is never ok).
  bool ok() const;
  //! One human-readable line per problem, each naming counts and the first ids.
  std::vector<std::string> problems() const;
};

struct LoadMeshOptions {
  //! Split faces with more than 3 vertices (triangulate_polygon) with a warning. When false
  //! such faces are an error.
  bool triangulate = true;
  //! Accept several connected components (the pipeline needs exactly one).
  bool allow_multiple_components = false;
};

//! Reads the raw vertices and faces of a mesh file (format from the extension: .obj, .off,
//! .ply, .stl; case-insensitive). Only a regular file is read (read_input_file). OBJ, ASCII
//! OFF and ASCII STL are parsed here with line-precise errors ("file.obj:12: vertex has 2
//! coordinates, expected 3") and exact double coordinates. A leading UTF-8 byte-order mark
//! is skipped in every text format (OBJ, OFF, ASCII STL, the PLY header).
//! OBJ: v (x y z, optional w or RGB) and f (v, v/vt, v/vt/vn, v//vn, negative = relative);
//! vt/vn/vp/o/g/s/usemtl/mtllib/l are ignored, other statements too, with a warning.
//! OFF: [ST][C][N]OFF header, counts on the header line or the next; a face may continue on
//! the next lines when they hold only its missing indices; an optional colour may follow.
//! ASCII STL: "solid" ... "endsolid" blocks of facets (three "vertex x y z" each); corners
//! with equal coordinates are one vertex; a file without its final "endsolid" is refused.
//! PLY, binary STL and binary OFF go through OpenMesh's readers with an importer that records
//! the raw indices. Precision: binary STL and binary OFF are float formats; OpenMesh 9 reads
//! PLY coordinates as float too (a warning is added when the file declares double x/y/z).
//! Out-of-range face indices are kept (build_*_mesh reports them).
//! \throw InvalidInputError naming the file (and line) if the file is missing ("<path>:
//!        cannot open file"), empty ("<path>: empty file"), has an unsupported extension,
//!        is truncated or malformed, or has no faces.
PolygonSoup read_polygon_soup(const std::string& path);

//! Loads a triangle mesh and checks it (check_mesh). Vertex order is the file's order; face
//! order is the file's order (triangulated faces expand in place).
//! \throw InvalidInputError listing every problem found: first line "<path>: invalid mesh",
//!        then one line per problem (MeshReport::problems(), e.g. "3 non-manifold vertices
//!        (ids 4, 9, 17): ..."). \p report, when given, is filled before throwing.
TriMesh load_mesh(const std::string& path, MeshReport* report = nullptr,
                  const LoadMeshOptions& options = {});

//! Loads a polygon mesh (quad meshes for import) without triangulating; same checks otherwise.
PolyMesh load_poly_mesh(const std::string& path, MeshReport* report = nullptr,
                        const LoadMeshOptions& options = {});

//! Writes a mesh as OBJ (full double precision), atomically. \throw QsError on I/O failure.
void save_mesh_obj(const TriMesh& mesh, const std::string& path);

}  // namespace qs
