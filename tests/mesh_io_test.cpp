// Tests of core/mesh/mesh_io.h and core/mesh/mesh_checks.h: parsers, checks, the bad-input
// corpus in assets/bad/ and the shared real meshes with the counts published in SOURCES.md.
#include "core/mesh/mesh_io.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string("qs_mesh_io_") + info->test_suite_name() + "_" + info->name();
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = fs::temp_directory_path() / name;
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  std::string write(const std::string& name, const std::string& content) const {
    std::ofstream(file(name), std::ios::binary) << content;
    return file(name);
  }

 private:
  fs::path path_;
};

const char* kTetrahedronObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
    "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";

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

// True when mesh face \p fh visits exactly \p expected, up to a rotation.
template <typename MeshT>
bool face_matches(const MeshT& mesh, typename MeshT::FaceHandle fh,
                  const std::vector<int>& expected) {
  std::vector<int> got;
  for (auto vh : mesh.fv_range(fh)) got.push_back(vh.idx());
  if (got.size() != expected.size()) return false;
  for (std::size_t r = 0; r < got.size(); ++r) {
    std::rotate(got.begin(), got.begin() + 1, got.end());
    if (got == expected) return true;
  }
  return false;
}

// ---------------------------------------------------------------------------------------------
// Parsers

TEST(ObjParser, ReadsAllFaceFormsNegativeIndicesAndIgnoresOtherStatements) {
  TempDir dir;
  const std::string path = dir.write("forms.obj",
                                     "# comment\r\n"
                                     "mtllib a.mtl\r\n"
                                     "o thing\r\n"
                                     "v 0 0 0\r\n"
                                     "v 1 0 0 # trailing comment\r\n"
                                     "vt 0 0\r\nvn 0 0 1\r\nvp 0.5\r\n"
                                     "v +2.5e0 -1 0.5\r\n"
                                     "g group\r\ns 1\r\nusemtl m\r\nl 1 2\r\n"
                                     "v 0 1 0\r\n"
                                     "\r\n"
                                     "f 1/1/1 2/1/1 3/1/1\r\n"
                                     "f 1//1 3//1 4//1\r\n"
                                     "f -4 -1 -2\r\n"
                                     "sm 1 2\r\n"
                                     "sm 3 4\r\n");
  const PolygonSoup soup = read_polygon_soup(path);
  ASSERT_EQ(soup.points.size(), 4u);
  EXPECT_EQ(soup.points[2], Vec3(2.5, -1.0, 0.5));
  ASSERT_EQ(soup.faces.size(), 3u);
  EXPECT_EQ(soup.faces[0], (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(soup.faces[1], (std::vector<int>{0, 2, 3}));
  EXPECT_EQ(soup.faces[2], (std::vector<int>{0, 3, 2}));
  EXPECT_EQ(soup.face_lines, (std::vector<int>{16, 17, 18}));
  ASSERT_EQ(soup.warnings.size(), 1u);
  EXPECT_NE(soup.warnings[0].find("2 lines 'sm'"), std::string::npos) << soup.warnings[0];
}

TEST(ObjParser, ReportsLinePreciseErrors) {
  TempDir dir;
  const std::string path =
      dir.write("bad.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 x\nf 1/2/3/4 2 3\n");
  const std::string message = error_of([&] { read_polygon_soup(path); });
  EXPECT_NE(message.find(path + ":2: vertex has 2 coordinates, expected 3"), std::string::npos)
      << message;
  EXPECT_NE(message.find(path + ":4: face vertex 'x' is not an index"), std::string::npos)
      << message;
  EXPECT_NE(message.find(path + ":5: face vertex '1/2/3/4'"), std::string::npos) << message;
  // Complete lines are not blamed on truncation.
  EXPECT_EQ(message.find("truncated"), std::string::npos) << message;
}

TEST(OffParser, AcceptsCommentsCountsOnHeaderLineAndFaceColours) {
  TempDir dir;
  const std::string path = dir.write("colours.off",
                                     "# leading comment\n\n"
                                     "OFF 4 2 0\n"
                                     "0 0 0\n1 0 0 # comment\n\n1 1 0\n0 1 0\n"
                                     "3 0 1 2 255 0 0\n"
                                     "3 0 2 3 0.5 0.5 0.5 1\n");
  const PolygonSoup soup = read_polygon_soup(path);
  ASSERT_EQ(soup.points.size(), 4u);
  EXPECT_EQ(soup.faces, (std::vector<std::vector<int>>{{0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(soup.face_lines, (std::vector<int>{9, 10}));
}

TEST(OffParser, ReportsDeclaredAndListedSizeMismatches) {
  TempDir dir;
  const std::string path =
      dir.write("sizes.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n4 0 1 2\n3 0 1 2\n3 0 1 2\n");
  const std::string message = error_of([&] { read_polygon_soup(path); });
  EXPECT_NE(message.find(path + ":6: face declares 4 vertices but lists 3"), std::string::npos)
      << message;
  EXPECT_NE(message.find(path + ":8: unexpected content after the 2 faces"), std::string::npos)
      << message;
}

TEST(OffParser, FaceIndicesMaySpanSeveralLines) {
  // libigl's inspired_mesh_quads_*.off write "4 887", then one index per line.
  TempDir dir;
  const std::string path = dir.write("multiline.off",
                                     "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                                     "3 0\n1\n# comment between indices\n\n2\n"
                                     "3 0 2 3\n");
  const PolygonSoup soup = read_polygon_soup(path);
  EXPECT_EQ(soup.faces, (std::vector<std::vector<int>>{{0, 1, 2}, {0, 2, 3}}));
  EXPECT_EQ(soup.face_lines, (std::vector<int>{7, 12}));
}

TEST(OffParser, ShortFaceDoesNotSwallowTheNextOne) {
  TempDir dir;
  const std::string cut = dir.write("cut_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1");
  const std::string message = error_of([&] { read_polygon_soup(cut); });
  EXPECT_NE(message.find("unexpected end of file"), std::string::npos) << message;
  EXPECT_NE(message.find("truncated"), std::string::npos) << message;
  const std::string variant = dir.write("4d.off", "4OFF\n1 0 0\n0 0 0 0\n");
  EXPECT_NE(error_of([&] { read_polygon_soup(variant); }).find("unsupported OFF variant '4OFF'"),
            std::string::npos);
  const std::string header = dir.write("header.off", "OFFF\n");
  EXPECT_NE(error_of([&] { read_polygon_soup(header); }).find(":1: expected the header 'OFF'"),
            std::string::npos);
}

TEST(OffParser, PrefixedVariantsIgnoreExtraVertexValues) {
  TempDir dir;
  const std::string path =
      dir.write("colour.off",
                "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n"
                "3 0 1 2\n");
  const PolygonSoup soup = read_polygon_soup(path);
  EXPECT_EQ(soup.points[1], Vec3(1, 0, 0));
  // Plain OFF stays strict.
  const std::string plain = dir.write("plain.off", "OFF\n3 1 0\n0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_NE(error_of([&] {
              read_polygon_soup(plain);
            }).find(plain + ":3: vertex has 4 coordinates, expected 3"),
            std::string::npos);
}

TEST(ObjParser, FileCutInsideAVertexLine) {
  TempDir dir;
  const std::string path = dir.write("cut.obj", "v 0 0 0\nv 1 0 0\nv 0.5 0.2");
  EXPECT_EQ(error_of([&] { read_polygon_soup(path); }),
            path +
                ":3: vertex has 2 coordinates, expected 3 (the file ends in the middle of this "
                "line: truncated?)");
}

TEST(ReadPolygonSoup, MissingFileAndExtensionCase) {
  TempDir dir;
  const std::string missing = dir.file("nothing_here.obj");
  EXPECT_EQ(error_of([&] { read_polygon_soup(missing); }), missing + ": cannot open file");
  // The extension is case-insensitive.
  const std::string upper = dir.write("TETRA.OBJ", kTetrahedronObj);
  EXPECT_EQ(load_mesh(upper).n_faces(), 4u);
}

// ---------------------------------------------------------------------------------------------
// Checks on synthetic meshes

TEST(CountTopology, ClosedTetrahedron) {
  TempDir dir;
  MeshReport report;
  const TriMesh mesh = load_mesh(dir.write("tet.obj", kTetrahedronObj), &report);
  EXPECT_TRUE(report.ok());
  EXPECT_TRUE(report.problems().empty());
  EXPECT_EQ(report.vertices, 4);
  EXPECT_EQ(report.faces, 4);
  EXPECT_EQ(report.edges, 6);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.boundary_loops, 0);
  EXPECT_EQ(report.euler_characteristic, 2);
  EXPECT_EQ(report.genus, 0);
  EXPECT_TRUE(boundary_loops(mesh).empty());
}

TEST(CountTopology, OpenSquareBoundaryLoopHasInteriorOnTheLeft) {
  // Two counter-clockwise triangles in the xy-plane: the interior halfedges along the border
  // run 0 -> 1 -> 2 -> 3, counter-clockwise seen from +z, with the square on their left.
  PolygonSoup soup;
  soup.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0, 1, 0)};
  soup.faces = {{0, 1, 2}, {0, 2, 3}};
  MeshReport report;
  const TriMesh mesh = build_tri_mesh(soup, report, {});
  EXPECT_TRUE(report.ok()) << ::testing::PrintToString(report.problems());
  EXPECT_EQ(report.boundary_loops, 1);
  EXPECT_EQ(report.euler_characteristic, 1);
  EXPECT_EQ(report.genus, 0);
  const auto loops = boundary_loops(mesh);
  ASSERT_EQ(loops.size(), 1u);
  EXPECT_EQ(loops[0], (std::vector<int>{0, 1, 2, 3}));
  // Each consecutive pair must be an interior halfedge whose face lies to its left.
  for (std::size_t i = 0; i < loops[0].size(); ++i) {
    const auto heh = mesh.find_halfedge(OpenMesh::VertexHandle(loops[0][i]),
                                        OpenMesh::VertexHandle(loops[0][(i + 1) % 4]));
    ASSERT_TRUE(heh.is_valid());
    EXPECT_FALSE(mesh.is_boundary(heh));
  }
}

TEST(FaceComponents, TwoSeparateTriangles) {
  MeshReport report;
  LoadMeshOptions options;
  options.allow_multiple_components = true;
  const TriMesh mesh = load_mesh(test::assets_dir() + "/bad/two_components.obj", &report, options);
  EXPECT_TRUE(report.ok());
  EXPECT_EQ(report.components, 2);
  int count = 0;
  EXPECT_EQ(face_components(mesh, &count), (std::vector<int>{0, 1}));
  EXPECT_EQ(count, 2);
}

TEST(NonManifoldVertex, OpenFansTouchingAtAVertexAreAcceptedByOpenMeshButReported) {
  // A bow tie: both triangles fit into the halfedge structure (vertex 0 gets two boundary
  // gaps), so only the vertex check can notice.
  PolygonSoup soup;
  soup.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(-1, 0, 0), Vec3(-1, -1, 0)};
  soup.faces = {{0, 1, 2}, {0, 3, 4}};
  MeshReport report;
  const TriMesh mesh = build_tri_mesh(soup, report, {});
  EXPECT_EQ(mesh.n_faces(), 2u);
  EXPECT_TRUE(report.dropped_faces.empty());
  EXPECT_EQ(report.nonmanifold_vertices, (std::vector<int>{0}));
  EXPECT_FALSE(report.ok());
}

TEST(NonManifoldVertex, ClosedFansTouchingAtAVertexAreRefusedAndReported) {
  MeshReport report;
  const std::string path = test::assets_dir() + "/bad/nonmanifold_vertex.obj";
  EXPECT_THROW(load_mesh(path, &report), InvalidInputError);
  EXPECT_EQ(report.nonmanifold_vertices, (std::vector<int>{0}));
  EXPECT_EQ(report.dropped_faces, (std::vector<int>{3, 4, 5}));
  for (DropReason r : report.drop_reasons) EXPECT_EQ(r, DropReason::kNonManifoldVertex);
}

TEST(NonManifoldEdge, ThirdFaceIsDroppedAndEdgeEndsAreNonManifold) {
  MeshReport report;
  EXPECT_THROW(load_mesh(test::assets_dir() + "/bad/nonmanifold_edge.obj", &report),
               InvalidInputError);
  EXPECT_EQ(report.dropped_faces, (std::vector<int>{2}));
  ASSERT_EQ(report.drop_reasons.size(), 1u);
  EXPECT_EQ(report.drop_reasons[0], DropReason::kNonManifoldEdge);
  EXPECT_EQ(report.nonmanifold_vertices, (std::vector<int>{0, 1}));
  // Apex 4 of the dropped face is not blamed.
  EXPECT_TRUE(report.unreferenced_vertices.empty());
}

TEST(Duplicates, ReversedCopyOfAnIsolatedTriangleIsNotGluedOn) {
  // add_face would accept (0, 2, 1) after (0, 1, 2) and close a two-triangle "pillow".
  PolygonSoup soup;
  soup.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  soup.faces = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}};
  MeshReport report;
  const TriMesh mesh = build_tri_mesh(soup, report, {});
  EXPECT_EQ(mesh.n_faces(), 1u);
  EXPECT_EQ(report.dropped_faces, (std::vector<int>{1, 2}));
  EXPECT_EQ(report.drop_reasons,
            (std::vector<DropReason>{DropReason::kDuplicate, DropReason::kDuplicate}));
  EXPECT_TRUE(report.nonmanifold_vertices.empty());
}

TEST(Degenerate, ThresholdSeparatesSliversFromZeroArea) {
  // A sliver with height 1e-6 of a unit diagonal is valid; collinear corners are not.
  PolygonSoup soup;
  soup.points = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0.5, 1e-6, 0), Vec3(0.5, -1, 0),
                 Vec3(0.25, 0, 0)};
  soup.faces = {{0, 1, 2}, {1, 0, 3}};
  MeshReport report;
  build_tri_mesh(soup, report, {});
  EXPECT_TRUE(report.degenerate_faces.empty());
  soup.faces.push_back({0, 4, 1});  // on the x axis: zero area
  // Corners rounded onto a skew line: the computed area is rounding noise, not exactly 0.
  const Vec3 a(0.1, 0.7, 0.3);
  const Vec3 d(0.3, -0.2, 0.9);
  soup.points.push_back(a);
  soup.points.push_back(a + 0.37 * d);
  soup.points.push_back(a + d);
  soup.faces.push_back({5, 6, 7});
  MeshReport report2;
  build_tri_mesh(soup, report2, {});
  EXPECT_EQ(report2.degenerate_faces, (std::vector<int>{2, 3}));
}

TEST(Report, ListsAtMostTenIdsAndKeepsReportWhenThrowing) {
  TempDir dir;
  std::string text = kTetrahedronObj;
  for (int i = 0; i < 12; ++i) text += "v 9 9 " + std::to_string(i) + "\n";
  const std::string path = dir.write("many.obj", text);
  MeshReport report;
  const std::string message = error_of([&] { load_mesh(path, &report); });
  EXPECT_EQ(report.path, path);
  EXPECT_EQ(report.unreferenced_vertices.size(), 12u);
  EXPECT_EQ(message.rfind(path + ": invalid mesh\n", 0), 0u) << message;
  EXPECT_NE(message.find("12 unreferenced vertices (ids 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, …)"),
            std::string::npos)
      << message;
}

TEST(Report, EveryProblemAppearsInOneMessage) {
  TempDir dir;
  const std::string path = dir.write("several.obj",
                                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 nan\nv 7 7 7\n"
                                     "f 1 2 3\nf 1 2 2\nf 1 2 9\nf 2 1 4\n");
  const std::string message = error_of([&] { load_mesh(path); });
  for (const char* words : {"non-finite", "degenerate face", "refers to missing vertices",
                            "unreferenced vertex (id 4)"}) {
    EXPECT_NE(message.find(words), std::string::npos) << words << " in\n" << message;
  }
}

// ---------------------------------------------------------------------------------------------
// Triangulation

TEST(Triangulation, QuadAndPentagonAreSplitWithAWarning) {
  TempDir dir;
  // Corners 1-2-3 of the quad and 6-5-4 of the pentagon are collinear, so a fan from the
  // first corner would contain a zero-area triangle.
  const std::string path = dir.write("poly.obj",
                                     "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 0 1 0\n"
                                     "v 1 2 0\nv 3 0.5 0\n"
                                     "f 1 2 3 5\n"
                                     "f 1 5 6\n"
                                     "f 6 5 4 8 7\n");
  MeshReport report;
  const TriMesh mesh = load_mesh(path, &report);
  EXPECT_EQ(report.input_faces, 3);
  EXPECT_EQ(report.triangulated_faces, 2);
  EXPECT_EQ(report.faces, 2 + 1 + 3);
  EXPECT_EQ(static_cast<int>(mesh.n_faces()), report.faces);
  EXPECT_TRUE(report.ok()) << ::testing::PrintToString(report.problems());
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0], "2 faces with more than 3 vertices were triangulated");
  // Triangulated faces expand in place: the triangle "f 1 5 6" comes right after the quad.
  EXPECT_TRUE(face_matches(mesh, mesh.face_handle(2), {0, 4, 5}));
  EXPECT_EQ(report.genus, 0);
  EXPECT_EQ(report.boundary_loops, 1);
}

TEST(Triangulation, RefusedWhenOff) {
  TempDir dir;
  const std::string path = dir.write("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
  LoadMeshOptions options;
  options.triangulate = false;
  MeshReport report;
  const std::string message = error_of([&] { load_mesh(path, &report, options); });
  EXPECT_NE(message.find("1 face with more than 3 vertices (file face 0; line 5)"),
            std::string::npos)
      << message;
  // The polygon loader keeps the quad as it is.
  MeshReport poly_report;
  const PolyMesh poly = load_poly_mesh(path, &poly_report);
  EXPECT_EQ(poly.n_faces(), 1u);
  EXPECT_EQ(poly.valence(poly.face_handle(0)), 4u);
}

// ---------------------------------------------------------------------------------------------
// Precision and other formats

TEST(Precision, ObjCoordinatesRoundTripExactly) {
  TempDir dir;
  const std::string path = dir.write("precise.obj",
                                     "v 1.0000000000001 0.1 -3.3333333333333335\n"
                                     "v 2.2250738585072014e-308 1 0\n"
                                     "v 0.5 0.30000000000000004 12345.678901234567\n"
                                     "f 1 2 3\n");
  MeshReport report;
  const TriMesh mesh = load_mesh(path, &report);
  EXPECT_EQ(mesh.point(mesh.vertex_handle(0)), Vec3(1.0000000000001, 0.1, -3.3333333333333335));
  EXPECT_EQ(mesh.point(mesh.vertex_handle(1))[0], 2.2250738585072014e-308);
  EXPECT_EQ(mesh.point(mesh.vertex_handle(2)), Vec3(0.5, 0.30000000000000004, 12345.678901234567));

  // save_mesh_obj writes every bit; reading its output gives the same doubles and faces.
  const std::string saved = dir.file("saved.obj");
  save_mesh_obj(mesh, saved);
  const TriMesh again = load_mesh(saved);
  ASSERT_EQ(again.n_vertices(), mesh.n_vertices());
  for (auto vh : mesh.vertices()) EXPECT_EQ(again.point(vh), mesh.point(vh));
  EXPECT_TRUE(face_matches(again, again.face_handle(0), {0, 1, 2}));
  // No temporary file is left beside the result.
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(fs::path(saved).parent_path())) {
    files.push_back(entry.path().filename().string());
  }
  std::sort(files.begin(), files.end());
  EXPECT_EQ(files, (std::vector<std::string>{"precise.obj", "saved.obj"}));
}

// A closed octahedron written through OpenMesh's writers.
TriMesh octahedron() {
  TriMesh mesh;
  const Vec3 p[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1.25}};
  std::vector<TriMesh::VertexHandle> v;
  for (const Vec3& q : p) v.push_back(mesh.add_vertex(q));
  const int f[8][3] = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                       {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (const auto& t : f) mesh.add_face(v[t[0]], v[t[1]], v[t[2]]);
  return mesh;
}

void expect_octahedron(const std::string& path) {
  SCOPED_TRACE(path);
  MeshReport report;
  const TriMesh mesh = load_mesh(path, &report);
  const TriMesh reference = octahedron();
  EXPECT_EQ(report.vertices, 6);
  EXPECT_EQ(report.faces, 8);
  EXPECT_EQ(report.edges, 12);
  EXPECT_EQ(report.genus, 0);
  EXPECT_EQ(report.boundary_loops, 0);
  // The coordinates are exact in float, so every format must give them back exactly; STL
  // renumbers vertices (it stores corners), so compare as sets.
  std::set<std::array<double, 3>> got, want;
  for (auto vh : mesh.vertices()) {
    got.insert({mesh.point(vh)[0], mesh.point(vh)[1], mesh.point(vh)[2]});
  }
  for (auto vh : reference.vertices()) {
    want.insert({reference.point(vh)[0], reference.point(vh)[1], reference.point(vh)[2]});
  }
  EXPECT_EQ(got, want);
}

TEST(OpenMeshFormats, PlyStlAndBinaryOffWrittenByOpenMeshReadBack) {
  TempDir dir;
  const TriMesh mesh = octahedron();
  OpenMesh::IO::Options binary(OpenMesh::IO::Options::Binary);
  ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, dir.file("ascii.ply")));
  ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, dir.file("binary.ply"), binary));
  ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, dir.file("ascii.stl")));
  ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, dir.file("binary.stl"), binary));
  ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, dir.file("binary.off"), binary));
  ASSERT_TRUE(OpenMesh::IO::write_mesh(mesh, dir.file("ascii.off")));
  for (const char* name :
       {"ascii.ply", "binary.ply", "ascii.stl", "binary.stl", "binary.off", "ascii.off"}) {
    expect_octahedron(dir.file(name));
  }
}

TEST(OpenMeshFormats, PlyWithDoubleCoordinatesWarnsAboutFloatPrecision) {
  TempDir dir;
  const std::string path = dir.write("double.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property double x\nproperty double y\nproperty double z\n"
                                     "element face 1\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  MeshReport report;
  load_mesh(path, &report);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_NE(report.warnings[0].find("float precision"), std::string::npos);
}

TEST(OpenMeshFormats, PlyFaceWithMissingVertexIsReportedNotDuplicated) {
  // OpenMesh's own importer would add copies of vertices here; the soup keeps raw indices.
  TempDir dir;
  const std::string path = dir.write("bad_index.ply",
                                     "ply\nformat ascii 1.0\nelement vertex 3\n"
                                     "property float x\nproperty float y\nproperty float z\n"
                                     "element face 2\nproperty list uchar int vertex_indices\n"
                                     "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 5\n");
  MeshReport report;
  const std::string message = error_of([&] { load_mesh(path, &report); });
  EXPECT_EQ(report.vertices, 3);
  EXPECT_EQ(report.bad_index_faces, (std::vector<int>{1}));
  EXPECT_NE(message.find("1 face refers to missing vertices (file face 1)"), std::string::npos)
      << message;
}

TEST(OpenMeshFormats, HostileCountsAreRefusedBeforeOpenMeshSeesThem) {
  // OpenMesh's readers trust these counts and would loop for minutes (or forever).
  TempDir dir;
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n";
  const std::string huge_list = dir.write("huge_list.ply", header + "4000000000 0 1 2\n");
  EXPECT_NE(error_of([&] { load_mesh(huge_list); }).find("the file ends in face 0 of 1"),
            std::string::npos);
  const std::string version = dir.write("version.ply", "ply\nformat ascii 2.0\nend_header\n");
  EXPECT_NE(error_of([&] { load_mesh(version); }).find(":2: unsupported PLY version '2.0'"),
            std::string::npos);

  std::string off = "OFF BINARY\n";
  const auto put = [&](std::uint32_t v) {
    for (int k = 0; k < 4; ++k) off += static_cast<char>((v >> (8 * k)) & 0xff);
  };
  put(3), put(1), put(0);
  for (float c : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f}) {
    std::uint32_t bits = 0;
    std::memcpy(&bits, &c, 4);
    put(bits);
  }
  put(0xfffffff0u), put(0), put(1), put(2);
  const std::string huge_face = dir.write("huge_face.off", off);
  EXPECT_NE(error_of([&] { load_mesh(huge_face); }).find("binary OFF data ends in face 0 of 1"),
            std::string::npos);
}

// ---------------------------------------------------------------------------------------------
// The bad-input corpus: every row of assets/bad/README.md about a mesh file.

struct BadFile {
  std::string file;
  std::vector<std::string> words;
};

bool is_mesh_corpus_file(const std::string& name) {
  static const std::set<std::string> kExtensions = {".obj", ".off", ".ply", ".stl", ".vtk"};
  return kExtensions.count(fs::path(name).extension().string()) > 0;
}

std::vector<BadFile> read_bad_corpus_table() {
  std::ifstream in(test::assets_dir() + "/bad/README.md");
  std::vector<BadFile> rows;
  const std::regex backticked("`([^`]+)`");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("| `", 0) != 0) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line.substr(1));
    for (std::string cell; std::getline(ss, cell, '|');) cells.push_back(cell);
    if (cells.size() < 3) continue;
    std::smatch m;
    if (!std::regex_search(cells[0], m, backticked)) continue;
    BadFile row{m[1].str(), {}};
    if (!is_mesh_corpus_file(row.file)) continue;  // bad layouts are tested elsewhere
    const std::string& words = cells[2];
    for (auto it = std::sregex_iterator(words.begin(), words.end(), backticked);
         it != std::sregex_iterator(); ++it) {
      row.words.push_back((*it)[1].str());
    }
    rows.push_back(row);
  }
  return rows;
}

TEST(BadCorpus, EveryFileIsRefusedWithItsWords) {
  const std::vector<BadFile> rows = read_bad_corpus_table();
  ASSERT_GE(rows.size(), 10u) << "assets/bad/README.md table not found or empty";
  std::set<std::string> listed;
  for (const BadFile& row : rows) {
    SCOPED_TRACE(row.file);
    listed.insert(row.file);
    ASSERT_FALSE(row.words.empty());
    const std::string path = test::assets_dir() + "/bad/" + row.file;
    ASSERT_TRUE(fs::exists(path));
    const std::string message = error_of([&] { load_mesh(path); });
    for (const std::string& w : row.words) {
      EXPECT_NE(message.find(w), std::string::npos) << "missing '" << w << "' in:\n" << message;
    }
  }
  // Every mesh file in the folder is described in the table.
  for (const auto& entry : fs::directory_iterator(test::assets_dir() + "/bad")) {
    const std::string name = entry.path().filename().string();
    if (is_mesh_corpus_file(name)) {
      EXPECT_TRUE(listed.count(name)) << name << " not in README";
    }
  }
}

TEST(BadCorpus, PolyLoaderRefusesTheSameMeshFiles) {
  for (const BadFile& row : read_bad_corpus_table()) {
    SCOPED_TRACE(row.file);
    EXPECT_THROW(load_poly_mesh(test::assets_dir() + "/bad/" + row.file), InvalidInputError);
  }
}

// ---------------------------------------------------------------------------------------------
// Real meshes: counts from ../shared/data/SOURCES.md (sections A and B).

struct Published {
  const char* file;
  int vertices;
  int faces;
  int boundary_loops;
  int genus;
};

std::ostream& operator<<(std::ostream& os, const Published& p) {
  return os << p.file;
}

const Published kTriangleMeshes[] = {
    {"fertility.obj", 13971, 27954, 0, 4},
    {"joint.obj", 20902, 41808, 0, 2},
    {"rocker-arm.obj", 10044, 20088, 0, 1},
    {"elephant.obj", 6034, 12064, 0, 0},
    {"face.obj", 25905, 51712, 1, 0},
    {"bunny.off", 34835, 69666, 0, 0},
    {"elk.off", 5194, 10388, 0, 1},
    {"block.off", 2132, 4272, 0, 3},
    {"mask_confmap.obj", 1298, 2428, 3, 0},
    {"3holes.off", 3596, 7200, 0, 3},
    {"spot/spot_triangulated.obj", 2930, 5856, 0, 0},
    {"fandisk/fandisk.off", 7229, 14454, 0, 0},
    {"quadwild_joint/joint_rem_p.obj", 4387, 8778, 0, 2},
    {"inspired_mesh/inspired_mesh.obj", 2244, 4288, 1, 0},
};

const Published kPolygonMeshes[] = {
    {"spot/spot_quadrangulated.obj", 2930, 2928, 0, 0},
    {"spot/spot_control_mesh.obj", 188, 180, 0, 0},
    {"fandisk/fandisk_quads.off", 766, 764, 0, 0},
    {"inspired_mesh/inspired_mesh_quads_Conjugate.off", 1749, 1633, 1, 0},
    {"inspired_mesh/inspired_mesh_quads_Smooth.off", 1963, 1838, 1, 0},
    {"animals_basemesh/cat_cat.obj", 3202, 3200, 0, 0},
    {"animals_basemesh/cow_cow.obj", 3000, 2998, 0, 0},
    {"animals_basemesh/pig_pig.obj", 2302, 2300, 0, 0},
    {"quadwild_joint/joint_rem_p_quadrangulation.obj", 21794, 21796, 0, 2},
};

class SharedTriangleMesh : public ::testing::TestWithParam<Published> {};

TEST_P(SharedTriangleMesh, LoadsWithPublishedCounts) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent: real-mesh tests skipped";
  const Published& p = GetParam();
  const std::string path = dir + "/" + p.file;
  MeshReport report;
  const auto start = std::chrono::steady_clock::now();
  const TriMesh mesh = load_mesh(path, &report);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("[ load time ] %s: %.1f ms (%d faces)\n", p.file, ms, report.faces);
  RecordProperty("load_ms", std::to_string(ms));
  EXPECT_TRUE(report.ok());
  EXPECT_EQ(report.vertices, p.vertices);
  EXPECT_EQ(report.faces, p.faces);
  EXPECT_EQ(report.input_faces, p.faces);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.boundary_loops, p.boundary_loops);
  EXPECT_EQ(report.genus, p.genus);
  EXPECT_EQ(report.euler_characteristic, 2 - 2 * p.genus - p.boundary_loops);
  EXPECT_EQ(static_cast<int>(boundary_loops(mesh).size()), p.boundary_loops);
  // Vertex and face order are the file's: compare with the raw soup.
  const PolygonSoup soup = read_polygon_soup(path);
  ASSERT_EQ(mesh.n_faces(), soup.faces.size());
  for (auto vh : mesh.vertices()) ASSERT_EQ(mesh.point(vh), soup.points[vh.idx()]);
  for (auto fh : mesh.faces()) ASSERT_TRUE(face_matches(mesh, fh, soup.faces[fh.idx()]));
}

INSTANTIATE_TEST_SUITE_P(SourcesSectionAB, SharedTriangleMesh,
                         ::testing::ValuesIn(kTriangleMeshes));

class SharedPolygonMesh : public ::testing::TestWithParam<Published> {};

TEST_P(SharedPolygonMesh, LoadsWithPublishedCounts) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent: real-mesh tests skipped";
  const Published& p = GetParam();
  MeshReport report;
  const PolyMesh mesh = load_poly_mesh(dir + "/" + p.file, &report);
  EXPECT_TRUE(report.ok());
  EXPECT_EQ(report.vertices, p.vertices);
  EXPECT_EQ(report.faces, p.faces);
  EXPECT_EQ(static_cast<int>(mesh.n_faces()), p.faces);
  EXPECT_EQ(report.triangulated_faces, 0);
  EXPECT_EQ(report.components, 1);
  EXPECT_EQ(report.boundary_loops, p.boundary_loops);
  EXPECT_EQ(report.genus, p.genus);
}

INSTANTIATE_TEST_SUITE_P(SourcesSectionB, SharedPolygonMesh, ::testing::ValuesIn(kPolygonMeshes));

TEST(SharedMeshes, QuadMeshTriangulatesToTwiceItsFaces) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent: real-mesh tests skipped";
  // spot_triangulated.obj is spot_quadrangulated.obj with each quad split in two.
  MeshReport report;
  const TriMesh mesh = load_mesh(dir + "/spot/spot_quadrangulated.obj", &report);
  EXPECT_EQ(report.triangulated_faces, 2928);
  EXPECT_EQ(report.faces, 2 * 2928);
  EXPECT_EQ(report.genus, 0);
  ASSERT_EQ(report.warnings.size(), 1u);
  EXPECT_EQ(report.warnings[0], "2928 faces with more than 3 vertices were triangulated");
  EXPECT_EQ(mesh.n_vertices(), 2930u);
}

}  // namespace
}  // namespace qs
