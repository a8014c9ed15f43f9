// Welding coincident vertices of a polygon soup, for quad meshes exported per patch (each
// patch's border vertices duplicated, e.g. Blender's split by face groups).
#pragma once

#include <string>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"

namespace qs {

//! Merges the soup's vertices that lie within \p relative_tolerance × (bounding-box diagonal
//! of its finite points) of each other (Euclidean distance; chains of such pairs merge
//! transitively). Each group keeps its smallest index's position; faces are renumbered and the
//! merged duplicates removed from \p soup.points (the other vertices keep their order; vertices
//! with non-finite coordinates are never merged). A face whose corners merge keeps its
//! repeated index (the mesh checks report it as degenerate).
//! \return the number of vertices removed (0: \p soup unchanged).
int weld_coincident_vertices(PolygonSoup& soup, double relative_tolerance = 1e-9);

//! The result of load_poly_mesh_welded.
struct WeldedPolyMesh {
  PolyMesh mesh;
  MeshReport report;     //!< the checks of the welded mesh (ids: vertices after welding)
  int welded = 0;        //!< vertices removed by welding
  int parts_before = 0;  //!< connected components of the file before welding
};

//! Reads a polygon mesh (read_polygon_soup), welds coincident vertices
//! (weld_coincident_vertices) and checks the welded mesh like load_poly_mesh (one connected
//! component required).
//! \throw InvalidInputError "<path>: invalid mesh" with one line per problem of the welded
//!        mesh (MeshReport::problems); when vertices were welded, the first line also says how
//!        many and how many parts of the file touch at them.
WeldedPolyMesh load_poly_mesh_welded(const std::string& path, double relative_tolerance = 1e-9);

}  // namespace qs
