// OBJ reader: v and f statements; everything else is ignored, unknown statements with a warning.
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs::mesh_detail {

PolygonSoup parse_obj(const std::string& path, std::string_view text) {
  PolygonSoup soup;
  ParseErrors errors(path);
  std::map<std::string, int> unknown;  // statement -> count, reported as a warning
  std::vector<std::string_view> tokens;
  std::vector<std::string_view> parts;  // of one face vertex "v/vt/vn"
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    tokenize(line, tokens);
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    if (key == "v") {
      const std::size_t n = tokens.size() - 1;
      Vec3 p(0.0, 0.0, 0.0);
      // x y z, optionally with w (4) or an RGB colour (6, 7) as common exporters write them.
      if (n != 3 && n != 4 && n != 6 && n != 7) {
        errors.add(lines, "vertex has " + std::to_string(n) + " coordinates, expected 3");
      } else {
        parse_point(tokens, 1, p, errors, lines);
        for (std::size_t k = 4; k <= n; ++k) {
          double ignored = 0.0;
          if (parse_double(tokens[k], ignored) != NumberStatus::kOk) {
            errors.add(lines, "vertex value " + quoted(tokens[k]) + " is not a number");
          }
        }
      }
      // Kept even when broken, so that later relative indices still count correctly.
      soup.points.push_back(p);
      soup.point_lines.push_back(lines.number());
    } else if (key == "f") {
      const std::size_t n = tokens.size() - 1;
      if (n < 3) {
        errors.add(lines, "face has " + std::to_string(n) + " vertices, expected at least 3");
        continue;
      }
      std::vector<int> face;
      face.reserve(n);
      bool ok = true;
      for (std::size_t i = 1; i <= n; ++i) {
        // v, v/vt, v/vt/vn or v//vn: only the position index matters here.
        const std::string_view t = tokens[i];
        parts.clear();
        for (std::size_t begin = 0;;) {
          const std::size_t slash = t.find('/', begin);
          parts.push_back(t.substr(begin, slash == std::string_view::npos ? slash : slash - begin));
          if (slash == std::string_view::npos) break;
          begin = slash + 1;
        }
        const std::string_view head = parts[0];
        bool well_formed = parts.size() <= 3;
        for (std::size_t k = 1; k < parts.size(); ++k) {
          long long ignored = 0;
          if (!parts[k].empty() && parse_integer(parts[k], ignored) != NumberStatus::kOk) {
            well_formed = false;
          }
        }
        long long index = 0;
        const NumberStatus status = parse_integer(head, index);
        if (!well_formed || status == NumberStatus::kNotANumber) {
          errors.add(lines, "face vertex " + quoted(t) + " is not an index (v, v/vt, v/vt/vn)");
          ok = false;
        } else if (status == NumberStatus::kOutOfRange) {
          errors.add(lines, "face vertex index " + quoted(head) + " is out of range");
          ok = false;
        } else if (index == 0) {
          errors.add(lines, "face vertex index 0 is invalid (OBJ indices start at 1)");
          ok = false;
        } else {
          // Negative indices count back from the last vertex read so far (-1 is the latest).
          const long long resolved =
              index > 0 ? index - 1 : static_cast<long long>(soup.points.size()) + index;
          face.push_back(clamp_index(resolved));
        }
      }
      if (ok) {
        soup.faces.push_back(std::move(face));
        soup.face_lines.push_back(lines.number());
      }
    } else if (key == "vt" || key == "vn" || key == "vp" || key == "o" || key == "g" ||
               key == "s" || key == "usemtl" || key == "mtllib" || key == "l") {
      continue;
    } else {
      ++unknown[std::string(key)];
    }
  }
  errors.throw_if_any();
  if (!unknown.empty()) {
    std::string what;
    for (const auto& [key, count] : unknown) {
      what += (what.empty() ? "" : ", ") + plural(count, "line", "lines") + " '" + key + "'";
    }
    soup.warnings.push_back("ignored unknown OBJ statements: " + what);
  }
  return soup;
}

}  // namespace qs::mesh_detail
