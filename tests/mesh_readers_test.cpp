// Tests of the per-format mesh readers behind core/mesh/mesh_io.h: byte-order marks in every
// text format, the ASCII STL grammar, coordinates out of range, files that are not files.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

namespace fs = std::filesystem;

const std::string kBom = "\xEF\xBB\xBF";

// Writes \p content to \p name in a fresh folder per test and returns the path.
std::string write(const std::string& name, const std::string& content) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string dir = test::temp_dir(std::string("mesh_readers_") + info->name());
  const std::string path = dir + "/" + name;
  std::ofstream(path, std::ios::binary) << content;
  return path;
}

// Message of the InvalidInputError thrown by \p load, or a failure marker.
template <typename F>
std::string error_of(F&& load) {
  try {
    load();
  } catch (const InvalidInputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    return std::string("<wrong exception type: ") + e.what() + ">";
  }
  return "<no exception>";
}

// The same tetrahedron in every text format.
const std::string kTetraObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
const std::string kTetraOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
const std::string kTetraPly =
    "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
    "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";

// ASCII STL of the tetrahedron: 4 facets of 7 lines after "solid" (facet k on line 2 + 7k).
std::string tetra_stl(bool with_endsolid = true) {
  const char* corners[4][3] = {{"0 0 0", "0 1 0", "1 0 0"},
                               {"0 0 0", "1 0 0", "0 0 1"},
                               {"1 0 0", "0 1 0", "0 0 1"},
                               {"0 1 0", "0 0 0", "0 0 1"}};
  std::string s = "solid tetra\n";
  for (const auto& facet : corners) {
    s += "  facet normal 0 0 0\n    outer loop\n";
    for (const char* c : facet) s += std::string("      vertex ") + c + "\n";
    s += "    endloop\n  endfacet\n";
  }
  return with_endsolid ? s + "endsolid tetra\n" : s;
}

// ---------------------------------------------------------------------------------------------
// Byte-order marks

void expect_tetrahedron(const std::string& path) {
  SCOPED_TRACE(path);
  MeshReport report;
  const TriMesh mesh = load_mesh(path, &report);
  EXPECT_EQ(report.vertices, 4);
  EXPECT_EQ(report.faces, 4);
  EXPECT_TRUE(report.warnings.empty()) << report.warnings[0];
  EXPECT_EQ(mesh.point(mesh.vertex_handle(0)), Vec3(0, 0, 0));
  EXPECT_EQ(mesh.point(mesh.vertex_handle(3)), Vec3(0, 0, 1));
}

TEST(ByteOrderMark, ObjSkipsItAndKeepsTheFirstVertexAndLineNumbers) {
  expect_tetrahedron(write("bom.obj", kBom + kTetraObj));
  const PolygonSoup soup = read_polygon_soup(write("lines.obj", kBom + kTetraObj));
  EXPECT_EQ(soup.point_lines, (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(soup.face_lines, (std::vector<int>{5, 6, 7, 8}));
}

TEST(ByteOrderMark, OffSkipsIt) {
  expect_tetrahedron(write("bom.off", kBom + kTetraOff));
}

TEST(ByteOrderMark, PlyHeaderSkipsIt) {
  expect_tetrahedron(write("bom.ply", kBom + kTetraPly));
}

TEST(ByteOrderMark, AsciiStlSkipsIt) {
  const std::string path = write("bom.stl", kBom + tetra_stl());
  MeshReport report;
  load_mesh(path, &report);
  EXPECT_EQ(report.vertices, 4);
  EXPECT_EQ(report.faces, 4);
}

TEST(ByteOrderMark, OnlyAtTheStart) {
  // Elsewhere the three bytes are content: here, an unknown OBJ statement.
  const PolygonSoup soup =
      read_polygon_soup(write("middle.obj", "v 0 0 0\n" + kBom + "v 1 0 0\n" + kTetraObj));
  EXPECT_EQ(soup.points.size(), 5u);
  ASSERT_EQ(soup.warnings.size(), 1u);
  EXPECT_NE(soup.warnings[0].find("ignored unknown OBJ statements"), std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// ASCII STL

TEST(AsciiStl, ReadsFacetsMergingEqualCornersWithTheirLines) {
  const PolygonSoup soup = read_polygon_soup(write("tetra.stl", tetra_stl()));
  ASSERT_EQ(soup.points.size(), 4u);
  EXPECT_EQ(soup.points[1], Vec3(0, 1, 0));
  EXPECT_EQ(soup.faces,
            (std::vector<std::vector<int>>{{0, 1, 2}, {0, 2, 3}, {2, 1, 3}, {1, 0, 3}}));
  EXPECT_EQ(soup.face_lines, (std::vector<int>{2, 9, 16, 23}));
  EXPECT_EQ(soup.point_lines, (std::vector<int>{4, 5, 6, 13}));
}

TEST(AsciiStl, CutAfterAFacetOrWithoutEndsolidIsRefusedWithItsLine) {
  // 29 lines without "endsolid": the file ends after facet 4 (line 29).
  const std::string cut = write("cut.stl", tetra_stl(false));
  EXPECT_EQ(error_of([&] { read_polygon_soup(cut); }),
            cut + ":29: the file ends after 4 facets without 'endsolid' (truncated?)");
  // Cut after the first facet.
  const std::string first =
      write("first.stl", tetra_stl().substr(0, tetra_stl().find("  facet", 20)));
  EXPECT_EQ(error_of([&] { read_polygon_soup(first); }),
            first + ":8: the file ends after 1 facet without 'endsolid' (truncated?)");
  // Cut after a facet's "endloop".
  const std::string inside =
      write("inside.stl", tetra_stl().substr(0, tetra_stl().find("  endfacet")));
  EXPECT_EQ(error_of([&] { read_polygon_soup(inside); }),
            inside + ":7: the file ends inside facet 1 without 'endsolid' (truncated?)");
}

TEST(AsciiStl, StructureIsChecked) {
  std::string no_endloop = tetra_stl();
  no_endloop.erase(no_endloop.find("    endloop\n"), 12);
  const std::string path = write("no_endloop.stl", no_endloop);
  EXPECT_EQ(error_of([&] { read_polygon_soup(path); }),
            path + ":7: expected 'endloop' after three corners (STL facets are triangles)");
  const std::string after = write("after.stl", tetra_stl() + "facet normal 0 0 1\n");
  EXPECT_EQ(error_of([&] { read_polygon_soup(after); }),
            after + ":31: unexpected 'facet' after 'endsolid'");
  // Several solids in one file are read as one mesh; keywords are case-insensitive, and a
  // name may contain a keyword ("outer" made OpenMesh's reader start a triangle).
  std::string two = tetra_stl();
  const std::size_t split = two.find("  facet normal", two.find("endfacet"));
  two.insert(split, "endsolid a\nSOLID outer_shell\n");
  const PolygonSoup soup = read_polygon_soup(write("two.stl", two));
  EXPECT_EQ(soup.faces.size(), 4u);
  EXPECT_EQ(soup.points.size(), 4u);
}

// ---------------------------------------------------------------------------------------------
// Coordinates out of range

const std::string kOctahedronFaces =
    "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n";

TEST(CoordinateRange, HugeCoordinateNamesItsVertexAndBlamesNoFace) {
  const std::string path =
      write("big.obj",
            "v 1 0 0\nv -1 0 0\nv 0 1e308 0\nv 0 -1 0\nv 0 0 1\nv 0 0 -1\n" + kOctahedronFaces);
  MeshReport report;
  const std::string message = error_of([&] { load_mesh(path, &report); });
  EXPECT_EQ(report.out_of_range_vertices, (std::vector<int>{2}));
  EXPECT_TRUE(report.degenerate_faces.empty());
  EXPECT_EQ(message, path +
                         ": invalid mesh\nvertex 2 (line 3): coordinate magnitude out of range "
                         "(above 1e+150, where lengths and areas overflow)");
}

TEST(CoordinateRange, LimitIsTheMagnitudeNotTheExtent) {
  // 1e150 itself is accepted (squared lengths stay finite); 1.1e150 is not.
  const std::string at_limit =
      write("limit.obj",
            "v 1e150 0 0\nv -1e150 0 0\nv 0 1e150 0\nv 0 -1e150 0\nv 0 0 1e150\n"
            "v 0 0 -1e150\n" +
                kOctahedronFaces);
  MeshReport report;
  load_mesh(at_limit, &report);
  EXPECT_TRUE(report.ok());
  const std::string beyond = write("beyond.obj",
                                   "v 1 0 0\nv -1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\n"
                                   "v 0 0 -1.1e150\n" +
                                       kOctahedronFaces);
  EXPECT_NE(error_of([&] { load_mesh(beyond); }).find("vertex 5 (line 6): coordinate magnitude"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// Files that are not regular files

TEST(InputFile, DirectoriesAndFifosAreRefusedWithoutReading) {
  const std::string folder = write("placeholder", "") + ".obj";
  fs::create_directories(folder);
  EXPECT_EQ(error_of([&] { read_polygon_soup(folder); }),
            folder + ": cannot open file: it is a directory, not a regular file");
  const std::string fifo = folder + "/pipe.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { read_polygon_soup(fifo); }),
            fifo + ": cannot open file: it is a FIFO (named pipe), not a regular file");
}

}  // namespace
}  // namespace qs
