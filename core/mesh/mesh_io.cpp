#include "core/mesh/mesh_io.h"

#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/ImporterT.hh>
#include <algorithm>
#include <cctype>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <ostream>
#include <string_view>
#include <system_error>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"

namespace qs {
namespace {

constexpr std::size_t kMaxListedIds = 10;
constexpr std::size_t kMaxListedErrors = 10;

// ---------------------------------------------------------------------------------------------
// Text helpers

std::string lowercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  return lowercase(ext);
}

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

// Splits a line into whitespace-separated tokens, dropping a trailing "# comment".
void tokenize(std::string_view line, std::vector<std::string_view>& tokens) {
  tokens.clear();
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_space(line[i])) ++i;
    const std::size_t begin = i;
    while (i < line.size() && !is_space(line[i])) ++i;
    if (i > begin) tokens.push_back(line.substr(begin, i - begin));
  }
}

// Walks a buffer line by line (LF or CRLF) and remembers the 1-based line number.
class LineReader {
 public:
  explicit LineReader(std::string_view text) : text_(text) {}

  bool next(std::string_view& line) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = text_.find('\n', pos_);
    unterminated_ = end == std::string_view::npos;
    if (unterminated_) end = text_.size();
    line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    ++number_;
    return true;
  }
  int number() const { return number_; }
  //! True when the current line is the last one and no newline ends it: a cut-off file.
  bool unterminated() const { return unterminated_; }

  //! Position to come back to after looking ahead.
  struct State {
    std::size_t pos;
    int number;
    bool unterminated;
  };
  State state() const { return {pos_, number_, unterminated_}; }
  void restore(const State& s) {
    pos_ = s.pos;
    number_ = s.number;
    unterminated_ = s.unterminated;
  }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
  bool unterminated_ = false;
};

// Collects line-precise parse errors and throws them together, so one run of the tool shows
// the first few problems of a broken file instead of one at a time.
class ParseErrors {
 public:
  explicit ParseErrors(std::string path) : path_(std::move(path)) {}

  void add(const LineReader& lines, const std::string& what) {
    add(lines.number(),
        what + (lines.unterminated() ? " (the file ends in the middle of this line: truncated?)"
                                     : ""));
  }
  void add(int line, const std::string& what) {
    if (count_++ < kMaxListedErrors) {
      messages_.push_back(path_ + ":" + std::to_string(line) + ": " + what);
    }
  }
  void throw_if_any() const {
    if (count_ == 0) return;
    std::string text;
    for (const auto& m : messages_) text += (text.empty() ? "" : "\n") + m;
    if (count_ > messages_.size()) {
      text +=
          "\n" + path_ + ": … and " + std::to_string(count_ - messages_.size()) + " more errors";
    }
    throw InvalidInputError(text);
  }

 private:
  std::string path_;
  std::vector<std::string> messages_;
  std::size_t count_ = 0;
};

enum class NumberStatus { kOk, kNotANumber, kOutOfRange };

NumberStatus parse_double(std::string_view token, double& value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);  // from_chars rejects '+'
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || end != token.data() + token.size() || token.empty()) {
    return NumberStatus::kNotANumber;
  }
  return NumberStatus::kOk;
}

NumberStatus parse_integer(std::string_view token, long long& value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec == std::errc::result_out_of_range) return NumberStatus::kOutOfRange;
  if (ec != std::errc() || end != token.data() + token.size() || token.empty()) {
    return NumberStatus::kNotANumber;
  }
  return NumberStatus::kOk;
}

std::string quoted(std::string_view token) {
  return "'" + std::string(token) + "'";
}

// Parses the x, y, z tokens of a vertex line; reports bad numbers and returns false.
bool parse_point(const std::vector<std::string_view>& tokens, std::size_t first, Vec3& p,
                 ParseErrors& errors, const LineReader& lines) {
  bool ok = true;
  for (int k = 0; k < 3; ++k) {
    const std::string_view t = tokens[first + k];
    switch (parse_double(t, p[k])) {
      case NumberStatus::kOk:
        break;
      case NumberStatus::kNotANumber:
        errors.add(lines, "coordinate " + quoted(t) + " is not a number");
        ok = false;
        break;
      case NumberStatus::kOutOfRange:
        errors.add(lines, "coordinate " + quoted(t) + " is out of the double range");
        ok = false;
        break;
    }
  }
  return ok;
}

// Stores an index that may be out of range as an int the mesh builder will flag.
int clamp_index(long long index) {
  return static_cast<int>(std::clamp<long long>(index, INT_MIN, INT_MAX));
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// ---------------------------------------------------------------------------------------------
// OBJ: v and f statements; everything else is ignored, unknown statements with a warning.

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

// ---------------------------------------------------------------------------------------------
// OFF (ASCII): [ST][C][N]OFF header, counts, vertex lines, "n i0 i1 ... [colour]" face lines.

PolygonSoup read_with_openmesh(const std::string& path, const std::string& format);

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
    return read_with_openmesh(path, "off");  // binary OFF stores floats anyway
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

// ---------------------------------------------------------------------------------------------
// PLY, STL and binary OFF through OpenMesh's readers.

// Records exactly what the reader hands over. OpenMesh's ImporterT would add faces to a mesh
// and silently duplicate the vertices of faces it cannot add; here faces only go into the soup
// (with their raw indices) and the scratch mesh just gets a bare face element, so that readers
// attaching attributes to the returned handle stay in bounds.
class SoupImporter : public OpenMesh::IO::ImporterT<PolyMesh> {
 public:
  using Base = OpenMesh::IO::ImporterT<PolyMesh>;
  using Base::add_face;
  using Base::add_vertex;
  using Base::set_point;

  SoupImporter(PolyMesh& scratch, PolygonSoup& soup) : Base(scratch), soup_(soup) {}

  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3f& p) override {
    return add_vertex(OpenMesh::Vec3d(p));
  }
  OpenMesh::VertexHandle add_vertex(const OpenMesh::Vec3d& p) override {
    soup_.points.push_back(p);
    return Base::add_vertex();  // handle index == soup index
  }
  OpenMesh::VertexHandle add_vertex() override {
    soup_.points.push_back(Vec3(0.0, 0.0, 0.0));
    return Base::add_vertex();
  }
  void set_point(OpenMesh::VertexHandle vh, const OpenMesh::Vec3f& p) override {
    if (vh.idx() >= 0 && vh.idx() < static_cast<int>(soup_.points.size())) {
      soup_.points[vh.idx()] = OpenMesh::Vec3d(p);
    }
  }
  OpenMesh::FaceHandle add_face(const VHandles& vhs) override {
    std::vector<int> face;
    face.reserve(vhs.size());
    for (auto vh : vhs) face.push_back(vh.idx());
    soup_.faces.push_back(std::move(face));
    soup_.face_lines.push_back(0);
    return Base::add_face(OpenMesh::HalfedgeHandle());
  }

 private:
  PolygonSoup& soup_;
};

std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InvalidInputError(path + ": cannot open file");
  std::string bytes(static_cast<std::size_t>(in.tellg()), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()))) {
    throw InvalidInputError(path + ": cannot read file");
  }
  return bytes;
}

std::string uppercase(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Binary STL is recognized like OpenMesh does: the size matches 84 + 50 * #triangles. ASCII
// STL is checked line by line. Returns the number of triangles the file holds, so that the
// ones OpenMesh's reader skips can be counted.
long long stl_triangle_count(const std::string& path, const std::string& bytes) {
  if (bytes.size() >= 84) {
    std::uint32_t n = 0;
    for (int k = 3; k >= 0; --k) n = (n << 8) | static_cast<unsigned char>(bytes[80 + k]);
    if (84 + 50 * static_cast<std::uint64_t>(n) == bytes.size()) return n;
  }
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[i]))) ++i;
  if (lowercase(bytes.substr(i, 5)) != "solid") {
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

// PLY scalar type: byte size (0 if unknown) and whether it is an integer type.
struct PlyType {
  int size = 0;
  bool integer = false;
  bool is_signed = false;
};

PlyType ply_type(std::string_view t) {
  if (t == "char" || t == "int8") return {1, true, true};
  if (t == "uchar" || t == "uint8") return {1, true, false};
  if (t == "short" || t == "int16") return {2, true, true};
  if (t == "ushort" || t == "uint16") return {2, true, false};
  if (t == "int" || t == "int32") return {4, true, true};
  if (t == "uint" || t == "uint32") return {4, true, false};
  if (t == "float" || t == "float32") return {4, false, true};
  if (t == "double" || t == "float64") return {8, false, true};
  return {};
}

struct PlyProperty {
  bool list = false;
  PlyType count;  // list only
  PlyType value;
};

struct PlyElement {
  std::string name;
  long long count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  enum class Format { kAscii, kBinaryLittleEndian, kBinaryBigEndian } format = Format::kAscii;
  std::vector<PlyElement> elements;
  long long vertices = -1;
  long long faces = -1;
  std::size_t data_offset = 0;
  int data_line = 0;  //!< line number of the header's last line
  bool double_coordinates = false;
};

// Checks the PLY header line by line before OpenMesh sees it: OpenMesh 9's header parser
// loops forever on a header cut before "end_header".
PlyHeader parse_ply_header(const std::string& path, const std::string& bytes) {
  PlyHeader header;
  ParseErrors errors(path);
  std::vector<std::string_view> tokens;
  LineReader lines(bytes);
  std::string_view line;
  bool has_format = false;
  bool ended = false;
  while (!ended && lines.next(line)) {
    tokenize(line, tokens);
    if (lines.number() == 1) {
      if (tokens.size() != 1 || tokens[0] != "ply") {
        throw InvalidInputError(path + ": not a PLY file (it does not start with 'ply')");
      }
      continue;
    }
    const std::string_view key = tokens.empty() ? std::string_view() : tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      ended = true;
    } else if (key == "format" && tokens.size() == 3 && !has_format) {
      has_format = true;
      // OpenMesh's header parser also loops forever on any other version.
      if (tokens[2] != "1.0") errors.add(lines, "unsupported PLY version " + quoted(tokens[2]));
      if (tokens[1] == "ascii") {
        header.format = PlyHeader::Format::kAscii;
      } else if (tokens[1] == "binary_little_endian") {
        header.format = PlyHeader::Format::kBinaryLittleEndian;
      } else if (tokens[1] == "binary_big_endian") {
        header.format = PlyHeader::Format::kBinaryBigEndian;
      } else {
        errors.add(lines, "unknown PLY format " + quoted(tokens[1]));
      }
    } else if (key == "element" && tokens.size() == 3) {
      PlyElement element;
      element.name = std::string(tokens[1]);
      if (parse_integer(tokens[2], element.count) != NumberStatus::kOk || element.count < 0) {
        errors.add(lines, "element count " + quoted(tokens[2]) + " is not a valid number");
      }
      if (element.name == "vertex") header.vertices = element.count;
      if (element.name == "face") header.faces = element.count;
      header.elements.push_back(std::move(element));
    } else if (key == "property" && !header.elements.empty() && tokens.size() == 3 &&
               ply_type(tokens[1]).size > 0) {
      header.elements.back().properties.push_back({false, {}, ply_type(tokens[1])});
      if (header.elements.back().name == "vertex" &&
          (tokens[2] == "x" || tokens[2] == "y" || tokens[2] == "z") &&
          ply_type(tokens[1]).size == 8) {
        header.double_coordinates = true;
      }
    } else if (key == "property" && !header.elements.empty() && tokens.size() == 5 &&
               tokens[1] == "list" && ply_type(tokens[2]).integer && ply_type(tokens[3]).size > 0) {
      header.elements.back().properties.push_back({true, ply_type(tokens[2]), ply_type(tokens[3])});
    } else {
      errors.add(lines, "unexpected PLY header line " + quoted(line.substr(0, 60)));
    }
  }
  if (!ended) {
    errors.add(lines, "the PLY header has no 'end_header' line (truncated?)");
  } else if (!has_format) {
    errors.add(lines, "the PLY header has no 'format' line");
  }
  for (const PlyElement& element : header.elements) {
    // Records without properties would take no bytes, so nothing would bound their count.
    if (element.count > 0 && element.properties.empty()) {
      errors.add(lines, "PLY element '" + element.name + "' has records but no properties");
    }
  }
  errors.throw_if_any();
  header.data_offset = std::min(lines.state().pos, bytes.size());
  header.data_line = lines.number();
  return header;
}

// Walks every PLY record, so that OpenMesh's readers, which trust element and list counts
// blindly (a count of 4e9 makes them loop for minutes), only see files whose counts fit.
void check_ply_records(const std::string& path, const std::string& bytes, const PlyHeader& header) {
  const std::string_view data = std::string_view(bytes).substr(header.data_offset);
  if (header.format == PlyHeader::Format::kAscii) {
    std::size_t pos = 0;
    int line = header.data_line + 1;
    std::string_view token;
    const auto next_token = [&]() {
      while (pos < data.size() && (is_space(data[pos]) || data[pos] == '\n')) {
        if (data[pos++] == '\n') ++line;
      }
      const std::size_t begin = pos;
      while (pos < data.size() && !is_space(data[pos]) && data[pos] != '\n') ++pos;
      token = data.substr(begin, pos - begin);
      return !token.empty();
    };
    for (const PlyElement& element : header.elements) {
      for (long long r = 0; r < element.count; ++r) {
        for (const PlyProperty& property : element.properties) {
          if (!next_token()) {
            throw InvalidInputError(path + ":" + std::to_string(line) + ": the file ends in " +
                                    element.name + " " + std::to_string(r) + " of " +
                                    std::to_string(element.count) + " (truncated?)");
          }
          if (!property.list) continue;
          long long n = 0;
          if (parse_integer(token, n) != NumberStatus::kOk || n < 0) {
            throw InvalidInputError(path + ":" + std::to_string(line) + ": list size " +
                                    quoted(token) + " of " + element.name + " " +
                                    std::to_string(r) + " is not a valid count");
          }
          for (long long i = 0; i < n; ++i) {
            if (!next_token()) {
              throw InvalidInputError(path + ":" + std::to_string(line) + ": the file ends in " +
                                      element.name + " " + std::to_string(r) + " of " +
                                      std::to_string(element.count) + " (truncated?)");
            }
          }
        }
      }
    }
    return;
  }
  const bool big_endian = header.format == PlyHeader::Format::kBinaryBigEndian;
  std::size_t pos = 0;
  for (const PlyElement& element : header.elements) {
    for (long long r = 0; r < element.count; ++r) {
      for (const PlyProperty& property : element.properties) {
        const auto truncated = [&]() {
          return InvalidInputError(path + ": the binary PLY data ends in " + element.name + " " +
                                   std::to_string(r) + " of " + std::to_string(element.count) +
                                   " (truncated?)");
        };
        if (!property.list) {
          if (data.size() - pos < static_cast<std::size_t>(property.value.size)) throw truncated();
          pos += property.value.size;
          continue;
        }
        const int size = property.count.size;
        if (data.size() - pos < static_cast<std::size_t>(size)) throw truncated();
        std::uint64_t raw = 0;
        for (int k = 0; k < size; ++k) {
          raw =
              (raw << 8) | static_cast<unsigned char>(data[pos + (big_endian ? k : size - 1 - k)]);
        }
        pos += size;
        const bool negative = property.count.is_signed && (raw >> (8 * size - 1)) != 0;
        if (negative) {
          throw InvalidInputError(path + ": negative list size in " + element.name + " " +
                                  std::to_string(r));
        }
        if (raw > (data.size() - pos) / property.value.size) throw truncated();
        pos += raw * property.value.size;
      }
    }
  }
}

// Plain "OFF BINARY" as OpenMesh reads it: little-endian int32 counts (vertices, faces,
// edges), 3 float32 per vertex, then per face an int32 n and n int32 indices. The record walk
// keeps OpenMesh's reader, which trusts every count, away from absurd sizes.
void check_binary_off(const std::string& path, const std::string& bytes) {
  const std::size_t header_end = bytes.find('\n');
  std::vector<std::string_view> tokens;
  tokenize(std::string_view(bytes).substr(0, header_end), tokens);
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

PolygonSoup read_with_openmesh(const std::string& path, const std::string& format) {
  const std::string bytes = read_bytes(path);
  long long expected_faces = -1;
  PlyHeader ply;
  if (format == "stl") expected_faces = stl_triangle_count(path, bytes);
  if (format == "ply") {
    ply = parse_ply_header(path, bytes);
    check_ply_records(path, bytes, ply);
  }
  if (format == "off") check_binary_off(path, bytes);

  PolyMesh scratch;
  PolygonSoup soup;
  SoupImporter importer(scratch, soup);
  OpenMesh::IO::Options options;  // request nothing but positions and faces
  // OpenMesh's readers are singletons with mutable state (options of the current file), so
  // two threads must not read at the same time.
  static std::mutex openmesh_readers;
  const std::lock_guard<std::mutex> lock(openmesh_readers);
  if (!OpenMesh::IO::IOManager().read(path, importer, options)) {
    throw InvalidInputError(path + ": OpenMesh's " + uppercase(format) +
                            " reader could not read the file (malformed or unsupported " +
                            uppercase(format) + ")");
  }
  for (std::size_t f = 0; f < soup.faces.size(); ++f) {
    if (soup.faces[f].size() < 3) {
      throw InvalidInputError(path + ": face " + std::to_string(f) + " has " +
                              std::to_string(soup.faces[f].size()) +
                              " vertices (file truncated or malformed)");
    }
  }
  if (format == "ply") {
    if ((ply.vertices >= 0 && ply.vertices != static_cast<long long>(soup.points.size())) ||
        (ply.faces >= 0 && ply.faces != static_cast<long long>(soup.faces.size()))) {
      throw InvalidInputError(path + ": the header declares " + std::to_string(ply.vertices) +
                              " vertices and " + std::to_string(ply.faces) + " faces, read " +
                              std::to_string(soup.points.size()) + " and " +
                              std::to_string(soup.faces.size()) + " (truncated?)");
    }
    if (ply.double_coordinates) {
      soup.warnings.push_back(
          "the PLY file stores double coordinates, but OpenMesh's PLY reader keeps only float "
          "precision (about 7 significant digits)");
    }
  }
  if (expected_faces > static_cast<long long>(soup.faces.size())) {
    soup.skipped_degenerate_faces =
        static_cast<int>(expected_faces - static_cast<long long>(soup.faces.size()));
  }
  return soup;
}

// ---------------------------------------------------------------------------------------------
// Report formatting

std::string id_list(const std::vector<int>& ids) {
  std::string s;
  for (std::size_t i = 0; i < ids.size() && i < kMaxListedIds; ++i) {
    s += (i ? ", " : "") + std::to_string(ids[i]);
  }
  if (ids.size() > kMaxListedIds) s += ", …";
  return s;
}

// "(file faces 3, 7; lines 12, 16)": face indices plus source lines when the reader knew them.
std::string face_list(const std::vector<int>& faces, const std::vector<int>& face_lines) {
  std::string s = "(file " + std::string(faces.size() == 1 ? "face " : "faces ") + id_list(faces);
  std::vector<int> lines;
  for (int f : faces) {
    if (f < 0 || f >= static_cast<int>(face_lines.size()) || face_lines[f] <= 0) {
      lines.clear();
      break;
    }
    lines.push_back(face_lines[f]);
  }
  if (!lines.empty()) s += (lines.size() == 1 ? "; line " : "; lines ") + id_list(lines);
  return s + ")";
}

std::string vertex_list(const std::vector<int>& ids) {
  return std::string(ids.size() == 1 ? "(id " : "(ids ") + id_list(ids) + ")";
}

const char* drop_explanation(DropReason reason, bool one) {
  switch (reason) {
    case DropReason::kNonManifoldEdge:
      return one ? "dropped because it would make a non-manifold edge"
                 : "dropped because they would make a non-manifold edge";
    case DropReason::kInconsistentOrientation:
      return one ? "dropped because its orientation is inconsistent with a neighbouring face"
                 : "dropped because their orientation is inconsistent with a neighbouring face";
    case DropReason::kNonManifoldVertex:
      return one ? "dropped because it would make a non-manifold vertex"
                 : "dropped because they would make a non-manifold vertex";
    case DropReason::kDuplicate:
      return one ? "dropped because it duplicates an earlier face"
                 : "dropped because they duplicate an earlier face";
  }
  return "dropped";
}

void finish_load(const MeshReport& result, MeshReport* report) {
  if (report) *report = result;
  if (result.ok()) return;
  std::string message = result.path + ": invalid mesh";
  for (const auto& line : result.problems()) message += "\n" + line;
  throw InvalidInputError(message);
}

}  // namespace

bool MeshReport::ok() const {
  const bool components_ok = components == 1 || (multiple_components_allowed && components > 1);
  return input_faces > 0 && components_ok && dropped_faces.empty() &&
         nonmanifold_vertices.empty() && degenerate_faces.empty() && nonfinite_vertices.empty() &&
         unreferenced_vertices.empty() && bad_index_faces.empty() && non_triangle_faces.empty() &&
         skipped_degenerate_faces == 0;
}

std::vector<std::string> MeshReport::problems() const {
  // Each line: "<count> <what> (<first ids>)[: <why>]".
  std::vector<std::string> out;
  if (input_faces == 0) out.push_back("no faces");
  if (!bad_index_faces.empty()) {
    out.push_back(plural(bad_index_faces.size(), "face refers", "faces refer") +
                  " to missing vertices " + face_list(bad_index_faces, face_lines) +
                  ": the file has " + plural(vertices, "vertex", "vertices"));
  }
  if (!nonfinite_vertices.empty()) {
    out.push_back(plural(nonfinite_vertices.size(), "vertex has", "vertices have") +
                  " non-finite coordinates " + vertex_list(nonfinite_vertices) +
                  ": NaN or infinite");
  }
  if (!degenerate_faces.empty()) {
    out.push_back(plural(degenerate_faces.size(), "degenerate face", "degenerate faces") + " " +
                  face_list(degenerate_faces, face_lines) + ": zero area or a repeated vertex");
  }
  if (skipped_degenerate_faces > 0) {
    out.push_back(plural(skipped_degenerate_faces, "degenerate triangle", "degenerate triangles") +
                  " skipped by the STL reader: two corners coincide");
  }
  if (!non_triangle_faces.empty()) {
    out.push_back(plural(non_triangle_faces.size(), "face", "faces") +
                  " with more than 3 vertices " + face_list(non_triangle_faces, face_lines) +
                  ": triangulation is off");
  }
  for (DropReason reason : {DropReason::kNonManifoldEdge, DropReason::kInconsistentOrientation,
                            DropReason::kNonManifoldVertex, DropReason::kDuplicate}) {
    std::vector<int> faces;
    for (std::size_t i = 0; i < dropped_faces.size(); ++i) {
      // A report filled by hand may lack reasons; those count as refused at a vertex.
      const DropReason r =
          i < drop_reasons.size() ? drop_reasons[i] : DropReason::kNonManifoldVertex;
      if (r == reason) faces.push_back(dropped_faces[i]);
    }
    if (faces.empty()) continue;
    out.push_back(plural(faces.size(), "face", "faces") + " " +
                  drop_explanation(reason, faces.size() == 1) + " " + face_list(faces, face_lines));
  }
  if (!nonmanifold_vertices.empty()) {
    out.push_back(
        plural(nonmanifold_vertices.size(), "non-manifold vertex", "non-manifold vertices") + " " +
        vertex_list(nonmanifold_vertices) +
        (nonmanifold_vertices.size() == 1 ? ": the faces around it do not form a single fan"
                                          : ": the faces around each do not form a single fan"));
  }
  if (!unreferenced_vertices.empty()) {
    out.push_back(
        plural(unreferenced_vertices.size(), "unreferenced vertex", "unreferenced vertices") + " " +
        vertex_list(unreferenced_vertices) +
        (unreferenced_vertices.size() == 1 ? ": no face uses it" : ": no face uses them"));
  }
  if (input_faces > 0 && components > 1 && !multiple_components_allowed) {
    out.push_back(std::to_string(components) + " connected components (expected 1)");
  }
  return out;
}

PolygonSoup read_polygon_soup(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InvalidInputError(path + ": cannot open file");
  }
  const std::string ext = extension_of(path);
  if (ext != "obj" && ext != "off" && ext != "ply" && ext != "stl") {
    throw InvalidInputError(path + ": unsupported file extension '" +
                            std::filesystem::path(path).extension().string() +
                            "' (expected .obj, .off, .ply or .stl)");
  }
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InvalidInputError(path + ": cannot open file");
  if (size == 0) throw InvalidInputError(path + ": empty file");

  PolygonSoup soup;
  if (ext == "obj") {
    soup = parse_obj(path, read_bytes(path));
  } else if (ext == "off") {
    soup = parse_off(path, read_bytes(path));
  } else {
    soup = read_with_openmesh(path, ext);
  }
  if (soup.faces.empty() && soup.skipped_degenerate_faces == 0) {
    throw InvalidInputError(path + ": no faces (" +
                            plural(soup.points.size(), "vertex", "vertices") + ", 0 faces)");
  }
  return soup;
}

TriMesh load_mesh(const std::string& path, MeshReport* report, const LoadMeshOptions& options) {
  const PolygonSoup soup = read_polygon_soup(path);
  MeshReport result;
  result.path = path;
  TriMesh mesh = build_tri_mesh(soup, result, options);
  finish_load(result, report);
  return mesh;
}

PolyMesh load_poly_mesh(const std::string& path, MeshReport* report,
                        const LoadMeshOptions& options) {
  const PolygonSoup soup = read_polygon_soup(path);
  MeshReport result;
  result.path = path;
  PolyMesh mesh = build_poly_mesh(soup, result);
  result.multiple_components_allowed = options.allow_multiple_components;
  finish_load(result, report);
  return mesh;
}

void save_mesh_obj(const TriMesh& mesh, const std::string& path) {
  write_file_atomic(path, [&](std::ostream& out) {
    char buffer[128];
    out << "# QuadSketch mesh: " << mesh.n_vertices() << " vertices, " << mesh.n_faces()
        << " faces\n";
    for (auto vh : mesh.vertices()) {
      const Vec3& p = mesh.point(vh);
      // %.17g round-trips every double exactly.
      std::snprintf(buffer, sizeof(buffer), "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
      out << buffer;
    }
    for (auto fh : mesh.faces()) {
      if (mesh.has_face_status() && mesh.status(fh).deleted()) continue;
      out << 'f';
      for (auto vh : mesh.fv_range(fh)) out << ' ' << vh.idx() + 1;
      out << '\n';
    }
  });
}

}  // namespace qs
