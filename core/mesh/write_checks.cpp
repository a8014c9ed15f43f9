#include "core/mesh/write_checks.h"

#include <string>
#include <vector>

#include "core/mesh/mesh_checks.h"

namespace qs {

namespace {

template <typename MeshT>
PolygonSoup soup_of(const MeshT& mesh) {
  PolygonSoup soup;
  soup.points.reserve(mesh.n_vertices());
  for (const auto v : mesh.vertices()) soup.points.push_back(mesh.point(v));
  soup.faces.reserve(mesh.n_faces());
  for (const auto f : mesh.faces()) {
    std::vector<int> face;
    for (const auto v : mesh.fv_range(f)) face.push_back(v.idx());
    soup.faces.push_back(std::move(face));
  }
  return soup;
}

}  // namespace

MeshReport check_as_read(const TriMesh& mesh) {
  MeshReport report;
  build_tri_mesh(soup_of(mesh), report, LoadMeshOptions{});
  return report;
}

MeshReport check_as_read(const PolyMesh& mesh) {
  MeshReport report;
  build_poly_mesh(soup_of(mesh), report);
  return report;
}

std::string rejection_message(const MeshReport& report, const std::string& what) {
  std::string message = what + " would be rejected when read back:";
  for (const auto& line : report.problems()) message += "\n  " + line;
  return message;
}

}  // namespace qs
