#include "tests/fixtures.h"

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <queue>
#include <set>
#include <stdexcept>

#include "core/field/cross_field.h"
#include "core/import/perturb.h"
#include "core/import/quad_import.h"
#include "core/layout/layout_io.h"
#include "core/layout/routing.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/relocation.h"

namespace qs::test {

std::string shared_meshes_dir() {
  const std::filesystem::path p = std::filesystem::path(QS_SHARED_DIR) / "data" / "meshes";
  return std::filesystem::is_directory(p) ? p.string() : std::string();
}

CageOptions fertility_cage_options() {
  CageOptions options;
  options.resolution = 30;
  options.shift = 0.5;
  options.attempts = 1;
  options.subsamples = 4;
  options.coarsen = 10;
  options.max_refine = 2;
  return options;
}

CageOptions fertility_simplified_cage_options() {
  CageOptions options = fertility_cage_options();
  options.resolution = 34;
  options.shift = 0;
  options.simplify = true;
  return options;
}

std::string assets_dir() {
  return QS_ASSETS_DIR;
}

std::string cli_path() {
  return QS_CLI_PATH;
}

std::string temp_dir(const std::string& name) {
  // One folder per test process: CTest runs tests in parallel processes, and a shared fixed
  // path would let one test wipe another's files.
  const auto dir =
      std::filesystem::temp_directory_path() / ("qs_test_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

int run_command(const std::string& command, std::string* output) {
  const std::string full = command + " 2>&1";
  FILE* pipe = popen(full.c_str(), "r");
  if (!pipe) return -1;
  std::array<char, 4096> buffer{};
  std::string text;
  size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) text.append(buffer.data(), n);
  const int status = pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

namespace {

// Adds the two triangles of quad (a,b,c,d) (ccw), alternating the diagonal with `flip`.
void add_quad(TriMesh& mesh, int a, int b, int c, int d, bool flip) {
  auto vh = [&](int i) { return mesh.vertex_handle(i); };
  if (flip) {
    mesh.add_face(vh(a), vh(b), vh(d));
    mesh.add_face(vh(b), vh(c), vh(d));
  } else {
    mesh.add_face(vh(a), vh(b), vh(c));
    mesh.add_face(vh(a), vh(c), vh(d));
  }
}

}  // namespace

LayoutNode make_node(int id, int vertex) {
  LayoutNode n;
  n.id = id;
  n.vertex = vertex;
  return n;
}

LayoutArc make_arc(int id, int from, int to, std::vector<int> path) {
  LayoutArc a;
  a.id = id;
  a.from = from;
  a.to = to;
  a.path = std::move(path);
  return a;
}

MeshAndLayout bumpy_rounded_cube() {
  MeshAndLayout ex = cube_sphere(24, Vec3(1, 1, 1), /*project=*/false);
  for (const auto vh : ex.mesh.vertices()) {
    const Vec3 p = ex.mesh.point(vh);
    Vec3 q = p;
    q.normalize();
    const double bump = 0.015 * std::sin(23.0 * p[0] + 1.0) * std::sin(19.0 * p[1] + 2.0) *
                        std::sin(17.0 * p[2] + 3.0);
    ex.mesh.set_point(vh, (0.3 * p + 0.7 * std::sqrt(3.0) * q) * (1.0 + bump));
  }
  return ex;
}

MeshAndLayout cube_sphere(int k, Vec3 radii, bool project) {
  MeshAndLayout out;
  TriMesh& mesh = out.mesh;
  std::map<std::array<int, 3>, int> index;
  auto vertex = [&](std::array<int, 3> ijk) {
    auto it = index.find(ijk);
    if (it != index.end()) return it->second;
    Vec3 p(2.0 * ijk[0] / k - 1.0, 2.0 * ijk[1] / k - 1.0, 2.0 * ijk[2] / k - 1.0);
    if (project) {
      p.normalize();
      p = Vec3(p[0] * radii[0], p[1] * radii[1], p[2] * radii[2]);
    }
    const int id = mesh.add_vertex(p).idx();
    index.emplace(ijk, id);
    return id;
  };
  for (int a = 0; a < 3; ++a) {
    for (int s = 0; s <= k; s += k) {
      // Axes (b, c) with e_b × e_c pointing outwards.
      int b = (a + 1) % 3, c = (a + 2) % 3;
      if (s == 0) std::swap(b, c);
      for (int u = 0; u < k; ++u) {
        for (int w = 0; w < k; ++w) {
          auto at = [&](int du, int dw) {
            std::array<int, 3> ijk{};
            ijk[a] = s;
            ijk[b] = u + du;
            ijk[c] = w + dw;
            return vertex(ijk);
          };
          add_quad(mesh, at(0, 0), at(1, 0), at(1, 1), at(0, 1), (u + w) % 2 == 1);
        }
      }
    }
  }
  // Nodes at the 8 corners; arcs along the 12 cube edges.
  std::map<std::array<int, 3>, int> node_of;
  for (int x = 0; x <= k; x += k)
    for (int y = 0; y <= k; y += k)
      for (int z = 0; z <= k; z += k) {
        const int id = static_cast<int>(out.layout.nodes.size());
        out.layout.nodes.push_back(make_node(id, vertex({x, y, z})));
        node_of[{x, y, z}] = id;
      }
  for (const auto& [corner, id] : node_of) {
    for (int axis = 0; axis < 3; ++axis) {
      if (corner[axis] != 0) continue;
      std::vector<int> path;
      std::array<int, 3> p = corner;
      for (int t = 0; t <= k; ++t) {
        p[axis] = t;
        path.push_back(vertex(p));
      }
      const int to = node_of.at(p);
      const int arc_id = static_cast<int>(out.layout.arcs.size());
      out.layout.arcs.push_back(make_arc(arc_id, id, to, std::move(path)));
    }
  }
  return out;
}

TriMesh icosphere(int subdivisions, Vec3 radii) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  std::vector<Vec3> points = {Vec3(-1, t, 0), Vec3(1, t, 0), Vec3(-1, -t, 0), Vec3(1, -t, 0),
                              Vec3(0, -1, t), Vec3(0, 1, t), Vec3(0, -1, -t), Vec3(0, 1, -t),
                              Vec3(t, 0, -1), Vec3(t, 0, 1), Vec3(-t, 0, -1), Vec3(-t, 0, 1)};
  for (auto& p : points) p.normalize();
  std::vector<std::array<int, 3>> faces = {
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      points.push_back((points[a] + points[b]).normalized());
      return midpoint[key] = static_cast<int>(points.size()) - 1;
    };
    std::vector<std::array<int, 3>> finer;
    for (const auto& f : faces) {
      const int a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      finer.insert(finer.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
    }
    faces = std::move(finer);
  }
  TriMesh mesh;
  for (const auto& p : points)
    mesh.add_vertex(Vec3(p[0] * radii[0], p[1] * radii[1], p[2] * radii[2]));
  for (const auto& f : faces)
    mesh.add_face(mesh.vertex_handle(f[0]), mesh.vertex_handle(f[1]), mesh.vertex_handle(f[2]));
  return mesh;
}

Layout transfer_layout(const MeshAndLayout& source, const TriMesh& target) {
  auto nearest = [&](int source_vertex) {
    const Vec3 q = source.mesh.point(source.mesh.vertex_handle(source_vertex));
    int best = -1;
    double best_d = 0;
    for (auto v : target.vertices()) {
      const double d = (target.point(v) - q).sqrnorm();
      if (best < 0 || d < best_d) {
        best = v.idx();
        best_d = d;
      }
    }
    return best;
  };
  Layout out = source.layout;
  for (auto& n : out.nodes) n.vertex = nearest(n.vertex);
  for (auto& arc : out.arcs) {
    const std::vector<int> path = std::move(arc.path);
    arc.path.clear();
    arc.points.clear();
    int last = -1;
    for (size_t i = 2; i + 2 < path.size(); i += 2) {
      const int w = nearest(path[i]);
      if (w == last) continue;
      last = w;
      // The point at vertex w: barycentric 1 at w's corner of one incident face.
      const auto fh = *target.vf_range(target.vertex_handle(w)).begin();
      SurfacePoint sp;
      sp.face = fh.idx();
      int corner = 0;
      for (auto vh : target.fv_range(fh)) sp.bary[corner++] = vh.idx() == w ? 1.0 : 0.0;
      arc.points.push_back(sp);
    }
  }
  route_layout(target, out);
  require_valid_layout(target, out, "the transferred layout");
  return out;
}

MeshAndLayout torus_grid(int nu, int nv, int pu, int pv, double R, double r) {
  MeshAndLayout out;
  TriMesh& mesh = out.mesh;
  auto id = [&](int i, int j) { return ((i % nu + nu) % nu) * nv + ((j % nv + nv) % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const double t = 2 * M_PI * i / nu, f = 2 * M_PI * j / nv;
      mesh.add_vertex(Vec3((R + r * std::cos(f)) * std::cos(t), (R + r * std::cos(f)) * std::sin(t),
                           r * std::sin(f)));
    }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      add_quad(mesh, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1), (i + j) % 2 == 1);
  const int su = nu / pu, sv = nv / pv;
  std::map<int, int> node_of;
  for (int a = 0; a < pu; ++a)
    for (int b = 0; b < pv; ++b) {
      const int nid = static_cast<int>(out.layout.nodes.size());
      out.layout.nodes.push_back(make_node(nid, id(a * su, b * sv)));
      node_of[id(a * su, b * sv)] = nid;
    }
  for (int a = 0; a < pu; ++a)
    for (int b = 0; b < pv; ++b) {
      const int i0 = a * su, j0 = b * sv;
      std::vector<int> pu_path, pv_path;
      for (int t = 0; t <= su; ++t) pu_path.push_back(id(i0 + t, j0));
      for (int t = 0; t <= sv; ++t) pv_path.push_back(id(i0, j0 + t));
      const int from = node_of.at(id(i0, j0));
      out.layout.arcs.push_back(make_arc(static_cast<int>(out.layout.arcs.size()), from,
                                         node_of.at(pu_path.back()), pu_path));
      out.layout.arcs.push_back(make_arc(static_cast<int>(out.layout.arcs.size()), from,
                                         node_of.at(pv_path.back()), pv_path));
    }
  return out;
}

MeshAndLayout disk_grid(int nx, int ny, int px, int py) {
  MeshAndLayout out;
  TriMesh& mesh = out.mesh;
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh.add_vertex(Vec3(i, j, 0));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      add_quad(mesh, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1), (i + j) % 2 == 1);
  const int sx = nx / px, sy = ny / py;
  std::map<int, int> node_of;
  for (int b = 0; b <= py; ++b)
    for (int a = 0; a <= px; ++a) {
      const int nid = static_cast<int>(out.layout.nodes.size());
      out.layout.nodes.push_back(make_node(nid, id(a * sx, b * sy)));
      node_of[id(a * sx, b * sy)] = nid;
    }
  for (int b = 0; b <= py; ++b)
    for (int a = 0; a <= px; ++a) {
      const int i0 = a * sx, j0 = b * sy;
      if (a < px) {
        std::vector<int> path;
        for (int t = 0; t <= sx; ++t) path.push_back(id(i0 + t, j0));
        out.layout.arcs.push_back(make_arc(static_cast<int>(out.layout.arcs.size()),
                                           node_of.at(path.front()), node_of.at(path.back()),
                                           path));
      }
      if (b < py) {
        std::vector<int> path;
        for (int t = 0; t <= sy; ++t) path.push_back(id(i0, j0 + t));
        out.layout.arcs.push_back(make_arc(static_cast<int>(out.layout.arcs.size()),
                                           node_of.at(path.front()), node_of.at(path.back()),
                                           path));
      }
    }
  return out;
}

MeshAndLayout flat_square_with_free_hole() {
  const int n = 12;
  MeshAndLayout out;
  TriMesh& mesh = out.mesh;
  auto id = [&](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.add_vertex(Vec3(i, j, 0));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (i >= 6 && i < 9 && j >= 5 && j < 8) continue;  // the hole: 3 × 3 quads
      add_quad(mesh, id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1), false);
    }
  auto line = [&](int i0, int j0, int i1, int j1) {
    std::vector<int> path;
    const int steps = std::max(std::abs(i1 - i0), std::abs(j1 - j0));
    for (int t = 0; t <= steps; ++t)
      path.push_back(id(i0 + (i1 - i0) * t / steps, j0 + (j1 - j0) * t / steps));
    return path;
  };
  out.layout.nodes.push_back(make_node(0, id(3, 6)));
  out.layout.arcs.push_back(make_arc(0, 0, -1, line(3, 6, 6, 6)));   // into the hole
  out.layout.arcs.push_back(make_arc(1, 0, -1, line(3, 6, 3, 12)));  // up to the outer boundary
  out.layout.arcs.push_back(make_arc(2, 0, -1, line(3, 6, 0, 6)));   // left
  out.layout.arcs.push_back(make_arc(3, 0, -1, line(3, 6, 3, 0)));   // down
  return out;
}

MeshAndLayout voxel_surface(const std::vector<std::array<int, 3>>& voxels, int k) {
  MeshAndLayout out;
  TriMesh& mesh = out.mesh;
  std::set<std::array<int, 3>> filled(voxels.begin(), voxels.end());
  std::map<std::array<int, 3>, int> index;  // lattice point (scaled by k) -> vertex
  auto vertex = [&](const std::array<int, 3>& q) {
    auto it = index.find(q);
    if (it != index.end()) return it->second;
    const int id =
        mesh.add_vertex(Vec3(double(q[0]) / k, double(q[1]) / k, double(q[2]) / k)).idx();
    index.emplace(q, id);
    return id;
  };
  // Boundary faces: a voxel side whose neighbour is empty.
  for (const auto& c : voxels) {
    for (int a = 0; a < 3; ++a) {
      for (int s : {-1, 1}) {
        std::array<int, 3> nb = c;
        nb[a] += s;
        if (filled.count(nb)) continue;
        int b = (a + 1) % 3, cc = (a + 2) % 3;
        if (s < 0) std::swap(b, cc);  // e_b × e_c points outwards
        for (int u = 0; u < k; ++u)
          for (int w = 0; w < k; ++w) {
            auto at = [&](int du, int dw) {
              std::array<int, 3> q{c[0] * k, c[1] * k, c[2] * k};
              q[a] += (s > 0 ? k : 0);
              q[b] += u + du;
              q[cc] += w + dw;
              return vertex(q);
            };
            add_quad(mesh, at(0, 0), at(1, 0), at(1, 1), at(0, 1), (u + w) % 2 == 1);
          }
      }
    }
  }
  // Nodes: lattice points on the surface; arcs: voxel edges on the surface.
  std::map<std::array<int, 3>, int> node_of;
  for (const auto& [q, v] : index) {
    if (q[0] % k || q[1] % k || q[2] % k) continue;
    const int id = static_cast<int>(out.layout.nodes.size());
    out.layout.nodes.push_back(make_node(id, v));
    node_of[q] = id;
  }
  for (const auto& [q, id] : node_of) {
    for (int axis = 0; axis < 3; ++axis) {
      std::array<int, 3> end = q;
      end[axis] += k;
      if (!node_of.count(end)) continue;
      std::vector<int> path;
      bool on_surface = true;
      for (int t = 0; t <= k && on_surface; ++t) {
        std::array<int, 3> p = q;
        p[axis] += t;
        auto it = index.find(p);
        if (it == index.end())
          on_surface = false;
        else
          path.push_back(it->second);
      }
      if (!on_surface) continue;
      // The lattice edge must be a mesh edge chain (it is unless it cuts through a face).
      bool chain = true;
      for (size_t i = 0; i + 1 < path.size(); ++i)
        chain &= mesh.find_halfedge(mesh.vertex_handle(path[i]), mesh.vertex_handle(path[i + 1]))
                     .is_valid();
      // Edges inside a flat face region (both sides coplanar) are lattice lines too: keep them,
      // they separate voxel faces.
      if (!chain) continue;
      out.layout.arcs.push_back(
          make_arc(static_cast<int>(out.layout.arcs.size()), id, node_of.at(end), path));
    }
  }
  return out;
}

MeshAndLayout crowded_refined_cube() {
  QuadImportOptions io;
  io.refine = 2;
  QuadImportResult cube = import_quads(quad_cube(2), nullptr, io);
  for (unsigned seed = 1; seed < 40; ++seed) {
    PerturbLayoutOptions po;
    po.rings = 2;
    po.seed = seed;
    Layout crowded = perturb_layout(cube.mesh, cube.layout, po).layout;
    if (separate_nodes(cube.mesh, crowded, {}).moved_nodes.size() >= 2)
      return {std::move(cube.mesh), std::move(crowded)};
  }
  throw std::runtime_error("crowded_refined_cube: no seed crowds the nodes");
}

MeshAndLayout genus2_polycube(int k) {
  std::vector<std::array<int, 3>> voxels;
  for (int x = 0; x < 5; ++x)
    for (int y = 0; y < 3; ++y)
      if (!(y == 1 && (x == 1 || x == 3))) voxels.push_back({x, y, 0});
  return voxel_surface(voxels, k);
}

PolyMesh quad_box(std::array<int, 3> size, Vec3 offset) {
  using VH = OpenMesh::VertexHandle;
  PolyMesh mesh;
  std::map<std::array<int, 3>, VH> lattice;
  auto vertex = [&](std::array<int, 3> p) {
    auto it = lattice.find(p);
    if (it != lattice.end()) return it->second;
    const VH v = mesh.add_vertex(Vec3(p[0], p[1], p[2]) + offset);
    lattice.emplace(p, v);
    return v;
  };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side : {0, size[axis]}) {
      // Tangent axes (b, c) with b × c = +axis; swapped on the negative side.
      int b = (axis + 1) % 3, c = (axis + 2) % 3;
      if (side == 0) std::swap(b, c);
      for (int i = 0; i < size[b]; ++i) {
        for (int j = 0; j < size[c]; ++j) {
          std::array<int, 3> p{};
          p[axis] = side;
          auto at = [&](int di, int dj) {
            std::array<int, 3> q = p;
            q[b] = i + di;
            q[c] = j + dj;
            return vertex(q);
          };
          mesh.add_face(std::vector<VH>{at(0, 0), at(1, 0), at(1, 1), at(0, 1)});
        }
      }
    }
  }
  return mesh;
}

PolyMesh quad_cube(int k, Vec3 offset) {
  return quad_box({k, k, k}, offset);
}

PolyMesh quad_torus(int nu, int nv) {
  using VH = OpenMesh::VertexHandle;
  PolyMesh mesh;
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) {
      const double t = 2 * M_PI * i / nu, f = 2 * M_PI * j / nv;
      mesh.add_vertex(Vec3((2 + 0.7 * std::cos(f)) * std::cos(t),
                           (2 + 0.7 * std::cos(f)) * std::sin(t), 0.7 * std::sin(f)));
    }
  }
  auto id = [&](int i, int j) { return VH(((i + nu) % nu) * nv + (j + nv) % nv); };
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j)
      mesh.add_face(std::vector<VH>{id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return mesh;
}

PolyMesh quad_disk(int nx, int ny) {
  using VH = OpenMesh::VertexHandle;
  PolyMesh mesh;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) mesh.add_vertex(Vec3(i, j, 0));
  auto id = [&](int i, int j) { return VH(j * (nx + 1) + i); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      mesh.add_face(std::vector<VH>{id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return mesh;
}

PolyMesh notched_disk(int n) {
  using VH = OpenMesh::VertexHandle;
  PolyMesh mesh;
  std::map<std::array<int, 2>, VH> ids;
  auto at = [&](int i, int j) {
    auto it = ids.find({i, j});
    if (it != ids.end()) return it->second;
    const VH v = mesh.add_vertex(Vec3(i, j, 0));
    ids.emplace(std::array<int, 2>{i, j}, v);
    return v;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (i != n - 1 || j != n - 1)
        mesh.add_face(std::vector<VH>{at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  return mesh;
}

Layout dangling_star_layout(const TriMesh& mesh, int center, const std::vector<int>& targets) {
  Layout layout;
  layout.nodes.push_back(make_node(0, center));
  for (size_t i = 0; i < targets.size(); ++i) {
    RoutingObstacles obstacles = obstacles_of_layout(mesh, layout);
    // A dangling arc touches the boundary only at its end.
    for (auto v : mesh.vertices())
      if (mesh.is_boundary(v) && v.idx() != targets[i]) obstacles.vertex_blocked[v.idx()] = 1;
    LayoutArc arc =
        make_arc(static_cast<int>(i), 0, -1, shortest_path(mesh, center, targets[i], obstacles));
    layout.arcs.push_back(std::move(arc));
  }
  return layout;
}

MaskStar mask_star(const TriMesh& mesh) {
  MaskStar star;
  auto loops = boundary_loops(mesh);
  star.boundary_loops = loops.size();
  if (loops.size() != 3) return star;
  std::sort(loops.begin(), loops.end(),
            [](const auto& a, const auto& b) { return a.size() > b.size(); });
  auto point = [&](int v) { return mesh.point(mesh.vertex_handle(v)); };
  auto centroid = [&](const std::vector<int>& vs) {
    Vec3 c(0, 0, 0);
    for (int v : vs) c += point(v);
    return c / static_cast<double>(vs.size());
  };
  auto nearest = [&](const std::vector<int>& candidates, const Vec3& p) {
    int best = candidates[0];
    for (int v : candidates)
      if ((point(v) - p).sqrnorm() < (point(best) - p).sqrnorm()) best = v;
    return best;
  };
  const Vec3 eye_a = centroid(loops[1]), eye_b = centroid(loops[2]);
  std::vector<int> interior;
  for (auto v : mesh.vertices())
    if (!mesh.is_boundary(v)) interior.push_back(v.idx());
  star.center = nearest(interior, 0.5 * (eye_a + eye_b));
  const Vec3 c = point(star.center);
  Vec3 normal(0, 0, 0);
  for (auto f : mesh.faces()) normal += mesh.calc_face_normal(f) * mesh.calc_face_area(f);
  const Vec3 up_dir = (normal % (eye_b - eye_a)).normalized();
  int up = loops[0][0], down = loops[0][0];
  for (int v : loops[0]) {
    if (((point(v) - c) | up_dir) > ((point(up) - c) | up_dir)) up = v;
    if (((point(v) - c) | up_dir) < ((point(down) - c) | up_dir)) down = v;
  }
  star.targets = {nearest(loops[1], c), up, nearest(loops[2], c), down};
  return star;
}

namespace {

template <class Mesh>
void write_obj_text(const Mesh& mesh, const std::string& path) {
  std::ofstream out(path);
  out.precision(17);
  for (auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    out << "v " << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  }
  for (auto f : mesh.faces()) {
    out << 'f';
    for (auto v : mesh.fv_range(f)) out << ' ' << v.idx() + 1;
    out << '\n';
  }
}

}  // namespace

void write_obj(const TriMesh& mesh, const std::string& path) {
  write_obj_text(mesh, path);
}

void write_obj(const PolyMesh& mesh, const std::string& path) {
  write_obj_text(mesh, path);
}

FieldIndexCheck check_field_indices(const TriMesh& mesh, const GeometryCache& geometry,
                                    const Layout& layout, const LayoutTopology& topology,
                                    const std::vector<double>& theta) {
  FieldIndexCheck check;
  const std::vector<int> indices = field_quarter_indices(geometry, theta);
  std::vector<int> expected(mesh.n_vertices(), 0);
  std::vector<char> is_node(mesh.n_vertices(), 0);
  for (int n = 0; n < topology.num_nodes; ++n) {
    expected[layout.nodes[n].vertex] = 4 - topology.valence[n];
    is_node[layout.nodes[n].vertex] = 1;
    check.irregular += topology.valence[n] != 4;
  }
  for (const auto v : mesh.vertices()) {
    check.sum += indices[v.idx()];
    if (mesh.is_boundary(v) || indices[v.idx()] == expected[v.idx()]) continue;
    ++check.wrong;
    check.spurious += !is_node[v.idx()];
    if (check.examples.size() < 5) {
      check.examples.push_back("vertex " + std::to_string(v.idx()) + ": index " +
                               std::to_string(indices[v.idx()]) + "/4, expected " +
                               std::to_string(expected[v.idx()]) + "/4");
    }
  }
  return check;
}

EmbeddingCheck check_embedding(const TriMesh& mesh, const GeometryCache& geometry,
                               const LayoutTopology& topology, const Extraction& extraction,
                               const std::vector<std::array<double, 2>>& corner_uv) {
  EmbeddingCheck check;
  for (const TracedArc& t : extraction.arcs) {
    for (size_t i = 0; i + 1 < t.samples.size(); ++i) {
      // Both samples lie on the face of the second one (the face the segment crosses).
      const int f = t.samples[i + 1].face;
      const auto p0 = uv_in_face(mesh, geometry, corner_uv, t.samples[i], f);
      const auto p1 = uv_in_face(mesh, geometry, corner_uv, t.samples[i + 1], f);
      const double du = std::abs(p1[0] - p0[0]), dv = std::abs(p1[1] - p0[1]);
      const double moving = std::max(du, dv), fixed = std::min(du, dv);
      if (moving > 1e-12) check.iso_violation = std::max(check.iso_violation, fixed / moving);
    }
  }
  for (const auto& patch : topology.patches) {
    if (patch.darts.size() != 4) continue;
    for (int k = 0; k < 2; ++k) {
      const double a = extraction.arcs[patch.darts[k] >> 1].param_length;
      const double b = extraction.arcs[patch.darts[k + 2] >> 1].param_length;
      const double scale = std::max(a, b);
      if (scale > 0) check.side_mismatch = std::max(check.side_mismatch, std::abs(a - b) / scale);
      ++check.sides_checked;
    }
  }
  return check;
}

EmbeddingCheck check_embedding(Pipeline& pipeline) {
  const Extraction& ex = pipeline.extract();
  return check_embedding(pipeline.mesh(), pipeline.geometry(), pipeline.topology(), ex,
                         pipeline.parameterization()->corner_uv);
}

Layout displace_nodes(const TriMesh& mesh, Layout layout, int rings, int seed) {
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n) {
    if (layout.nodes[n].pinned) continue;
    const auto cand = ring_vertices(mesh, layout.nodes[n].vertex, rings);
    for (size_t k = 0; k < cand.size(); ++k) {
      const int w = cand[(k + static_cast<size_t>(seed) * 7 + n * 3) % cand.size()];
      const auto forbidden = forbidden_relocation_vertices(mesh, layout, n);
      if (forbidden[w]) continue;
      if (move_node_and_reroute(mesh, layout, n, w)) break;
    }
  }
  return layout;
}

std::vector<int> ring_vertices(const TriMesh& mesh, int v, int rings) {
  std::vector<int> dist(mesh.n_vertices(), -1);
  std::vector<int> out;
  std::queue<int> queue;
  dist[v] = 0;
  queue.push(v);
  while (!queue.empty()) {
    const int a = queue.front();
    queue.pop();
    if (dist[a] == rings) {
      out.push_back(a);
      continue;
    }
    for (auto w : mesh.vv_range(mesh.vertex_handle(a))) {
      if (dist[w.idx()] >= 0) continue;
      dist[w.idx()] = dist[a] + 1;
      queue.push(w.idx());
    }
  }
  return out;
}

std::vector<int> ring_distances(const TriMesh& mesh, const std::vector<int>& sources) {
  std::vector<int> dist(mesh.n_vertices(), -1), queue;
  for (int v : sources)
    if (dist[v] < 0) dist[v] = 0, queue.push_back(v);
  for (size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    for (auto w : mesh.vv_range(mesh.vertex_handle(v)))
      if (dist[w.idx()] < 0) dist[w.idx()] = dist[v] + 1, queue.push_back(w.idx());
  }
  return dist;
}

int face_ring_distance(const TriMesh& mesh, const std::vector<int>& dist, int f) {
  int d = INT_MAX;
  for (auto v : mesh.fv_range(mesh.face_handle(f))) d = std::min(d, dist[v.idx()]);
  return d;
}

Vec3 frozen_field_difference(const TriMesh& mesh, const GeometryCache& geometry,
                             const std::vector<double>& theta, int v, double eps,
                             const MovedEnergy& energy) {
  Vec3 t[2];
  tangent_basis(vertex_normal(mesh, geometry, v), t[0], t[1]);
  Vec3 fd(0, 0, 0);
  for (const Vec3& dir : t) {
    double E[2];
    for (int s = 0; s < 2; ++s) {
      TriMesh moved = mesh;
      moved.set_point(moved.vertex_handle(v),
                      mesh.point(mesh.vertex_handle(v)) + (s == 0 ? eps : -eps) * dir);
      GeometryCache g2 = geometry;
      update_geometry(moved, g2);
      E[s] = energy(moved, g2, freeze_field_after_move(moved, geometry, g2, theta, v));
    }
    fd += (E[0] - E[1]) / (2 * eps) * dir;
  }
  return fd;
}

MeshAndLayout ellipsoid_example() {
  const std::string dir = assets_dir() + "/example/";
  MeshAndLayout e;
  e.mesh = test::load_mesh(dir + "ellipsoid.obj");
  e.layout = load_layout(dir + "ellipsoid.layout.json", e.mesh);
  return e;
}

FieldGap field_gap(const Pipeline& a, const Pipeline& b) {
  FieldGap gap;
  const auto sa = a.singularities(), sb = b.singularities();
  gap.same_singularities = sa.size() == sb.size();
  for (size_t k = 0; gap.same_singularities && k < sa.size(); ++k)
    gap.same_singularities =
        sa[k].vertex == sb[k].vertex && sa[k].quarter_index == sb[k].quarter_index;
  const auto& ta = a.field()->theta;
  const auto& tb = b.field()->theta;
  for (size_t f = 0; f < ta.size() && f < tb.size(); ++f)
    gap.max_theta = std::max(gap.max_theta, std::abs(std::remainder(ta[f] - tb[f], M_PI / 2)));
  return gap;
}

}  // namespace qs::test
