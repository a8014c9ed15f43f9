#include "core/mesh/mesh_checks.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <deque>
#include <limits>
#include <numeric>
#include <span>
#include <utility>

#include "core/mesh/triangulate.h"

namespace qs {
namespace {

// A face is degenerate when area <= kZeroAreaFactor * (bounding box diagonal)^2. The factor
// is far below any real sliver (the smallest area / diagonal^2 among the shared meshes is
// 7e-9 in bunny.off, 1e-7 in block.off) and above the rounding noise of exactly collinear
// corners (up to ~1e-15 when the corners are rounded onto a line).
constexpr double kZeroAreaFactor = 1e-14;

bool is_finite(const Vec3& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// Finite, and small enough for squared lengths and areas to stay finite.
bool in_range(const Vec3& p) {
  return is_finite(p) && std::abs(p[0]) <= kMaxCoordinateMagnitude &&
         std::abs(p[1]) <= kMaxCoordinateMagnitude && std::abs(p[2]) <= kMaxCoordinateMagnitude;
}

// Diagonal of the bounding box of the in-range points (0 when there are none).
double bbox_diagonal(const std::vector<Vec3>& points) {
  constexpr double kBig = std::numeric_limits<double>::max();
  Vec3 lo(kBig, kBig, kBig);
  Vec3 hi(-kBig, -kBig, -kBig);
  bool any = false;
  for (const Vec3& p : points) {
    if (!in_range(p)) continue;
    lo.minimize(p);
    hi.maximize(p);
    any = true;
  }
  return any ? (hi - lo).norm() : 0.0;
}

// Area of a polygon from its vector area (Newell), so that the same rule covers triangles and
// the polygons of quad meshes.
double polygon_area(std::span<const int> face, const std::vector<Vec3>& points) {
  return polygon_vector_area(face, points).norm();
}

class UnionFind {
 public:
  explicit UnionFind(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  int find(int x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];  // path halving keeps the trees flat
      x = parent_[x];
    }
    return x;
  }
  void unite(int a, int b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<int> parent_;
};

// Faces stored back to back, to avoid one allocation per face on large meshes.
struct FlatFaces {
  std::vector<int> vertices;
  std::vector<std::size_t> offsets{0};

  void push(const int* face, std::size_t n) {
    vertices.insert(vertices.end(), face, face + n);
    offsets.push_back(vertices.size());
  }
  std::size_t size() const { return offsets.size() - 1; }
};

// Vertices whose link (the opposite edges of their face wedges) is not a single path or
// cycle, i.e. whose faces do not form one fan. This looks at the soup itself, so it does not
// depend on the order in which OpenMesh accepted or refused faces: two fans touching at a
// vertex are caught whether add_face accepted them (two boundary gaps) or refused the last
// face. Endpoints of an edge with three faces have a link vertex of degree 3.
std::vector<int> link_nonmanifold_vertices(int n_vertices, const FlatFaces& faces) {
  std::vector<int> start(n_vertices + 1, 0);
  for (int v : faces.vertices) ++start[v + 1];
  std::partial_sum(start.begin(), start.end(), start.begin());
  std::vector<std::pair<int, int>> link(start[n_vertices]);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const int* face = faces.vertices.data() + faces.offsets[f];
    const std::size_t n = faces.offsets[f + 1] - faces.offsets[f];
    for (std::size_t i = 0; i < n; ++i) {
      link[fill[face[i]]++] = std::minmax(face[(i + n - 1) % n], face[(i + 1) % n]);
    }
  }

  std::vector<int> result;
  std::vector<std::pair<int, int>> edges;
  std::vector<int> nodes;
  std::vector<int> degree;
  for (int v = 0; v < n_vertices; ++v) {
    if (start[v] == start[v + 1]) continue;
    edges.assign(link.begin() + start[v], link.begin() + start[v + 1]);
    std::sort(edges.begin(), edges.end());
    // Two faces sharing both edges at v (a valence-2 vertex of a polygon mesh) is a closed
    // fan; any other repeated wedge means stacked faces.
    const bool two_cycle = edges.size() == 2 && edges[0] == edges[1];
    const bool repeated = std::adjacent_find(edges.begin(), edges.end()) != edges.end();
    if (repeated && !two_cycle) {
      result.push_back(v);
      continue;
    }
    nodes.clear();
    for (const auto& [a, b] : edges) {
      nodes.push_back(a);
      nodes.push_back(b);
    }
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    const auto local = [&](int x) {
      return static_cast<int>(std::lower_bound(nodes.begin(), nodes.end(), x) - nodes.begin());
    };
    degree.assign(nodes.size(), 0);
    UnionFind uf(nodes.size());
    bool fan = true;
    for (const auto& [a, b] : edges) {
      const int la = local(a);
      const int lb = local(b);
      if (++degree[la] > 2 || ++degree[lb] > 2) fan = false;
      uf.unite(la, lb);
    }
    for (std::size_t i = 1; fan && i < nodes.size(); ++i) {
      if (uf.find(static_cast<int>(i)) != 0) fan = false;
    }
    if (!fan) result.push_back(v);
  }
  return result;
}

// True when a face already in the mesh has the same vertex cycle, in either direction. A
// same-direction copy would be refused by add_face, but a reversed copy of a face whose edges
// are all on the boundary would be accepted and glue a two-sided flap onto the surface.
template <typename MeshT>
bool is_duplicate(const MeshT& mesh, const std::vector<OpenMesh::VertexHandle>& vhs) {
  const std::size_t n = vhs.size();
  for (const bool reversed : {false, true}) {
    OpenMesh::FaceHandle common;
    bool same = true;
    for (std::size_t i = 0; i < n && same; ++i) {
      const auto a = vhs[i];
      const auto b = vhs[(i + 1) % n];
      const auto heh = reversed ? mesh.find_halfedge(b, a) : mesh.find_halfedge(a, b);
      const auto fh = heh.is_valid() ? mesh.face_handle(heh) : OpenMesh::FaceHandle();
      same = fh.is_valid() && (i == 0 || fh == common);
      common = fh;
    }
    if (same && mesh.valence(common) == n) return true;
  }
  return false;
}

// Repeated vertex index inside one face (no halfedge mesh can hold such a face).
bool has_repeated_vertex(const std::vector<int>& face) {
  for (std::size_t i = 0; i < face.size(); ++i) {
    for (std::size_t j = i + 1; j < face.size(); ++j) {
      if (face[i] == face[j]) return true;
    }
  }
  return false;
}

// Why OpenMesh refused a face: looks at the halfedges the face would use.
template <typename MeshT>
DropReason classify_refused_face(const MeshT& mesh,
                                 const std::vector<OpenMesh::VertexHandle>& vhs) {
  bool same_direction = false;
  for (std::size_t i = 0; i < vhs.size(); ++i) {
    const auto heh = mesh.find_halfedge(vhs[i], vhs[(i + 1) % vhs.size()]);
    if (!heh.is_valid() || mesh.is_boundary(heh)) continue;
    if (!mesh.is_boundary(mesh.opposite_halfedge_handle(heh))) {
      return DropReason::kNonManifoldEdge;  // the edge already has its two faces
    }
    same_direction = true;
  }
  return same_direction ? DropReason::kInconsistentOrientation : DropReason::kNonManifoldVertex;
}

// Shared by the triangle and polygon builders; \p split_polygons selects TriMesh behaviour.
template <typename MeshT>
MeshT build_mesh(const PolygonSoup& soup, MeshReport& report, bool split_polygons,
                 const LoadMeshOptions& options) {
  MeshT mesh;
  const int n_vertices = static_cast<int>(soup.points.size());
  const int n_faces = static_cast<int>(soup.faces.size());
  report.input_faces = n_faces;
  report.multiple_components_allowed = options.allow_multiple_components;
  report.skipped_degenerate_faces = soup.skipped_degenerate_faces;
  report.face_lines = soup.face_lines;
  report.face_lines.resize(n_faces, 0);
  report.vertex_lines = soup.point_lines;
  report.vertex_lines.resize(n_vertices, 0);
  report.warnings.insert(report.warnings.end(), soup.warnings.begin(), soup.warnings.end());

  // All vertices first and in file order, so that TriMesh indices are the file's indices.
  mesh.reserve(n_vertices, 3 * n_faces, 2 * n_faces);
  // Geometry is only judged on faces whose corners are all in range (usable[v]); the others
  // are reported through their vertices.
  std::vector<char> usable(n_vertices, 1);
  for (int v = 0; v < n_vertices; ++v) {
    mesh.add_vertex(soup.points[v]);
    if (!is_finite(soup.points[v])) {
      report.nonfinite_vertices.push_back(v);
      usable[v] = 0;
    } else if (!in_range(soup.points[v])) {
      report.out_of_range_vertices.push_back(v);
      usable[v] = 0;
    }
  }
  const double diagonal = bbox_diagonal(soup.points);
  const double min_area = kZeroAreaFactor * diagonal * diagonal;

  std::vector<char> referenced(n_vertices, 0);
  FlatFaces added;  // faces given to add_face, for the link check
  added.vertices.reserve(3 * n_faces);
  added.offsets.reserve(n_faces + 1);
  std::vector<OpenMesh::VertexHandle> vhs;
  std::vector<std::array<int, 3>> triangles;
  const auto drop = [&](int f, DropReason reason) {
    if (!report.dropped_faces.empty() && report.dropped_faces.back() == f) return;
    report.dropped_faces.push_back(f);
    report.drop_reasons.push_back(reason);
  };
  const auto add = [&](int f, const int* face, std::size_t n) {
    vhs.clear();
    for (std::size_t i = 0; i < n; ++i) vhs.push_back(OpenMesh::VertexHandle(face[i]));
    if (is_duplicate(mesh, vhs)) {
      drop(f, DropReason::kDuplicate);  // kept out of the link check: it would double a fan
      return;
    }
    added.push(face, n);
    if (!mesh.add_face(vhs).is_valid()) drop(f, classify_refused_face(mesh, vhs));
  };

  for (int f = 0; f < n_faces; ++f) {
    const std::vector<int>& face = soup.faces[f];
    bool bad_index = false;
    for (int v : face) {
      if (v < 0 || v >= n_vertices) {
        bad_index = true;
      } else {
        referenced[v] = 1;
      }
    }
    if (bad_index) {
      report.bad_index_faces.push_back(f);
      continue;
    }
    if (face.size() < 3 || has_repeated_vertex(face)) {
      report.degenerate_faces.push_back(f);
      continue;
    }
    // Zero-area faces are still added: the topology checks stay meaningful around them.
    const bool judged = std::all_of(face.begin(), face.end(), [&](int v) { return usable[v]; });
    const bool zero_area = judged && polygon_area(face, soup.points) <= min_area;
    if (split_polygons && face.size() > 3) {
      if (!options.triangulate) {
        report.non_triangle_faces.push_back(f);
        continue;
      }
      ++report.triangulated_faces;
      triangles.clear();
      if (judged && !zero_area) {
        triangles = triangulate_polygon(face, soup.points);
        if (triangles.empty()) report.untriangulable_faces.push_back(f);
      }
      if (triangles.empty()) {  // a fan from the first corner, for the topology checks only
        for (std::size_t i = 1; i + 1 < face.size(); ++i) {
          triangles.push_back({face[0], face[i], face[i + 1]});
        }
      }
      bool degenerate = zero_area;
      for (const auto& t : triangles) {
        degenerate = degenerate || (judged && polygon_area(t, soup.points) <= min_area);
      }
      if (degenerate) report.degenerate_faces.push_back(f);
      for (const auto& t : triangles) add(f, t.data(), 3);
    } else {
      if (zero_area) report.degenerate_faces.push_back(f);
      add(f, face.data(), face.size());
    }
  }

  for (int v = 0; v < n_vertices; ++v) {
    if (!referenced[v]) report.unreferenced_vertices.push_back(v);
  }
  std::vector<int> nonmanifold = link_nonmanifold_vertices(n_vertices, added);
  // OpenMesh's own view (several boundary gaps at a vertex) as a safety net.
  for (auto vh : mesh.vertices()) {
    if (!mesh.is_manifold(vh)) nonmanifold.push_back(vh.idx());
  }
  std::sort(nonmanifold.begin(), nonmanifold.end());
  nonmanifold.erase(std::unique(nonmanifold.begin(), nonmanifold.end()), nonmanifold.end());
  report.nonmanifold_vertices = std::move(nonmanifold);

  if (report.triangulated_faces > 0) {
    const int n = report.triangulated_faces;
    report.warnings.push_back(std::to_string(n) + (n == 1 ? " face" : " faces") +
                              " with more than 3 vertices " + (n == 1 ? "was" : "were") +
                              " triangulated");
  }
  count_topology(mesh, report);
  return mesh;
}

// Component id per face (vertex-connected, numbered in order of first face) and their count.
template <typename MeshT>
std::vector<int> components_of_faces(const MeshT& mesh, int* count) {
  UnionFind uf(mesh.n_vertices());
  for (auto fh : mesh.faces()) {
    const int first = mesh.cfv_begin(fh)->idx();
    for (auto vh : mesh.fv_range(fh)) uf.unite(first, vh.idx());
  }
  std::vector<int> label(mesh.n_vertices(), -1);
  std::vector<int> ids;
  ids.reserve(mesh.n_faces());
  int next = 0;
  for (auto fh : mesh.faces()) {
    int& l = label[uf.find(mesh.cfv_begin(fh)->idx())];
    if (l < 0) l = next++;
    ids.push_back(l);
  }
  if (count) *count = next;
  return ids;
}

// Boundary halfedges (those without a face) grouped into their cycles.
template <typename MeshT>
std::vector<std::vector<OpenMesh::HalfedgeHandle>> boundary_cycles(const MeshT& mesh) {
  std::vector<std::vector<OpenMesh::HalfedgeHandle>> cycles;
  std::vector<char> visited(mesh.n_halfedges(), 0);
  for (auto start : mesh.halfedges()) {
    if (!mesh.is_boundary(start) || visited[start.idx()]) continue;
    std::vector<OpenMesh::HalfedgeHandle> cycle;
    OpenMesh::HalfedgeHandle h = start;
    // The step bound guards against corrupt next pointers; a valid cycle returns to start.
    for (std::size_t steps = 0; steps < mesh.n_halfedges() && !visited[h.idx()]; ++steps) {
      visited[h.idx()] = 1;
      cycle.push_back(h);
      h = mesh.next_halfedge_handle(h);
    }
    cycles.push_back(std::move(cycle));
  }
  return cycles;
}

}  // namespace

TriMesh build_tri_mesh(const PolygonSoup& soup, MeshReport& report,
                       const LoadMeshOptions& options) {
  return build_mesh<TriMesh>(soup, report, true, options);
}

PolyMesh build_poly_mesh(const PolygonSoup& soup, MeshReport& report) {
  // Polygon meshes are imported as they are; multiple components are judged like triangles.
  return build_mesh<PolyMesh>(soup, report, false, LoadMeshOptions{});
}

template <typename MeshT>
void count_topology(const MeshT& mesh, MeshReport& report) {
  report.vertices = static_cast<int>(mesh.n_vertices());
  report.faces = static_cast<int>(mesh.n_faces());
  report.edges = static_cast<int>(mesh.n_edges());
  components_of_faces(mesh, &report.components);
  report.boundary_loops = static_cast<int>(boundary_cycles(mesh).size());
  // Isolated vertices are reported as unreferenced; counting them here would also shift the
  // genus, so chi only counts vertices that belong to a face.
  int used_vertices = 0;
  for (auto vh : mesh.vertices()) {
    if (!mesh.is_isolated(vh)) ++used_vertices;
  }
  report.euler_characteristic = used_vertices - report.edges + report.faces;
  // Sum over components of (2 - b_i - chi_i) / 2; for one component V - E + F = 2 - 2g - b.
  report.genus = (2 * report.components - report.boundary_loops - report.euler_characteristic) / 2;
}

template void count_topology<TriMesh>(const TriMesh&, MeshReport&);
template void count_topology<PolyMesh>(const PolyMesh&, MeshReport&);

std::vector<std::vector<int>> boundary_loops(const TriMesh& mesh) {
  std::vector<std::vector<int>> loops;
  for (const auto& cycle : boundary_cycles(mesh)) {
    // Boundary halfedge h runs v_i -> v_(i+1); its face-side twin runs back, so walking the
    // interior halfedges visits the cycle's from-vertices in reverse order.
    std::vector<int> loop;
    loop.reserve(cycle.size());
    for (auto it = cycle.rbegin(); it != cycle.rend(); ++it) {
      loop.push_back(mesh.to_vertex_handle(*it).idx());
    }
    std::rotate(loop.begin(), std::min_element(loop.begin(), loop.end()), loop.end());
    loops.push_back(std::move(loop));
  }
  std::sort(loops.begin(), loops.end());
  return loops;
}

std::vector<int> face_components(const TriMesh& mesh, int* count) {
  return components_of_faces(mesh, count);
}

std::vector<char> dual_spanning_tree(const TriMesh& mesh,
                                     const std::function<bool(int)>& crossable) {
  const int nf = static_cast<int>(mesh.n_faces());
  std::vector<char> seen(nf, 0), tree(mesh.n_edges(), 0);
  for (int root = 0; root < nf; ++root) {
    if (seen[root]) continue;
    seen[root] = 1;
    std::deque<int> queue{root};
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      for (auto h : mesh.fh_range(mesh.face_handle(f))) {
        const int e = mesh.edge_handle(h).idx();
        const auto opp = mesh.opposite_halfedge_handle(h);
        if (mesh.is_boundary(opp) || !crossable(e)) continue;
        const int f2 = mesh.face_handle(opp).idx();
        if (seen[f2]) continue;
        seen[f2] = 1;
        tree[e] = 1;
        queue.push_back(f2);
      }
    }
  }
  return tree;
}

}  // namespace qs
