// Tests of core/mesh/triangulate.h and of the triangulation of polygons by load_mesh.
#include "core/mesh/triangulate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// Checks that \p triangles split polygon \p face without inverting any triangle relative to
// the polygon's normal and without losing or doubling area.
void expect_tiles(const std::vector<int>& face, const std::vector<Vec3>& points,
                  const std::vector<std::array<int, 3>>& triangles) {
  ASSERT_EQ(triangles.size(), face.size() - 2);
  const Vec3 area = polygon_vector_area(face, points);
  const Vec3 normal = area.normalized();
  double sum = 0.0;
  for (const auto& t : triangles) {
    const Vec3 ta = polygon_vector_area(t, points);
    EXPECT_GT(OpenMesh::dot(ta, normal), 0.0)
        << "inverted triangle " << t[0] << " " << t[1] << " " << t[2];
    sum += ta.norm();
  }
  EXPECT_NEAR(sum, area.norm(), 1e-12 * area.norm());
}

// A prism over a U-shaped octagon: no corner of the U sees all of it.
const char* const kUPrism =
    "v 0 0 0\nv 3 0 0\nv 3 2 0\nv 2 2 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n"
    "v 0 0 1\nv 3 0 1\nv 3 2 1\nv 2 2 1\nv 2 1 1\nv 1 1 1\nv 1 2 1\nv 0 2 1\n"
    "f 8 7 6 5 4 3 2 1\nf 9 10 11 12 13 14 15 16\n"
    "f 1 2 10 9\nf 2 3 11 10\nf 3 4 12 11\nf 4 5 13 12\nf 5 6 14 13\nf 6 7 15 14\n"
    "f 7 8 16 15\nf 8 1 9 16\n";

TEST(Triangulate, ConcaveCapsOfTheUPrismKeepOrientationAndArea) {
  const std::string path = test::temp_dir("triangulate_u_prism") + "/u_prism.obj";
  std::ofstream(path) << kUPrism;
  const PolygonSoup soup = read_polygon_soup(path);
  MeshReport report;
  const TriMesh mesh = load_mesh(path, &report);
  ASSERT_TRUE(report.ok()) << ::testing::PrintToString(report.problems());
  ASSERT_EQ(report.faces, 2 * 6 + 8 * 2);
  // Triangulated faces expand in place: file face f owns the next size - 2 mesh faces.
  int next = 0;
  for (const auto& face : soup.faces) {
    SCOPED_TRACE(::testing::PrintToString(face));
    std::vector<std::array<int, 3>> triangles;
    for (std::size_t k = 0; k + 2 < face.size(); ++k) {
      std::array<int, 3> t{};
      int i = 0;
      for (const auto vh : mesh.fv_range(mesh.face_handle(next++))) t[i++] = vh.idx();
      triangles.push_back(t);
    }
    expect_tiles(face, soup.points, triangles);
  }
}

TEST(Triangulate, ConvexPolygonsUseTheBestFan) {
  // A quad whose short diagonal gives the better triangles: the fan from corner 1.
  const std::vector<Vec3> points = {{0, 0, 0}, {2, 0, 0}, {2.2, 1, 0}, {0, 1, 0}};
  const std::vector<int> face = {0, 1, 2, 3};
  const auto triangles = triangulate_polygon(face, points);
  expect_tiles(face, points, triangles);
  EXPECT_EQ(triangles[0], (std::array<int, 3>{1, 2, 3}));
  EXPECT_EQ(triangles[1], (std::array<int, 3>{1, 3, 0}));
}

TEST(Triangulate, CombAndSpiralAreClippedIntoEars) {
  // A comb with 5 teeth (no corner sees all teeth), tilted out of every coordinate plane.
  std::vector<Vec3> comb;
  comb.push_back({0, 0, 0});
  comb.push_back({9, 0, 0});
  for (int k = 4; k >= 0; --k) {
    comb.push_back({2.0 * k + 1, 3, 0});
    comb.push_back({2.0 * k + 0.5, 3, 0});
    comb.push_back({2.0 * k + 0.5, 1, 0});
    if (k > 0) comb.push_back({2.0 * k - 0.5, 1, 0});
  }
  comb.push_back({0, 1, 0});
  for (Vec3& p : comb) p = Vec3(p[0], p[1] * 0.8, p[1] * 0.6 + 0.1 * p[0]);
  // A square spiral, reversed (clockwise when seen from +z).
  std::vector<Vec3> spiral = {{0, 0, 0}, {6, 0, 0}, {6, 6, 0}, {1, 6, 0}, {1, 2, 0},
                              {4, 2, 0}, {4, 4, 0}, {3, 4, 0}, {3, 3, 0}, {2, 3, 0},
                              {2, 5, 0}, {5, 5, 0}, {5, 1, 0}, {0, 1, 0}};
  std::reverse(spiral.begin(), spiral.end());
  for (const auto* points : {&comb, &spiral}) {
    std::vector<int> face(points->size());
    std::iota(face.begin(), face.end(), 0);
    expect_tiles(face, *points, triangulate_polygon(face, *points));
  }
}

TEST(Triangulate, SelfCrossingOrFlatPolygonsHaveNoTriangulation) {
  // A pentagram: every fan keeps turning the same way, but the triangles overlap.
  std::vector<Vec3> star;
  for (int k = 0; k < 5; ++k) {
    const double a = 2.0 * M_PI * (2 * k % 5) / 5.0;
    star.push_back({std::cos(a), std::sin(a), 0});
  }
  EXPECT_TRUE(triangulate_polygon(std::vector<int>{0, 1, 2, 3, 4}, star).empty());
  const std::vector<Vec3> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  EXPECT_TRUE(triangulate_polygon(std::vector<int>{0, 1, 2, 3}, line).empty());
}

TEST(Triangulate, LoadMeshRefusesAFaceThatCannotBeTriangulatedWithItsId) {
  const std::string path = test::temp_dir("triangulate_star") + "/star.obj";
  {
    std::ofstream out(path);
    out << "v 0 0 -1\n";
    for (int k = 0; k < 5; ++k) {
      const double a = 2.0 * M_PI * (2 * k % 5) / 5.0;
      out << "v " << std::cos(a) << " " << std::sin(a) << " 0\n";
    }
    out << "f 1 3 2\nf 2 3 4 5 6\n";
  }
  MeshReport report;
  try {
    load_mesh(path, &report);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("1 face cannot be triangulated without inverted "
                                         "triangles (file face 1; line 8): its outline crosses "
                                         "or touches itself in its plane"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(report.untriangulable_faces, (std::vector<int>{1}));
}

}  // namespace
}  // namespace qs
