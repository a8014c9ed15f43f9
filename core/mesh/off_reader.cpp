// OFF reader: ASCII [ST][C][N]OFF (header, counts, vertex lines, "n i0 i1 ... [colour]" face
// lines) parsed here; "OFF BINARY" checked here and read by OpenMesh.
#include <algorithm>
#include <climits>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs::mesh_detail {

PolygonSoup parse_off(const std::string& path, std::string_view text) {
  PolygonSoup soup;
  ParseErrors errors(path);
  std::vector<std::string_view> tokens;
  std::vector<std::string_view> continuation;
  std::vector<std::string_view> values;  // indices (and colour) of one face
  LineReader lines(text);
  std::string_view line;
  const auto next_tokens = [&]() {
    while (lines.next(line)) {
      tokenize(line, tokens);
      if (!tokens.empty()) return true;
    }
    return false;
  };

  if (!next_tokens()) throw InvalidInputError(path + ": no OFF header (only comments)");
  const std::string header(tokens[0]);
  const std::size_t off_pos = header.rfind("OFF");
  if (off_pos == std::string::npos || off_pos + 3 != header.size()) {
    errors.add(lines, "expected the header 'OFF', found " + quoted(tokens[0]));
    errors.throw_if_any();
  }
  const std::string prefix = header.substr(0, off_pos);
  if (std::find(tokens.begin() + 1, tokens.end(), "BINARY") != tokens.end()) {
    return read_with_openmesh(path, "off", text);  // binary OFF stores floats anyway
  }
  for (char c : prefix) {
    if (c != 'S' && c != 'T' && c != 'C' && c != 'N') {
      errors.add(lines, "unsupported OFF variant " + quoted(tokens[0]) + " (only 3D OFF)");
      errors.throw_if_any();
    }
  }
  // Plain OFF vertices are exactly x y z; the prefixed variants append normals, colours or
  // texture coordinates, which are ignored.
  const bool extra_vertex_values = !prefix.empty();

  // Counts: on the header line ("OFF 8 6 0") or on the next line.
  const bool counts_on_header = tokens.size() > 1;
  if (!counts_on_header && !next_tokens()) {
    errors.add(lines, "missing the line with the vertex and face counts (truncated?)");
    errors.throw_if_any();
  }
  const std::size_t first = counts_on_header ? 1 : 0;
  long long counts[2] = {0, 0};
  const std::size_t n_counts = tokens.size() - first;
  if (n_counts < 2 || n_counts > 3) {
    errors.add(lines, "expected 'vertices faces [edges]' counts, found " +
                          std::to_string(n_counts) + " values");
    errors.throw_if_any();
  }
  for (int k = 0; k < 2; ++k) {
    if (parse_integer(tokens[first + k], counts[k]) != NumberStatus::kOk || counts[k] < 0 ||
        counts[k] > INT_MAX) {
      errors.add(lines, "count " + quoted(tokens[first + k]) + " is not a valid number");
      errors.throw_if_any();
    }
  }
  const int n_vertices = static_cast<int>(counts[0]);
  const int n_faces = static_cast<int>(counts[1]);
  // The counts come from the file: cap the reservation so a lying header cannot exhaust memory.
  soup.points.reserve(std::min(n_vertices, 1 << 24));
  soup.point_lines.reserve(std::min(n_vertices, 1 << 24));
  soup.faces.reserve(std::min(n_faces, 1 << 24));

  const auto truncated = [&](const std::string& what) {
    errors.add(lines.number(), "unexpected end of file: the header declares " +
                                   plural(n_vertices, "vertex", "vertices") + " and " +
                                   plural(n_faces, "face", "faces") + ", found " + what +
                                   " (truncated?)");
    errors.throw_if_any();
  };

  for (int v = 0; v < n_vertices; ++v) {
    if (!next_tokens()) truncated(plural(v, "vertex", "vertices"));
    const std::size_t n = tokens.size();
    Vec3 p(0.0, 0.0, 0.0);
    if (n < 3 || (n != 3 && !extra_vertex_values)) {
      errors.add(lines, "vertex has " + std::to_string(n) + " coordinates, expected 3");
    } else {
      parse_point(tokens, 0, p, errors, lines);
    }
    soup.points.push_back(p);
    soup.point_lines.push_back(lines.number());
  }
  for (int f = 0; f < n_faces; ++f) {
    if (!next_tokens()) {
      truncated(plural(n_vertices, "vertex", "vertices") + " and " + plural(f, "face", "faces"));
    }
    long long n = 0;
    if (parse_integer(tokens[0], n) != NumberStatus::kOk) {
      errors.add(lines, "face size " + quoted(tokens[0]) + " is not a number");
      continue;
    }
    if (n < 3) {
      errors.add(lines, "face has " + std::to_string(n) + " vertices, expected at least 3");
      continue;
    }
    const int face_line = lines.number();
    values.assign(tokens.begin() + 1, tokens.end());
    const long long listed = static_cast<long long>(values.size());
    if (listed < n) {
      // Some writers put one index per line (libigl's inspired_mesh quads). The face may go on
      // over the next lines if they hold nothing but its missing indices; anything else is an
      // error, so that a short face never swallows the start of the next one.
      const LineReader::State after_face_line = lines.state();
      bool complete = false;
      bool end_of_file = true;
      while (lines.next(line)) {
        tokenize(line, continuation);
        if (continuation.empty()) continue;
        if (static_cast<long long>(values.size() + continuation.size()) > n) {
          end_of_file = false;
          break;
        }
        values.insert(values.end(), continuation.begin(), continuation.end());
        if (static_cast<long long>(values.size()) == n) {
          complete = true;
          break;
        }
      }
      if (!complete) {
        if (end_of_file) {
          truncated(plural(n_vertices, "vertex", "vertices") + " and " +
                    plural(f, "face", "faces") + " and a partial face");
        }
        lines.restore(after_face_line);
        errors.add(face_line, "face declares " + std::to_string(n) + " vertices but lists " +
                                  std::to_string(listed));
        continue;
      }
    }
    // After the indices an optional colour (RGB or RGBA, integers or floats) may follow.
    if (static_cast<long long>(values.size()) - n > 4) {
      errors.add(lines, "face has " + std::to_string(values.size() - n) +
                            " values after its vertex indices, expected at most 4 (a colour)");
      continue;
    }
    std::vector<int> face;
    face.reserve(static_cast<std::size_t>(n));
    bool ok = true;
    for (long long i = 0; i < n; ++i) {
      long long index = 0;
      const NumberStatus status = parse_integer(values[i], index);
      if (status == NumberStatus::kOk) {
        face.push_back(clamp_index(index));
      } else {
        errors.add(lines, "face vertex index " + quoted(values[i]) +
                              (status == NumberStatus::kNotANumber ? " is not an integer"
                                                                   : " is out of range"));
        ok = false;
      }
    }
    for (std::size_t i = static_cast<std::size_t>(n); i < values.size(); ++i) {
      double ignored = 0.0;
      if (parse_double(values[i], ignored) != NumberStatus::kOk) {
        errors.add(lines, "face colour value " + quoted(values[i]) + " is not a number");
        ok = false;
      }
    }
    if (ok) {
      soup.faces.push_back(std::move(face));
      soup.face_lines.push_back(face_line);
    }
  }
  if (next_tokens()) {
    errors.add(lines, "unexpected content after the " + plural(n_faces, "face", "faces") +
                          " declared in the header");
  }
  errors.throw_if_any();
  return soup;
}

// Plain "OFF BINARY" as OpenMesh reads it: little-endian int32 counts (vertices, faces,
// edges), 3 float32 per vertex, then per face an int32 n and n int32 indices. The record walk
// keeps OpenMesh's reader, which trusts every count, away from absurd sizes.
void check_binary_off(const std::string& path, std::string_view bytes) {
  const std::size_t header_end = bytes.find('\n');
  std::vector<std::string_view> tokens;
  tokenize(bytes.substr(0, header_end), tokens);
  if (tokens.size() != 2 || tokens[0] != "OFF" || tokens[1] != "BINARY") {
    throw InvalidInputError(path + ": unsupported binary OFF variant (only 'OFF BINARY')");
  }
  std::size_t pos = header_end + 1;
  const auto read_uint32 = [&](std::uint32_t& value) {
    if (bytes.size() < pos + 4) return false;
    value = 0;
    for (int k = 3; k >= 0; --k) value = (value << 8) | static_cast<unsigned char>(bytes[pos + k]);
    pos += 4;
    return true;
  };
  const auto fail = [&](const std::string& what) {
    return InvalidInputError(path + ": binary OFF " + what);
  };
  std::uint32_t n_vertices = 0;
  std::uint32_t n_faces = 0;
  std::uint32_t n_edges = 0;
  if (!read_uint32(n_vertices) || !read_uint32(n_faces) || !read_uint32(n_edges)) {
    throw fail("header is cut off (truncated?)");
  }
  if ((bytes.size() - pos) / 12 < n_vertices) {
    throw fail("data ends before its " + std::to_string(n_vertices) + " vertices (truncated?)");
  }
  pos += 12 * static_cast<std::size_t>(n_vertices);
  for (std::uint32_t f = 0; f < n_faces; ++f) {
    std::uint32_t n = 0;
    if (!read_uint32(n) || (bytes.size() - pos) / 4 < n) {
      throw fail("data ends in face " + std::to_string(f) + " of " + std::to_string(n_faces) +
                 " (truncated?)");
    }
    pos += 4 * static_cast<std::size_t>(n);
  }
  if (pos != bytes.size()) {
    throw fail("has " + std::to_string(bytes.size() - pos) +
               " unexpected bytes after the last face (per-face colours are not supported)");
  }
}

}  // namespace qs::mesh_detail
