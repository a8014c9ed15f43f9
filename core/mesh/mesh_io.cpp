#include "core/mesh/mesh_io.h"

// Entry points of the mesh readers (the formats are in obj_reader.cpp, off_reader.cpp,
// ply_reader.cpp, stl_reader.cpp and openmesh_reader.cpp), report formatting and the writer.
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string_view>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/base/input_file.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs {
namespace {

using mesh_detail::lowercase;
using mesh_detail::plural;

constexpr std::size_t kMaxListedIds = 10;

std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  return lowercase(ext);
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

// kMaxCoordinateMagnitude as written in messages ("1e+150").
std::string magnitude_limit() {
  char text[32];
  std::snprintf(text, sizeof(text), "%g", kMaxCoordinateMagnitude);
  return text;
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
         out_of_range_vertices.empty() && unreferenced_vertices.empty() &&
         bad_index_faces.empty() && non_triangle_faces.empty() && untriangulable_faces.empty() &&
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
  if (!out_of_range_vertices.empty()) {
    // "vertex 2 (line 3)": each named with its line, as the coordinates are the problem.
    std::string which;
    for (std::size_t i = 0; i < out_of_range_vertices.size() && i < kMaxListedIds; ++i) {
      const int v = out_of_range_vertices[i];
      const int line = v < static_cast<int>(vertex_lines.size()) ? vertex_lines[v] : 0;
      which += (i ? ", vertex " : "vertex ") + std::to_string(v) +
               (line > 0 ? " (line " + std::to_string(line) + ")" : "");
    }
    if (out_of_range_vertices.size() > kMaxListedIds) which += ", …";
    const std::string why = " (above " + magnitude_limit() + ", where lengths and areas overflow)";
    if (out_of_range_vertices.size() == 1) {
      out.push_back(which + ": coordinate magnitude out of range" + why);
    } else {
      out.push_back(std::to_string(out_of_range_vertices.size()) +
                    " vertices with coordinate magnitude out of range" + why + ": " + which);
    }
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
  if (!untriangulable_faces.empty()) {
    const bool one = untriangulable_faces.size() == 1;
    out.push_back(plural(untriangulable_faces.size(), "face", "faces") +
                  " cannot be triangulated without inverted triangles " +
                  face_list(untriangulable_faces, face_lines) +
                  (one ? ": its outline crosses or touches itself in its plane"
                       : ": their outlines cross or touch themselves in their planes"));
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
  // Only regular files: a FIFO would block and a device such as /dev/zero never ends.
  const std::string bytes = read_input_file(path);
  const std::string ext = extension_of(path);
  if (ext != "obj" && ext != "off" && ext != "ply" && ext != "stl") {
    throw InvalidInputError(path + ": unsupported file extension '" +
                            std::filesystem::path(path).extension().string() +
                            "' (expected .obj, .off, .ply or .stl)");
  }
  if (bytes.empty()) throw InvalidInputError(path + ": empty file");

  // Text formats may start with a UTF-8 byte-order mark; it is no part of the content.
  const std::string_view text = mesh_detail::skip_utf8_bom(bytes);
  PolygonSoup soup;
  if (ext == "obj") {
    soup = mesh_detail::parse_obj(path, text);
  } else if (ext == "off") {
    soup = mesh_detail::parse_off(path, text);
  } else if (ext == "ply") {
    soup = mesh_detail::read_with_openmesh(path, ext, text);
  } else if (mesh_detail::is_binary_stl(bytes)) {  // its 80-byte header may hold anything
    soup = mesh_detail::read_with_openmesh(path, ext, bytes);
  } else {
    soup = mesh_detail::parse_ascii_stl(path, text);
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
