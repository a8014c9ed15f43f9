// The checks of the mesh readers, applied to a mesh before it is written, so that a command
// never writes a mesh that reading it back would reject.
#pragma once

#include <string>

#include "core/mesh/mesh.h"
#include "core/mesh/mesh_io.h"

namespace qs {

//! The report load_mesh would give for \p mesh written as OBJ and read back (build_tri_mesh on
//! its vertices and faces, same order and indices; one connected component required):
//! MeshReport::ok() says whether it would be accepted, problems() why not (face ids are
//! \p mesh's face indices).
MeshReport check_as_read(const TriMesh& mesh);

//! The same for a polygon mesh and load_poly_mesh.
MeshReport check_as_read(const PolyMesh& mesh);

//! "<what> would be rejected when read back:" and one indented line per problem of \p report
//! (MeshReport::problems), for an error.
std::string rejection_message(const MeshReport& report, const std::string& what);

}  // namespace qs
