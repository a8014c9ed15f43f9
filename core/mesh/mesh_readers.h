// The per-format readers behind read_polygon_soup (obj_reader.cpp, off_reader.cpp,
// ply_reader.cpp, stl_reader.cpp, openmesh_reader.cpp). Internal to core/mesh; the public API
// is mesh_io.h. \p path only names the file in messages; \p bytes is its whole content and
// \p text the same without a leading UTF-8 byte-order mark (skip_utf8_bom).
// Every function throws InvalidInputError naming the file (and line where known).
#pragma once

#include <string>
#include <string_view>

#include "core/mesh/mesh_io.h"

namespace qs::mesh_detail {

//! OBJ: v and f statements (see read_polygon_soup); other statements are ignored, unknown
//! ones with a warning. Every parse error is listed with its line.
PolygonSoup parse_obj(const std::string& path, std::string_view text);

//! OFF: ASCII [ST][C][N]OFF is parsed here; "OFF BINARY" goes to read_with_openmesh.
PolygonSoup parse_off(const std::string& path, std::string_view text);

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
PlyInfo check_ply(const std::string& path, std::string_view text);

//! True when \p bytes is a binary STL: 80-byte header, uint32 triangle count n, and a size of
//! exactly 84 + 50 * n bytes (OpenMesh's rule). \p triangles, when given, receives n.
bool is_binary_stl(std::string_view bytes, long long* triangles = nullptr);

//! ASCII STL: one or more "solid [name]" ... "endsolid [name]" blocks of facets
//! ("facet normal nx ny nz", "outer loop", three "vertex x y z", "endloop", "endfacet");
//! keywords are case-insensitive, normals are ignored. Corners with equal coordinates become
//! one vertex (in order of first use); face_lines are the "facet" lines, point_lines the
//! first "vertex" line of each vertex. A file cut anywhere (no final "endsolid") is an error.
PolygonSoup parse_ascii_stl(const std::string& path, std::string_view text);

//! Reads PLY, binary STL or binary OFF (\p format "ply", "stl", "off") with OpenMesh's readers
//! after the checks above, recording the raw vertices and faces. PLY and STL are handed over
//! from \p text (for PLY without its byte-order mark, for STL all bytes); binary OFF is read
//! from \p path, since OpenMesh tells the OFF variant only from a file.
PolygonSoup read_with_openmesh(const std::string& path, const std::string& format,
                               std::string_view text);

}  // namespace qs::mesh_detail
