// field.txt is the field of the parameterization, on the final geometry, with its singularities
// exactly at the layout's irregular nodes (issue #44 item 4). The check is independent of the
// library: it reads param.obj, field.txt and layout.json as written, and measures every
// interior vertex's index from the written directions alone (principal matching between
// neighbouring faces, unfolded across their common edge, plus the angle defect).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/field/cross_field.h"
#include "core/field/matching_repair.h"
#include "core/mesh/geometry.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

using P3 = std::array<double, 3>;

P3 sub(const P3& a, const P3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
P3 cross3(const P3& a, const P3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot3(const P3& a, const P3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

struct WrittenResult {
  std::vector<P3> points;                 // param.obj vertices
  std::vector<std::array<int, 3>> faces;  // param.obj triangles (0-based)
  std::vector<P3> field;                  // field.txt, one direction per face
  std::map<int, int> node_valence;        // layout.json: node vertex → arcs ending there
};

WrittenResult read_result(const std::string& dir) {
  WrittenResult r;
  std::ifstream obj(dir + "/param.obj");
  std::string line;
  while (std::getline(obj, line)) {
    std::istringstream in(line);
    std::string tag;
    in >> tag;
    if (tag == "v") {
      P3 p;
      in >> p[0] >> p[1] >> p[2];
      r.points.push_back(p);
    } else if (tag == "f") {
      std::array<int, 3> f;
      for (int& v : f) {
        std::string corner;
        in >> corner;
        v = std::stoi(corner.substr(0, corner.find('/'))) - 1;
      }
      r.faces.push_back(f);
    }
  }
  std::ifstream field(dir + "/field.txt");
  P3 d;
  while (field >> d[0] >> d[1] >> d[2]) r.field.push_back(d);
  std::ifstream layout_file(dir + "/layout.json");
  const nlohmann::json layout = nlohmann::json::parse(layout_file);
  std::map<int, int> vertex_of;
  for (const auto& n : layout["nodes"]) {
    vertex_of[n["id"].get<int>()] = n["vertex"].get<int>();
    r.node_valence[n["vertex"].get<int>()] = 0;
  }
  for (const auto& a : layout["arcs"])
    for (const char* end : {"from", "to"})
      if (a.contains(end) && a[end].is_number_integer() && a[end].get<int>() >= 0)
        ++r.node_valence[vertex_of.at(a[end].get<int>())];
  return r;
}

struct IndexCheck {
  std::map<int, int> index;  // interior vertex → quarter turns (non-zero only)
  double max_normal = 0;     // largest |d · n| / |d| of a written direction
  double max_length_error = 0;
};

// Signed angle from a to b in the plane with unit normal n.
double angle_in_plane(const P3& a, const P3& b, const P3& n) {
  return std::atan2(dot3(cross3(a, b), n), dot3(a, b));
}

IndexCheck measure(const WrittenResult& r) {
  IndexCheck out;
  const int nf = static_cast<int>(r.faces.size());
  std::vector<P3> normal(nf);
  for (int f = 0; f < nf; ++f) {
    const auto& t = r.faces[f];
    P3 n = cross3(sub(r.points[t[1]], r.points[t[0]]), sub(r.points[t[2]], r.points[t[0]]));
    const double len = std::sqrt(dot3(n, n));
    for (double& c : n) c /= len;
    normal[f] = n;
    const P3& d = r.field[f];
    const double dl = std::sqrt(dot3(d, d));
    out.max_length_error = std::max(out.max_length_error, std::abs(dl - 1));
    out.max_normal = std::max(out.max_normal, std::abs(dot3(d, n)) / dl);
  }
  // Around vertex v: for each corner (face f, next vertex a, previous vertex b) in ccw order,
  // the field's angle against the edge v→b in f and in the face across v→b. The turn across
  // that edge is their difference (the unfolding keeps angles to the common edge), reduced
  // to (−45°, 45°]; the index is (angle defect + Σ turns) / 90°.
  std::map<int, std::map<int, std::pair<int, int>>> corners;  // v → a → (face, b)
  for (int f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k)
      corners[r.faces[f][k]][r.faces[f][(k + 1) % 3]] = {f, r.faces[f][(k + 2) % 3]};
  const double quarter = M_PI / 2;
  for (const auto& [v, ring] : corners) {
    bool closed = true;
    for (const auto& [a, fb] : ring) closed = closed && ring.count(fb.second);
    if (!closed) continue;  // boundary vertex
    double angles = 0, turns = 0;
    for (const auto& [a, fb] : ring) {
      const auto [f, b] = fb;
      const P3 ea = sub(r.points[a], r.points[v]), eb = sub(r.points[b], r.points[v]);
      angles += angle_in_plane(ea, eb, normal[f]);
      const int g = ring.at(b).first;
      double t =
          angle_in_plane(eb, r.field[g], normal[g]) - angle_in_plane(eb, r.field[f], normal[f]);
      t -= quarter * std::round(t / quarter);
      turns += t;
    }
    const int index = static_cast<int>(std::lround((2 * M_PI - angles + turns) / quarter));
    if (index != 0) out.index[v] = index;
  }
  return out;
}

// import-quads \p import_args, then optimize \p optimize_args on the imported layout; the
// written field's singularities are the layout's irregular nodes with index 4 − valence.
void expect_field_singularities_at_nodes(const std::string& name, const std::string& import_args,
                                         const std::string& optimize_args) {
  SCOPED_TRACE(name);
  const std::string dir = test::temp_dir("field_txt_" + name);
  std::string out;
  ASSERT_EQ(
      test::run_command(
          test::cli_path() + " -q import-quads " + import_args + " --out " + dir + "/import", &out),
      0)
      << out;
  ASSERT_EQ(test::run_command(test::cli_path() + " -q optimize --mesh " + dir +
                                  "/import/mesh.obj --layout " + dir + "/import/layout.json " +
                                  optimize_args + " --out " + dir + "/opt",
                              &out),
            0)
      << out;
  const WrittenResult r = read_result(dir + "/opt");
  ASSERT_EQ(r.field.size(), r.faces.size());
  const IndexCheck c = measure(r);
  EXPECT_LT(c.max_normal, 1e-6);
  EXPECT_LT(c.max_length_error, 1e-6);
  int irregular = 0;
  for (const auto& [v, valence] : r.node_valence) {
    const int want = 4 - valence;
    irregular += want != 0;
    const auto it = c.index.find(v);
    EXPECT_EQ(it == c.index.end() ? 0 : it->second, want) << "node vertex " << v;
  }
  EXPECT_GT(irregular, 0);
  for (const auto& [v, index] : c.index)
    EXPECT_TRUE(r.node_valence.count(v))
        << "singularity of index " << index << " at vertex " << v << ", no node there";
  std::printf("[stat] %s: %d irregular nodes, %zu singularities in field.txt, max normal %.2g\n",
              name.c_str(), irregular, c.index.size(), c.max_normal);
}

// Spot's control mesh (public domain, assets/repro): its coarse cones sit on vertices of three
// faces with angle defects above 100°, and the node optimization moves nodes next to them,
// where the smoothest field turned by more than 45° across an edge (4 extra singularities
// beside 4 nodes measured at index 0).
TEST(FieldTxtCli, SingularitiesAreTheNodesOnSpotsImportedLayout) {
  expect_field_singularities_at_nodes(
      "spot", "--quads " + test::assets_dir() + "/repro/spot_control_mesh.obj --refine 3", "");
}

// A synthetic quad mesh: the cube split 3×3 per side, every edge an arc.
TEST(FieldTxtCli, SingularitiesAreTheNodesOnAnImportedCube) {
  const std::string dir = test::temp_dir("field_txt_cube_input");
  test::write_obj(test::quad_cube(3), dir + "/cube.obj");
  expect_field_singularities_at_nodes("cube", "--quads " + dir + "/cube.obj --all-edges --refine 2",
                                      "--steps 5");
}

// The repair itself, on a flat 8×8 grid: period jumps of a quarter turn across the edges of a
// ray from the centre vertex to the boundary (a singularity of index ±1 at the centre), and a
// constant field, which turns by 90° across every edge of the ray. Principal matching sees no
// turn there, so the field alone has no singularity. After the repair no edge turns by 45°
// or more, the field alone has its singularity at the centre and nowhere else, and the held
// face keeps its θ.
TEST(FieldTxtCli, RepairSpreadsASteepTurn) {
  const test::MeshAndLayout d = test::disk_grid(8, 8, 1, 1);
  const GeometryCache g = build_geometry(d.mesh);
  int centre = -1;
  std::vector<int> p(g.n_edges, 0);
  for (int e = 0; e < g.n_edges; ++e) {
    const Vec3 a = d.mesh.point(d.mesh.vertex_handle(g.edge_vertices[e][0]));
    const Vec3 b = d.mesh.point(d.mesh.vertex_handle(g.edge_vertices[e][1]));
    if (a[1] == 4 && b[1] == 4 && a[0] >= 4 && b[0] >= 4) p[e] = 1;
  }
  for (auto v : d.mesh.vertices())
    if (d.mesh.point(v) == Vec3(4, 4, 0)) centre = v.idx();
  ASSERT_GE(centre, 0);
  std::vector<double> theta(g.n_faces);
  for (int f = 0; f < g.n_faces; ++f) theta[f] = g.angle_in_face(f, Vec3(1, 0, 0));
  for (int i : field_quarter_indices(g, theta)) ASSERT_EQ(i, 0);
  std::vector<char> fixed(g.n_faces, 0);
  fixed[0] = 1;
  const double held = theta[0];
  const MatchingRepairResult r = repair_principal_matching(g, p, fixed, theta);
  EXPECT_EQ(r.mismatched_before, 4);
  EXPECT_EQ(r.mismatched_after, 0);
  EXPECT_GT(r.changed_faces, 0);
  EXPECT_EQ(theta[0], held);
  for (int e = 0; e < g.n_edges; ++e) {
    if (g.edge_face_i[e] < 0 || g.edge_face_j[e] < 0) continue;
    EXPECT_LT(
        std::abs(theta[g.edge_face_j[e]] - theta[g.edge_face_i[e]] - g.kappa[e] - M_PI / 2 * p[e]),
        M_PI / 4)
        << "edge " << e;
  }
  const std::vector<int> index = field_quarter_indices(g, theta);
  for (int v = 0; v < g.n_vertices; ++v)
    if (v == centre)
      EXPECT_EQ(std::abs(index[v]), 1);
    else
      EXPECT_EQ(index[v], 0) << "vertex " << v;
}

}  // namespace
}  // namespace qs
