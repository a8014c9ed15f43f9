// The per-format readers behind read_polygon_soup (obj_reader.cpp, off_reader.cpp,
// ply_reader.cpp, stl_reader.cpp, openmesh_reader.cpp). Internal to core/mesh; the public API
// is mesh_io.h. \p path only names the file in messages; \p bytes is its whole content.
// Every function throws InvalidInputError naming the file (and line where known).
#pragma once

#include <string>
#include <string_view>

#include "core/mesh/mesh_io.h"

namespace qs::mesh_detail {

//! OBJ: v and f statements (see read_polygon_soup); other statements are ignored, unknown
//! ones with a warning. Every parse error is listed with its line.
PolygonSoup parse_obj(const std::string& path, std::string_view bytes);

//! OFF: ASCII [ST][C][N]OFF is parsed here; "OFF BINARY" goes to read_with_openmesh.
PolygonSoup parse_off(const std::string& path, std::string_view bytes);

//! Checks "OFF BINARY" record by record (little-endian int32 counts, float32 coordinates,
//! int32 face sizes and indices), so that OpenMesh's reader never sees absurd counts.
void check_binary_off(const std::string& path, std::string_view bytes);

//! What the PLY header declares (counts are -1 when the element is missing).
struct PlyInfo {
  long long vertices = -1;
  long long faces = -1;
  bool double_coordinates = false;  //!< x, y or z is declared double
};

//! Checks a PLY header line by line and walks every record (ASCII or binary), so that
//! OpenMesh's reader (which loops forever on a cut header and trusts every count) only sees
//! well-formed files.
PlyInfo check_ply(const std::string& path, std::string_view bytes);

//! Checks an STL file (binary: the size matches 84 + 50 * #triangles; ASCII: line by line)
//! and returns the number of triangles it holds, so that the ones OpenMesh's reader skips can
//! be counted.
long long check_stl(const std::string& path, std::string_view bytes);

//! Reads PLY, STL or binary OFF (\p format "ply", "stl", "off") with OpenMesh's readers after
//! the checks above, recording the raw vertices and faces.
PolygonSoup read_with_openmesh(const std::string& path, const std::string& format,
                               std::string_view bytes);

}  // namespace qs::mesh_detail
