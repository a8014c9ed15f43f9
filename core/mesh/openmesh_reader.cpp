// PLY, STL and binary OFF through OpenMesh's readers, after the checks of ply_reader.cpp,
// stl_reader.cpp and off_reader.cpp.
#include <OpenMesh/Core/IO/IOManager.hh>
#include <OpenMesh/Core/IO/importer/ImporterT.hh>
#include <mutex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_readers.h"
#include "core/mesh/mesh_text.h"

namespace qs::mesh_detail {
namespace {

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

}  // namespace

PolygonSoup read_with_openmesh(const std::string& path, const std::string& format,
                               std::string_view text) {
  long long expected_faces = -1;
  PlyInfo ply;
  if (format == "stl" && !is_binary_stl(text, &expected_faces)) {
    throw InvalidInputError(path + ": not a binary STL file");
  }
  if (format == "ply") ply = check_ply(path, text);
  if (format == "off") check_binary_off(path, text);

  PolyMesh scratch;
  PolygonSoup soup;
  SoupImporter importer(scratch, soup);
  OpenMesh::IO::Options options;  // request nothing but positions and faces
  // A stream has no name to tell the STL variant from.
  if (format == "stl") options += OpenMesh::IO::Options::Binary;
  // OpenMesh's readers are singletons with mutable state (options of the current file), so
  // two threads must not read at the same time.
  static std::mutex openmesh_readers;
  const std::lock_guard<std::mutex> lock(openmesh_readers);
  bool read = false;
  if (format == "off") {
    read = OpenMesh::IO::IOManager().read(path, importer, options);
  } else {
    std::istringstream in(std::string(text), std::ios::in | std::ios::binary);
    read = OpenMesh::IO::IOManager().read(in, format, importer, options);
  }
  if (!read) {
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

}  // namespace qs::mesh_detail
