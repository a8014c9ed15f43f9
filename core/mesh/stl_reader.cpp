// STL: ASCII STL is parsed here (a strict grammar, exact double coordinates); binary STL is
// recognized here and read by OpenMesh (openmesh_reader.cpp).
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs::mesh_detail {
namespace {

// What the next non-blank line of an ASCII STL must be.
enum class Expect {
  kSolid,
  kFacetOrEndSolid,
  kOuterLoop,
  kVertex,
  kEndLoop,
  kEndFacet,
  kNextSolid
};

}  // namespace

bool is_binary_stl(std::string_view bytes, long long* triangles) {
  // 80-byte header, little-endian uint32 triangle count, 50 bytes per triangle. Like OpenMesh,
  // the size decides (a binary header may well start with "solid").
  if (bytes.size() < 84) return false;
  std::uint32_t n = 0;
  for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(bytes[80 + k]);
  if (84 + 50 * static_cast<std::uint64_t>(n) != bytes.size()) return false;
  if (triangles) *triangles = n;
  return true;
}

PolygonSoup parse_ascii_stl(const std::string& path, std::string_view text) {
  PolygonSoup soup;
  ParseErrors errors(path);
  // Structural errors end the parse: after a missing keyword nothing can be trusted.
  const auto fail = [&](const LineReader& lines, const std::string& what) {
    errors.add(lines, what);
    errors.throw_if_any();
  };
  // Corners with equal coordinates are one vertex (STL stores every triangle on its own).
  std::map<std::array<double, 3>, int> vertex_of;
  std::vector<std::string_view> tokens;
  std::vector<int> face;
  Expect expect = Expect::kSolid;
  long long facets = 0;
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    tokenize(line, tokens);
    if (tokens.empty()) continue;
    const std::string key = lowercase(std::string(tokens[0]));
    switch (expect) {
      case Expect::kSolid:
      case Expect::kNextSolid:
        if (key != "solid") {
          if (expect == Expect::kSolid) {
            throw InvalidInputError(path +
                                    ": not an STL file (neither 'solid' ASCII nor a binary STL "
                                    "whose size matches its triangle count)");
          }
          fail(lines, "unexpected " + quoted(tokens[0]) + " after 'endsolid'");
        }
        expect = Expect::kFacetOrEndSolid;
        break;
      case Expect::kFacetOrEndSolid:
        if (key == "endsolid") {
          expect = Expect::kNextSolid;
        } else if (key == "facet") {
          face.clear();
          soup.face_lines.push_back(lines.number());
          ++facets;
          expect = Expect::kOuterLoop;
        } else {
          fail(lines, "expected 'facet normal nx ny nz' or 'endsolid', found " + quoted(tokens[0]));
        }
        break;
      case Expect::kOuterLoop:
        if (key != "outer" || tokens.size() != 2 || lowercase(std::string(tokens[1])) != "loop") {
          fail(lines, "expected 'outer loop' after 'facet'");
        }
        expect = Expect::kVertex;
        break;
      case Expect::kVertex: {
        if (tokens.size() != 4 || key != "vertex") {
          // Counted as a corner anyway, so that a cut-off file also says where it ends.
          errors.add(lines, "expected 'vertex x y z' (three lines after each 'outer loop')");
          face.push_back(-1);
        } else {
          std::array<double, 3> x{};
          bool ok = true;
          for (int k = 0; k < 3; ++k) {
            const std::string_view t = tokens[k + 1];
            const NumberStatus status = parse_double(t, x[k]);
            if (status != NumberStatus::kOk) {
              errors.add(lines,
                         "vertex coordinate " + quoted(t) +
                             (status == NumberStatus::kNotANumber ? " is not a number"
                                                                  : " is out of the double range"));
              ok = false;
            } else if (!std::isfinite(x[k])) {
              errors.add(lines,
                         "vertex coordinate " + quoted(t) + " is non-finite (NaN or infinite)");
              ok = false;
            }
          }
          int index = -1;
          if (ok) {
            const auto [it, added] = vertex_of.emplace(x, static_cast<int>(soup.points.size()));
            if (added) {
              soup.points.push_back(Vec3(x[0], x[1], x[2]));
              soup.point_lines.push_back(lines.number());
            }
            index = it->second;
          }
          face.push_back(index);
        }
        if (face.size() == 3) {
          // Equal corners stay in the face: the mesh builder reports it as degenerate.
          soup.faces.push_back(face);
          expect = Expect::kEndLoop;
        }
        break;
      }
      case Expect::kEndLoop:
        if (key != "endloop") {
          fail(lines, "expected 'endloop' after three corners (STL facets are triangles)");
        }
        expect = Expect::kEndFacet;
        break;
      case Expect::kEndFacet:
        if (key != "endfacet") fail(lines, "expected 'endfacet'");
        expect = Expect::kFacetOrEndSolid;
        break;
    }
  }
  if (expect == Expect::kSolid) {  // blank
    throw InvalidInputError(path + ": not an STL file (no 'solid' line)");
  }
  if (expect == Expect::kFacetOrEndSolid) {
    errors.add(lines.number(), "the file ends after " + plural(facets, "facet", "facets") +
                                   " without 'endsolid' (truncated?)");
  } else if (expect != Expect::kNextSolid) {
    errors.add(lines.number(), "the file ends inside facet " + std::to_string(facets) +
                                   " without 'endsolid' (truncated?)");
  }
  errors.throw_if_any();
  soup.face_lines.resize(soup.faces.size());
  return soup;
}

}  // namespace qs::mesh_detail
