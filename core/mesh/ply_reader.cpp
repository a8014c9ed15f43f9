// PLY checks: the header line by line and every record, before OpenMesh's reader sees the file.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs::mesh_detail {
namespace {

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
PlyHeader parse_ply_header(const std::string& path, std::string_view bytes) {
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
void check_ply_records(const std::string& path, std::string_view bytes, const PlyHeader& header) {
  const std::string_view data = bytes.substr(header.data_offset);
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

}  // namespace

PlyInfo check_ply(const std::string& path, std::string_view text) {
  const PlyHeader header = parse_ply_header(path, text);
  check_ply_records(path, text, header);
  return {header.vertices, header.faces, header.double_coordinates};
}

}  // namespace qs::mesh_detail
