#include "core/import/quad_triangulation.h"

#include <string>

#include "core/base/errors.h"

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;
using VH = OpenMesh::VertexHandle;

// Index of the lattice point at parameter t (0..k) along halfedge h of the quad mesh.
int edge_lattice_vertex(const PolyMesh& quads, int k, HH h, int t) {
  if (t == 0) return quads.from_vertex_handle(h).idx();
  if (t == k) return quads.to_vertex_handle(h).idx();
  const auto e = quads.edge_handle(h);
  const int along = h == quads.halfedge_handle(e, 0) ? t : k - t;
  return static_cast<int>(quads.n_vertices()) + e.idx() * (k - 1) + (along - 1);
}

void require_pure_quad(const PolyMesh& quads) {
  for (const auto f : quads.faces()) {
    if (quads.valence(f) != 4) {
      throw InvalidInputError("face " + std::to_string(f.idx()) + " has " +
                              std::to_string(quads.valence(f)) + " vertices; expected quads only");
    }
  }
}

}  // namespace

TriMesh triangulate_quads(const PolyMesh& quads, int refine) {
  if (refine < 1) {
    throw InvalidInputError("refine must be at least 1 (got " + std::to_string(refine) + ")");
  }
  require_pure_quad(quads);
  const double triangles = 2.0 * refine * refine * static_cast<double>(quads.n_faces());
  if (triangles > static_cast<double>(kMaxTriangulatedFaces)) {
    throw InvalidInputError("refine " + std::to_string(refine) + " would split the " +
                            std::to_string(quads.n_faces()) + " quads into " +
                            std::to_string(static_cast<long long>(triangles)) +
                            " triangles, more than " + std::to_string(kMaxTriangulatedFaces) +
                            ": use a smaller refine");
  }
  const int k = refine;
  const int nqv = static_cast<int>(quads.n_vertices());
  const int ne = static_cast<int>(quads.n_edges());
  const int nf = static_cast<int>(quads.n_faces());
  TriMesh mesh;
  for (const auto v : quads.vertices()) mesh.add_vertex(quads.point(v));
  for (const auto e : quads.edges()) {
    const HH h = quads.halfedge_handle(e, 0);
    const Vec3 a = quads.point(quads.from_vertex_handle(h)),
               b = quads.point(quads.to_vertex_handle(h));
    for (int t = 1; t < k; ++t) mesh.add_vertex(a + (b - a) * (static_cast<double>(t) / k));
  }
  const int face_base = nqv + ne * (k - 1);
  std::vector<int> lattice((k + 1) * (k + 1));
  for (const auto f : quads.faces()) {
    HH h[4];
    h[0] = quads.halfedge_handle(f);
    for (int s = 1; s < 4; ++s) h[s] = quads.next_halfedge_handle(h[s - 1]);
    Vec3 c[4];
    for (int s = 0; s < 4; ++s) c[s] = quads.point(quads.from_vertex_handle(h[s]));
    // Local lattice (i, j): (0,0) = c0, (k,0) = c1, (k,k) = c2, (0,k) = c3; the four sides
    // are h0..h3 in order, so the cells keep the quad's orientation.
    auto at = [&](int i, int j) -> int& { return lattice[j * (k + 1) + i]; };
    for (int t = 0; t <= k; ++t) {
      at(t, 0) = edge_lattice_vertex(quads, k, h[0], t);
      at(k, t) = edge_lattice_vertex(quads, k, h[1], t);
      at(k - t, k) = edge_lattice_vertex(quads, k, h[2], t);
      at(0, k - t) = edge_lattice_vertex(quads, k, h[3], t);
    }
    for (int j = 1; j < k; ++j) {
      for (int i = 1; i < k; ++i) {
        const double s = static_cast<double>(i) / k, r = static_cast<double>(j) / k;
        const Vec3 p =
            (1 - s) * (1 - r) * c[0] + s * (1 - r) * c[1] + s * r * c[2] + (1 - s) * r * c[3];
        const int id = face_base + f.idx() * (k - 1) * (k - 1) + (j - 1) * (k - 1) + (i - 1);
        mesh.add_vertex(p);
        at(i, j) = id;
      }
    }
    for (int j = 0; j < k; ++j) {
      for (int i = 0; i < k; ++i) {
        const VH a(at(i, j)), b(at(i + 1, j)), cc(at(i + 1, j + 1)), d(at(i, j + 1));
        const double ac = (mesh.point(a) - mesh.point(cc)).sqrnorm();
        const double bd = (mesh.point(b) - mesh.point(d)).sqrnorm();
        if (ac <= bd) {
          mesh.add_face(a, b, cc);
          mesh.add_face(a, cc, d);
        } else {
          mesh.add_face(a, b, d);
          mesh.add_face(b, cc, d);
        }
      }
    }
  }
  if (static_cast<int>(mesh.n_faces()) != 2 * k * k * nf) {
    throw InvalidInputError("the quad mesh could not be triangulated: " +
                            std::to_string(2 * k * k * nf - static_cast<int>(mesh.n_faces())) +
                            " triangles were refused (non-manifold or inconsistently oriented "
                            "quads)");
  }
  return mesh;
}

std::vector<int> refine_quad_path(const PolyMesh& quads, int refine, const std::vector<int>& path) {
  std::vector<int> out;
  if (path.empty()) return out;
  out.push_back(path[0]);
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const HH h = quads.find_halfedge(VH(path[i]), VH(path[i + 1]));
    for (int t = 1; t <= refine; ++t) out.push_back(edge_lattice_vertex(quads, refine, h, t));
  }
  return out;
}

Layout layout_on_triangulation(const PolyMesh& quads, const QuadComplex& complex, int refine) {
  Layout layout;
  for (size_t n = 0; n < complex.node_vertex.size(); ++n) {
    LayoutNode node;
    node.id = static_cast<int>(n);
    node.vertex = complex.node_vertex[n];
    layout.nodes.push_back(node);
  }
  for (size_t a = 0; a < complex.arcs.size(); ++a) {
    LayoutArc arc;
    arc.id = static_cast<int>(a);
    arc.from = complex.arcs[a].from;
    arc.to = complex.arcs[a].to;
    arc.path = refine_quad_path(quads, refine, complex.arcs[a].path);
    layout.arcs.push_back(std::move(arc));
  }
  return layout;
}

}  // namespace qs
