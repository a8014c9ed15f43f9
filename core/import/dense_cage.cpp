#include "core/import/dense_cage.h"

#include <OpenMesh/Tools/Subdivider/Uniform/CatmullClarkT.hh>
#include <algorithm>
#include <array>
#include <map>
#include <string>

#include "core/base/errors.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

double mean_edge_length(const PolyMesh& mesh) {
  double sum = 0;
  for (const auto e : mesh.edges()) sum += mesh.calc_edge_length(e);
  return mesh.n_edges() > 0 ? sum / static_cast<double>(mesh.n_edges()) : 0.0;
}

// Finds common neighbours with a stamp per vertex (no clearing between queries).
class CommonNeighbours {
 public:
  explicit CommonNeighbours(const PolyMesh& mesh) : mesh_(mesh), stamp_(mesh.n_vertices(), 0) {}

  //! The neighbours that \p a and \p b share, except \p skip.
  std::vector<int> of(int a, int b, int skip = -1) {
    ++now_;
    for (const auto x : mesh_.vv_range(VH(a))) stamp_[x.idx()] = now_;
    std::vector<int> out;
    for (const auto x : mesh_.vv_range(VH(b)))
      if (stamp_[x.idx()] == now_ && x.idx() != skip) out.push_back(x.idx());
    return out;
  }

 private:
  const PolyMesh& mesh_;
  std::vector<int> stamp_;
  int now_ = 0;
};

// One Catmull–Clark step of \p mesh, keeping track of the arcs' chains and of every new face's
// parent face. Old vertices keep their indices (CatmullClarkT only adds vertices), so the new
// vertex on old edge (a, b) is the only neighbour that a and b share afterwards, and the new
// vertex of an old face is the neighbour shared by the new vertices of two consecutive edges of
// that face other than their common corner. \p linear (one position per vertex) follows the
// step as a linear subdivision: edge points at edge midpoints, face points at face centroids.
void refine_once(PolyMesh& mesh, std::vector<int>& parent_of_face,
                 std::vector<std::vector<int>>& chains, std::vector<Vec3>& linear) {
  // Which steps of the chains are edges (the others are jumps, kept as they are).
  std::vector<std::vector<char>> chain_edges(chains.size());
  for (size_t c = 0; c < chains.size(); ++c) {
    for (size_t k = 0; k + 1 < chains[c].size(); ++k)
      chain_edges[c].push_back(
          mesh.find_halfedge(VH(chains[c][k]), VH(chains[c][k + 1])).is_valid());
  }
  std::vector<std::vector<int>> old_faces;
  old_faces.reserve(mesh.n_faces());
  for (const auto f : mesh.faces()) {
    std::vector<int> corners;
    for (const auto v : mesh.fv_range(f)) corners.push_back(v.idx());
    old_faces.push_back(std::move(corners));
  }
  OpenMesh::Subdivider::Uniform::CatmullClarkT<PolyMesh> subdivider;
  subdivider.attach(mesh);
  subdivider(1);
  subdivider.detach();

  CommonNeighbours common(mesh);
  auto edge_point = [&](int a, int b) {
    const std::vector<int> c = common.of(a, b);
    if (c.size() != 1) throw std::logic_error("Catmull-Clark: no unique edge point");
    return c[0];
  };
  std::vector<int> face_of_centre(mesh.n_vertices(), -1);
  linear.resize(mesh.n_vertices());
  for (size_t f = 0; f < old_faces.size(); ++f) {
    const auto& c = old_faces[f];
    const int e0 = edge_point(c[0], c[1]), e1 = edge_point(c[1], c[2]);
    const std::vector<int> centre = common.of(e0, e1, c[1]);
    if (centre.size() != 1) throw std::logic_error("Catmull-Clark: no unique face point");
    face_of_centre[centre[0]] = static_cast<int>(f);
    Vec3 sum(0, 0, 0);
    for (size_t k = 0; k < c.size(); ++k) {
      const int a = c[k], b = c[(k + 1) % c.size()];
      sum += linear[a];
      linear[edge_point(a, b)] = 0.5 * (linear[a] + linear[b]);
    }
    linear[centre[0]] = sum / static_cast<double>(c.size());
  }
  std::vector<int> parent(mesh.n_faces(), -1);
  for (const auto f : mesh.faces()) {
    for (const auto v : mesh.fv_range(f)) {
      if (face_of_centre[v.idx()] >= 0) parent[f.idx()] = parent_of_face[face_of_centre[v.idx()]];
    }
    if (parent[f.idx()] < 0) throw std::logic_error("Catmull-Clark: a face without parent");
  }
  parent_of_face = std::move(parent);
  for (size_t c = 0; c < chains.size(); ++c) {
    std::vector<int>& chain = chains[c];
    std::vector<int> fine{chain[0]};
    fine.reserve(2 * chain.size());
    for (size_t k = 0; k + 1 < chain.size(); ++k) {
      if (chain_edges[c][k]) fine.push_back(edge_point(chain[k], chain[k + 1]));
      fine.push_back(chain[k + 1]);
    }
    chain = std::move(fine);
  }
}

}  // namespace

DenseCage subdivide_cage(const PolyMesh& cage, const PolyMesh& quads, const QuadComplex& complex,
                         const DenseCageOptions& options) {
  DenseCage out;
  out.mesh = cage;
  out.linear.reserve(cage.n_vertices());
  for (const auto v : cage.vertices()) out.linear.push_back(cage.point(v));
  const bool ngons = !is_pure_quad(cage);
  std::vector<std::vector<int>> no_chains;
  if (ngons) {
    std::vector<int> parent(cage.n_faces());
    for (size_t f = 0; f < parent.size(); ++f) parent[f] = static_cast<int>(f);
    refine_once(out.mesh, parent, no_chains, out.linear);
    out.levels = 1;
  }
  // The quad structure must be the mesh reached so far: same vertex count, same edges.
  const PolyMesh& m = out.mesh;
  bool same = m.n_vertices() == quads.n_vertices() && m.n_edges() == quads.n_edges() &&
              m.n_faces() == quads.n_faces();
  for (const auto e : quads.edges()) {
    if (!same) break;
    const auto h = quads.halfedge_handle(e, 0);
    same = m.find_halfedge(quads.from_vertex_handle(h), quads.to_vertex_handle(h)).is_valid();
  }
  if (!same) {
    throw InvalidInputError(
        "the quad structure of the layout is neither the cage nor its split into quads");
  }
  // Faces of the quad structure by their corner sets.
  std::map<std::array<int, 4>, int> quad_by_corners;
  auto corner_key = [](const PolyMesh& mesh, OpenMesh::FaceHandle f) {
    std::array<int, 4> key{-1, -1, -1, -1};
    int k = 0;
    for (const auto v : mesh.fv_range(f))
      if (k < 4) key[k++] = v.idx();
    std::sort(key.begin(), key.end());
    return key;
  };
  for (const auto f : quads.faces()) quad_by_corners[corner_key(quads, f)] = f.idx();
  out.quad_of_face.resize(m.n_faces());
  for (const auto f : m.faces()) {
    const auto it = quad_by_corners.find(corner_key(m, f));
    if (it == quad_by_corners.end()) {
      throw InvalidInputError(
          "the quad structure of the layout is neither the cage nor its split into quads");
    }
    out.quad_of_face[f.idx()] = it->second;
  }
  const int nq = static_cast<int>(quads.n_vertices());
  out.quad_vertices = nq;
  for (size_t a = 0; a < complex.arcs.size(); ++a) {
    const auto& path = complex.arcs[a].path;
    bool valid = path.size() >= 2;
    for (int v : path) valid = valid && v >= 0 && v < nq;
    for (size_t k = 0; valid && k + 1 < path.size(); ++k) valid = path[k] != path[k + 1];
    if (!valid) {
      throw InvalidInputError("arc " + std::to_string(a) +
                              ": its path is not a chain of distinct quad-mesh vertices");
    }
    out.arc_chains.push_back(path);
  }
  while (options.max_mean_edge > 0 && mean_edge_length(out.mesh) > options.max_mean_edge &&
         4 * out.mesh.n_faces() <= options.max_faces) {
    refine_once(out.mesh, out.quad_of_face, out.arc_chains, out.linear);
    ++out.levels;
    ++out.levels_below_quads;
  }
  return out;
}

}  // namespace qs
