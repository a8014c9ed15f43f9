// STL checks: binary STL by its size, ASCII STL line by line, before OpenMesh's reader.
#include <cctype>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs::mesh_detail {

// Binary STL is recognized like OpenMesh does: the size matches 84 + 50 * #triangles.
long long check_stl(const std::string& path, std::string_view bytes) {
  if (bytes.size() >= 84) {
    std::uint32_t n = 0;
    for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(bytes[80 + k]);
    if (84 + 50 * static_cast<std::uint64_t>(n) == bytes.size()) return n;
  }
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  if (lowercase(std::string(bytes.substr(i, 5))) != "solid") {
    throw InvalidInputError(path +
                            ": not an STL file (neither 'solid' ASCII nor a binary STL whose "
                            "size matches its triangle count)");
  }
  // OpenMesh's ASCII reader starts a triangle at every line containing "outer" or "OUTER" and
  // takes the next three lines as its corners, whatever they hold (unparsable numbers keep the
  // previous value). Check exactly that, so that a cut or garbled file is an error here.
  ParseErrors errors(path);
  std::vector<std::string_view> tokens;
  long long facets = 0;
  int corners_due = 0;
  LineReader lines(bytes);
  std::string_view line;
  while (lines.next(line)) {
    tokenize(line, tokens);
    if (corners_due > 0) {
      --corners_due;
      if (tokens.size() != 4 || lowercase(std::string(tokens[0])) != "vertex") {
        errors.add(lines, "expected 'vertex x y z' (three lines after each 'outer loop')");
        continue;
      }
      for (int k = 1; k <= 3; ++k) {
        double value = 0.0;
        if (parse_double(tokens[k], value) != NumberStatus::kOk) {
          errors.add(lines, "vertex coordinate " + quoted(tokens[k]) + " is not a number");
        } else if (!std::isfinite(value)) {
          errors.add(lines,
                     "vertex coordinate " + quoted(tokens[k]) + " is non-finite (NaN or infinite)");
        }
      }
    } else if (line.find("outer") != std::string_view::npos ||
               line.find("OUTER") != std::string_view::npos) {
      ++facets;
      corners_due = 3;
    }
  }
  if (corners_due > 0) {
    errors.add(lines, "the file ends inside a facet (truncated?)");
  }
  errors.throw_if_any();
  return facets;
}

}  // namespace qs::mesh_detail
