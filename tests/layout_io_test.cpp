// Tests of the layout JSON reader/writer (core/layout/layout_io.h, interfaces.md §1).
#include "core/layout/layout_io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

namespace fs = std::filesystem;

//! n x n vertex grid in the plane z = 0 with unit spacing; vertex (i, j) has index j*n + i.
TriMesh grid_mesh(int n) {
  TriMesh mesh;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) mesh.add_vertex(Vec3(i, j, 0));
  }
  auto vh = [n](int i, int j) { return OpenMesh::VertexHandle(j * n + i); };
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      mesh.add_face(vh(i, j), vh(i + 1, j), vh(i + 1, j + 1));
      mesh.add_face(vh(i, j), vh(i + 1, j + 1), vh(i, j + 1));
    }
  }
  return mesh;
}

void expect_point_eq(const SurfacePoint& a, const SurfacePoint& b, const std::string& what) {
  EXPECT_EQ(a.face, b.face) << what;
  for (int k = 0; k < 3; ++k) EXPECT_EQ(a.bary[k], b.bary[k]) << what << " bary " << k;
}

void expect_points_eq(const std::vector<SurfacePoint>& a, const std::vector<SurfacePoint>& b,
                      const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t k = 0; k < a.size(); ++k)
    expect_point_eq(a[k], b[k], what + "[" + std::to_string(k) + "]");
}

//! Compares every field of two layouts (doubles exactly).
void expect_layout_eq(const Layout& a, const Layout& b) {
  EXPECT_EQ(a.mesh_vertices, b.mesh_vertices);
  EXPECT_EQ(a.mesh_faces, b.mesh_faces);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const LayoutNode& x = a.nodes[i];
    const LayoutNode& y = b.nodes[i];
    const std::string what = "node " + std::to_string(i);
    EXPECT_EQ(x.id, y.id) << what;
    EXPECT_EQ(x.vertex, y.vertex) << what;
    EXPECT_EQ(x.pinned, y.pinned) << what;
    EXPECT_EQ(x.valence, y.valence) << what;
    ASSERT_EQ(x.point.has_value(), y.point.has_value()) << what;
    if (x.point) expect_point_eq(*x.point, *y.point, what + " point");
    ASSERT_EQ(x.position.has_value(), y.position.has_value()) << what;
    if (x.position) {
      EXPECT_EQ(*x.position, *y.position) << what;
    }
  }
  ASSERT_EQ(a.arcs.size(), b.arcs.size());
  for (size_t i = 0; i < a.arcs.size(); ++i) {
    const LayoutArc& x = a.arcs[i];
    const LayoutArc& y = b.arcs[i];
    const std::string what = "arc " + std::to_string(i);
    EXPECT_EQ(x.id, y.id) << what;
    EXPECT_EQ(x.from, y.from) << what;
    EXPECT_EQ(x.to, y.to) << what;
    EXPECT_EQ(x.path, y.path) << what;
    EXPECT_EQ(x.pinned, y.pinned) << what;
    EXPECT_EQ(x.label, y.label) << what;
    EXPECT_EQ(x.polyline, y.polyline) << what;
    expect_points_eq(x.points, y.points, what + " points");
    expect_points_eq(x.samples, y.samples, what + " samples");
  }
  EXPECT_EQ(a.feature_edges, b.feature_edges);
  ASSERT_EQ(a.patches.size(), b.patches.size());
  for (size_t i = 0; i < a.patches.size(); ++i) {
    EXPECT_EQ(a.patches[i].id, b.patches[i].id);
    EXPECT_EQ(a.patches[i].nodes, b.patches[i].nodes);
    EXPECT_EQ(a.patches[i].arcs, b.patches[i].arcs);
    EXPECT_EQ(a.patches[i].size, b.patches[i].size);
  }
}

//! A layout using every field kind, with doubles that only round-trip at full precision.
Layout full_layout() {
  Layout x;
  x.mesh_vertices = 100;
  x.mesh_faces = 162;

  LayoutNode n0;
  n0.id = 0;
  n0.vertex = 17;
  n0.pinned = true;
  LayoutNode n1;  // snapped point node with output fields
  n1.id = 1;
  n1.vertex = 40;
  n1.point = SurfacePoint{12, {{0.2, 0.3, 0.5}}};
  n1.position = std::array<double, 3>{{0.1, 1.0 / 3.0, -2.5e300}};
  n1.valence = 5;
  LayoutNode n7;  // point only (not snapped yet)
  n7.id = 7;
  n7.point = SurfacePoint{3, {{1.0 / 3.0, 1.0 / 3.0, 1.0 - 2.0 / 3.0}}};
  x.nodes = {n0, n1, n7};

  LayoutArc a0;  // path arc with output fields
  a0.id = 0;
  a0.from = 0;
  a0.to = 1;
  a0.path = {17, 18, 40};
  a0.pinned = true;
  a0.label = "u";
  a0.polyline = {
      {{0.0, 0.0, 0.0}}, {{0.1, 0.2, 0.1 + 0.2}}, {{5e-324, -1e-300, 1.7976931348623157e308}}};
  a0.samples = {SurfacePoint{1, {{1.0, 0.0, 0.0}}}, SurfacePoint{2, {{0.5, 0.5, 0.0}}}};
  LayoutArc a3;  // points arc
  a3.id = 3;
  a3.from = 1;
  a3.to = 7;
  a3.points = {SurfacePoint{12, {{0.2, 0.3, 0.5}}}, SurfacePoint{13, {{0.0, 0.5, 0.5}}}};
  LayoutArc a2;  // dangling path arc
  a2.id = 2;
  a2.from = 7;
  a2.to = -1;
  a2.path = {90, 91, 92};
  a2.label = "v";
  x.arcs = {a0, a3, a2};

  x.feature_edges = {{{3, 4}}, {{4, 9}}};
  LayoutPatch p0;
  p0.id = 0;
  p0.nodes = {0, 1, 7, 0};
  p0.arcs = {0, 3, 2};
  p0.size = {{2.5, 1e-3}};
  LayoutPatch p1;
  p1.id = 1;
  x.patches = {p0, p1};
  return x;
}

//! The example of interfaces.md §1, verbatim.
const char* const kInterfacesExample = R"({
  "format": "quadsketch-layout",
  "version": 1,
  "mesh": {"vertices": 2930, "faces": 5856},
  "nodes": [
    {"id": 0, "vertex": 17, "pinned": false},
    {"id": 1, "point": {"face": 12, "bary": [0.2, 0.3, 0.5]}}
  ],
  "arcs": [
    {"id": 0, "from": 0, "to": 1, "path": [17, 18, 40, 41], "pinned": false},
    {"id": 1, "from": 1, "to": 2, "points": [{"face": 12, "bary": [0.2, 0.3, 0.5]}]},
    {"id": 2, "from": 2, "to": null, "path": [90, 91, 92]}
  ],
  "features": {"edges": [[3, 4], [4, 9]]}
})";

//! Expects parse_layout_json(text) to throw InvalidInputError containing every substring.
void expect_parse_error(const std::string& text, const std::vector<std::string>& substrings) {
  try {
    parse_layout_json(text, "layout.json");
    ADD_FAILURE() << "no error for:\n" << text;
  } catch (const InvalidInputError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.rfind("layout.json: ", 0), 0u) << msg;
    for (const std::string& s : substrings) {
      EXPECT_NE(msg.find(s), std::string::npos) << "'" << s << "' not in: " << msg;
    }
  }
}

//! A valid document with one node and one arc, where \p node and \p arc replace the defaults.
std::string doc(const std::string& node = R"({"id": 0, "vertex": 1})",
                const std::string& arc = R"({"id": 0, "from": 0, "to": null, "path": [1, 2]})",
                const std::string& head = R"("format": "quadsketch-layout", "version": 1)") {
  return "{" + head + ",\n\"nodes\": [" + node + "],\n\"arcs\": [" + arc + "]}";
}

TEST(LayoutIo, InterfacesExampleParses) {
  const Layout x = parse_layout_json(kInterfacesExample, "example.json");
  EXPECT_EQ(x.mesh_vertices, 2930);
  EXPECT_EQ(x.mesh_faces, 5856);
  ASSERT_EQ(x.nodes.size(), 2u);
  EXPECT_EQ(x.nodes[0].id, 0);
  EXPECT_EQ(x.nodes[0].vertex, 17);
  EXPECT_FALSE(x.nodes[0].pinned);
  EXPECT_FALSE(x.nodes[0].point.has_value());
  EXPECT_EQ(x.nodes[1].id, 1);
  EXPECT_EQ(x.nodes[1].vertex, -1);  // snapped by load_layout
  ASSERT_TRUE(x.nodes[1].point.has_value());
  EXPECT_EQ(x.nodes[1].point->face, 12);
  EXPECT_EQ(x.nodes[1].point->bary, (std::array<double, 3>{{0.2, 0.3, 0.5}}));
  ASSERT_EQ(x.arcs.size(), 3u);
  EXPECT_EQ(x.arcs[0].path, (std::vector<int>{17, 18, 40, 41}));
  EXPECT_EQ(x.arcs[0].to, 1);
  EXPECT_TRUE(x.arcs[1].path.empty());
  ASSERT_EQ(x.arcs[1].points.size(), 1u);
  EXPECT_EQ(x.arcs[1].points[0].face, 12);
  EXPECT_TRUE(x.arcs[2].dangling());
  EXPECT_EQ(x.arcs[2].path, (std::vector<int>{90, 91, 92}));
  EXPECT_EQ(x.feature_edges, (std::vector<std::array<int, 2>>{{{3, 4}}, {{4, 9}}}));
  EXPECT_TRUE(x.patches.empty());

  const Layout again = parse_layout_json(layout_to_json(x), "again.json");
  expect_layout_eq(again, x);
}

TEST(LayoutIo, InterfacesDocumentExampleParses) {
  // The example as it stands in the shared interfaces.md (skipped when the docs are absent).
  const fs::path md = fs::path(QS_SHARED_DIR) / "docs" / "interfaces.md";
  if (!fs::exists(md)) GTEST_SKIP() << md << " not found";
  const std::string text = read_file(md.string());
  const size_t start = text.find("```json\n");
  ASSERT_NE(start, std::string::npos);
  const size_t end = text.find("```", start + 8);
  ASSERT_NE(end, std::string::npos);
  const std::string json = text.substr(start + 8, end - start - 8);
  const Layout x = parse_layout_json(json, "interfaces.md");
  expect_layout_eq(x, parse_layout_json(kInterfacesExample));
}

TEST(LayoutIo, RoundTripIsLossless) {
  const Layout x = full_layout();
  const std::string text = layout_to_json(x);
  const Layout y = parse_layout_json(text, "roundtrip.json");
  expect_layout_eq(y, x);
  // parse(write(parse(x))) == parse(x), and the text is stable.
  const std::string text2 = layout_to_json(y);
  EXPECT_EQ(text2, text);
  expect_layout_eq(parse_layout_json(text2), y);
}

TEST(LayoutIo, WriterKeyOrderAndShape) {
  const std::string text = layout_to_json(full_layout());
  const std::vector<std::string> keys = {"\"format\": \"quadsketch-layout\"",
                                         "\"version\": 1",
                                         "\"mesh\": {\"vertices\": 100, \"faces\": 162}",
                                         "\"nodes\"",
                                         "\"arcs\"",
                                         "\"features\": {\"edges\": [[3, 4], [4, 9]]}",
                                         "\"patches\""};
  size_t last = 0;
  for (const std::string& k : keys) {
    const size_t at = text.find(k);
    ASSERT_NE(at, std::string::npos) << k << "\n" << text;
    EXPECT_GT(at, last) << k;
    last = at;
  }
  // One node per line, keys in the order of interfaces.md.
  EXPECT_NE(text.find("    {\"id\": 0, \"vertex\": 17, \"pinned\": true},\n"), std::string::npos)
      << text;
  EXPECT_NE(text.find("{\"id\": 1, \"vertex\": 40, \"point\": {\"face\": 12, \"bary\": [0.2, 0.3, "
                      "0.5]}, \"pinned\": false, \"position\": [0.1, 0.3333333333333333, "
                      "-2.5e+300], \"valence\": 5}"),
            std::string::npos)
      << text;
  // A point-only node has no vertex; a dangling arc has "to": null; a points arc has no path.
  EXPECT_NE(text.find("{\"id\": 7, \"point\": {"), std::string::npos) << text;
  EXPECT_NE(text.find("{\"id\": 2, \"from\": 7, \"to\": null, \"path\": [90, 91, 92], "
                      "\"pinned\": false, \"label\": \"v\"}"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("{\"id\": 3, \"from\": 1, \"to\": 7, \"points\": [{\"face\": 12"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("{\"id\": 0, \"nodes\": [0, 1, 7, 0], \"arcs\": [0, 3, 2], \"size\": [2.5, "
                      "0.001]}"),
            std::string::npos)
      << text;
}

TEST(LayoutIo, WriterOmitsEmptyOptionalBlocks) {
  Layout x;
  const std::string text = layout_to_json(x);
  EXPECT_EQ(text.find("\"mesh\""), std::string::npos) << text;
  EXPECT_EQ(text.find("\"features\""), std::string::npos) << text;
  EXPECT_EQ(text.find("\"patches\""), std::string::npos) << text;
  EXPECT_NE(text.find("\"nodes\": []"), std::string::npos) << text;
  expect_layout_eq(parse_layout_json(text), x);

  // The mesh given to the writer wins over the layout's counts.
  const TriMesh mesh = grid_mesh(4);
  x.mesh_vertices = 5;
  x.mesh_faces = 6;
  EXPECT_NE(layout_to_json(x, &mesh).find("\"mesh\": {\"vertices\": 16, \"faces\": 18}"),
            std::string::npos);
}

TEST(LayoutIo, RoutedArcIsWrittenWithItsPathOnly) {
  Layout x = full_layout();
  x.arcs[1].path = {40, 41};  // routed: path supersedes points
  const Layout y = parse_layout_json(layout_to_json(x));
  EXPECT_EQ(y.arcs[1].path, (std::vector<int>{40, 41}));
  EXPECT_TRUE(y.arcs[1].points.empty());
}

TEST(LayoutIo, WriterNeverCrashesOnOutOfRangeData) {
  Layout x;
  LayoutNode n;
  n.id = 3;
  n.vertex = 1 << 30;
  x.nodes = {n};
  LayoutArc a;
  a.id = 4;
  a.from = 99;
  a.to = -7;
  a.path = {-3, 1 << 30};
  a.points = {SurfacePoint{-5, {{0.0, 0.0, 0.0}}}};
  x.arcs = {a};
  x.feature_edges = {{{-1, 1 << 30}}};
  const std::string text = layout_to_json(x);
  EXPECT_NE(text.find("[-3, 1073741824]"), std::string::npos) << text;
  // Negative indices are written faithfully, and the reader rejects them with a location.
  expect_parse_error(text, {"arcs[0].path[0]", ">= 0, got number -3"});
}

TEST(LayoutIo, WriterRejectsNonFiniteNumbers) {
  Layout x = full_layout();
  x.nodes[1].position = std::array<double, 3>{{0.0, std::nan(""), 0.0}};
  try {
    layout_to_json(x);
    ADD_FAILURE() << "no error";
  } catch (const QsError& e) {
    EXPECT_NE(std::string(e.what()).find("node 1 position"), std::string::npos) << e.what();
  }
}

TEST(LayoutIo, NodeWithVertexAndPointKeepsVertex) {
  const Layout x =
      parse_layout_json(doc(R"({"id": 0, "vertex": 5, "point": {"face": 1, "bary": [1, 0, 0]}})"));
  EXPECT_EQ(x.nodes[0].vertex, 5);
  ASSERT_TRUE(x.nodes[0].point.has_value());
  EXPECT_EQ(x.nodes[0].point->face, 1);
}

TEST(LayoutIo, LeadingByteOrderMarkIsSkipped) {
  const Layout x = parse_layout_json("\xEF\xBB\xBF" + doc(), "bom.json");
  ASSERT_EQ(x.nodes.size(), 1u);
  EXPECT_EQ(x.nodes[0].vertex, 1);
  // Error columns on the first line count from the first visible character.
  expect_parse_error("\xEF\xBB\xBF{x}", {"malformed JSON at line 1, column 2: "});
}

TEST(LayoutIo, IgnoresUnknownFieldsAndAcceptsIntegralNumbers) {
  const Layout x = parse_layout_json(
      doc(R"({"id": 0, "vertex": 17.0, "color": "red"})",
          R"({"id": 0, "from": 0, "to": null, "path": [1, 2], "comment": {"a": [1]}})",
          R"("format": "quadsketch-layout", "version": 1, "generator": "test", "extra": [1, 2])"));
  EXPECT_EQ(x.nodes[0].vertex, 17);
  EXPECT_EQ(x.arcs[0].path, (std::vector<int>{1, 2}));
}

TEST(LayoutIo, MalformedJsonReportsLineAndColumn) {
  expect_parse_error("{\n  \"format\": \"quadsketch-layout\",\n  \"version\": 1x\n}",
                     {"layout.json: malformed JSON at line 3, column 15: "});
  expect_parse_error("{\n  \"format\": \"quadsketch-layout\",\n  \"nodes\": [,]\n}",
                     {"malformed JSON at line 3, column 13: ", "syntax error"});
  // Columns count characters, not bytes (two 2-byte characters before the error).
  expect_parse_error("{\"é\": 1,\n\"ü\": x}", {"malformed JSON at line 2, column 6: "});
  expect_parse_error("", {"malformed JSON at line 1, column 1: "});
  // Unexpected end of input: the position after the last character.
  expect_parse_error("{\n  \"nodes\": [",
                     {"malformed JSON at line 2, column 13: ", "end of input"});
  // nlohmann reports no position for an overflow; the literal is located.
  expect_parse_error("{\n  \"version\": 1e400\n}",
                     {"malformed JSON at line 2, column 14: ", "1e400"});
}

TEST(LayoutIo, WrongTypesNameTheLocation) {
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})",
          R"({"id": 0, "from": 0, "to": 1, "path": [1, 2]},
                            {"id": 1, "from": 0, "to": 1, "path": [1, 2]},
                            {"id": 2, "from": 0, "to": 1, "path": [1, 2]},
                            {"id": 3, "from": 0, "to": 1, "path": [1, 2, "x"]})"),
      {"layout.json: arcs[3].path[2]: expected an integer vertex index, got string"});
  expect_parse_error(doc(R"({"id": "a", "vertex": 1})"),
                     {"nodes[0].id: expected an integer id, got string"});
  expect_parse_error(doc(R"({"id": -1, "vertex": 1})"),
                     {"nodes[0].id: expected an integer id >= 0, got number -1"});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1.5})"),
                     {"nodes[0].vertex: expected an integer vertex index, got number 1.5"});
  expect_parse_error(doc(R"({"id": 0, "vertex": 3000000000})"), {"nodes[0].vertex", "too large"});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1, "pinned": "yes"})"),
                     {"nodes[0].pinned: expected true or false, got string"});
  expect_parse_error(doc(R"({"id": 0, "point": {"face": 1, "bary": [0.5, 0.5]}})"),
                     {"nodes[0].point.bary: expected an array of 3 numbers, got an array of 2"});
  expect_parse_error(doc(R"({"id": 0, "point": {"face": 1, "bary": [0.5, 0.5, null]}})"),
                     {"nodes[0].point.bary[2]: expected a number, got null"});
  expect_parse_error(doc(R"({"id": 0, "point": {"bary": [0.5, 0.5, 0]}})"),
                     {"nodes[0].point: missing required field \"face\""});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1, "position": [0, 0, true]})"),
                     {"nodes[0].position[2]: expected a number, got boolean true"});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1, "valence": -2})"),
                     {"nodes[0].valence: expected an integer valence >= 0"});
  expect_parse_error(doc(R"({"id": 0})"), {"nodes[0]: a node needs \"vertex\" or \"point\""});
  expect_parse_error(doc(R"(17)"), {"nodes[0]: expected an object, got number 17"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": "1", "path": []})"),
      {"arcs[0].to: expected an integer node id (or null for a dangling arc), got "
       "string"});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1})",
                         R"({"id": 0, "from": 0, "to": 1, "path": [1], "label": "w"})"),
                     {"arcs[0].label: expected \"u\" or \"v\", got \"w\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})",
          R"({"id": 0, "from": 0, "to": 1, "path": [1], "polyline": [[0, 0, 0], [1, 2]]})"),
      {"arcs[0].polyline[1]: expected an array of 3 numbers"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})",
          R"({"id": 0, "from": 0, "to": 1, "path": [1], "samples": [{"face": 1, "bary": 3}]})"),
      {"arcs[0].samples[0].bary: expected an array of 3 numbers, got number 3"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": 1, "path": 5})"),
      {"arcs[0].path: expected an array, got number 5"});
  expect_parse_error(R"({"format": "quadsketch-layout", "version": 1, "nodes": {}, "arcs": []})",
                     {"nodes: expected an array, got object"});
  expect_parse_error(R"({"format": "quadsketch-layout", "version": 1, "nodes": []})",
                     {"missing required field \"arcs\""});
  expect_parse_error(R"([1, 2])", {"expected a JSON object at the top level, got array"});
}

TEST(LayoutIo, DefaultDocumentIsValid) {
  EXPECT_NO_THROW(parse_layout_json(doc()));
}

TEST(LayoutIo, ArcRequirements) {
  expect_parse_error(doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "to": 1, "path": [1, 2]})"),
                     {"layout.json: arcs[0]: missing required field \"from\""});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "path": [1, 2]})"),
                     {"arcs[0]: missing required field \"to\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})",
          R"({"id": 0, "from": 0, "to": 1, "path": [1, 2], "points": [{"face": 0, "bary": [1, 0, 0]}]})"),
      {"arcs[0]: an arc has either \"path\" or \"points\", not both"});
  expect_parse_error(doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": 1})"),
                     {"arcs[0]: an arc needs \"path\" or \"points\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": 1, "points": []})"),
      {"arcs[0].points: expected at least one surface point"});
}

TEST(LayoutIo, FormatAndVersion) {
  expect_parse_error(doc(R"({"id": 0, "vertex": 1})",
                         R"({"id": 0, "from": 0, "to": null, "path": []})", R"("version": 1)"),
                     {"layout.json: missing \"format\": \"quadsketch-layout\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          R"("format": "obj", "version": 1)"),
      {"layout.json: format: expected \"quadsketch-layout\", got \"obj\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          R"("format": 3, "version": 1)"),
      {"format: expected \"quadsketch-layout\", got number 3"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          R"("format": "quadsketch-layout", "version": 2)"),
      {"layout.json: version: unsupported version 2"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          R"("format": "quadsketch-layout", "version": "1")"),
      {"version: unsupported version \"1\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          R"("format": "quadsketch-layout")"),
      {"missing \"version\": 1"});
}

TEST(LayoutIo, MeshFeaturesAndPatchesBlocks) {
  const std::string head = R"("format": "quadsketch-layout", "version": 1, )";
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          head + R"("mesh": {"vertices": 10})"),
      {"mesh: missing required field \"faces\""});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          head + R"("mesh": {"vertices": 10, "faces": "many"})"),
      {"mesh.faces: expected an integer face count, got string"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          head + R"("features": {"edges": [[1, 2], [3]]})"),
      {"features.edges[1]: expected a pair of vertex indices"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          head + R"("features": [])"),
      {"features: expected an object, got array"});
  expect_parse_error(
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": []})",
          head + R"("patches": [{"id": 0, "nodes": [0, 1, 2, 3], "arcs": [0, "1"]}])"),
      {"patches[0].arcs[1]: expected an integer arc id, got string"});
  // An empty features object is fine.
  EXPECT_NO_THROW(parse_layout_json(doc(R"({"id": 0, "vertex": 1})",
                                        R"({"id": 0, "from": 0, "to": null, "path": []})",
                                        head + R"("features": {})")));
}

TEST(LayoutIo, DuplicateIdsAreStoredFaithfully) {
  const Layout x = parse_layout_json(doc(R"({"id": 4, "vertex": 1}, {"id": 4, "vertex": 2})"));
  ASSERT_EQ(x.nodes.size(), 2u);
  EXPECT_EQ(x.nodes[0].id, 4);
  EXPECT_EQ(x.nodes[1].id, 4);
  EXPECT_EQ(x.nodes[1].vertex, 2);
}

//! Temporary folder for files of one test.
class LayoutFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("qs_layout_io_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) const {
    const std::string path = (dir_ / name).string();
    write_file_atomic(path, text);
    return path;
  }

  //! Expects load_layout to throw InvalidInputError containing every substring.
  static void expect_load_error(const std::string& path, const TriMesh& mesh,
                                const std::vector<std::string>& substrings) {
    try {
      load_layout(path, mesh);
      ADD_FAILURE() << "no error for " << path;
    } catch (const InvalidInputError& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.rfind(path + ": ", 0), 0u) << msg;
      for (const std::string& s : substrings) {
        EXPECT_NE(msg.find(s), std::string::npos) << "'" << s << "' not in: " << msg;
      }
    }
  }

  fs::path dir_;
};

TEST_F(LayoutFileTest, MeshBlockMustMatch) {
  const TriMesh mesh = grid_mesh(10);  // 100 vertices, 162 faces
  const std::string path = write(
      "layout.json",
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": [1, 0]})",
          R"("format": "quadsketch-layout", "version": 1, "mesh": {"vertices": 2930, "faces": 5856})"));
  expect_load_error(path, mesh,
                    {"layout.json: mesh block says 2930 vertices / 5856 faces but the mesh has "
                     "100 / 162"});
  // Matching counts load.
  const std::string ok = write(
      "ok.json",
      doc(R"({"id": 0, "vertex": 1})", R"({"id": 0, "from": 0, "to": null, "path": [1, 0]})",
          R"("format": "quadsketch-layout", "version": 1, "mesh": {"vertices": 100, "faces": 162})"));
  const Layout x = load_layout(ok, mesh);
  EXPECT_EQ(x.mesh_vertices, 100);
  EXPECT_EQ(x.mesh_faces, 162);
}

TEST_F(LayoutFileTest, UnreadableAndMalformedFilesNameThePath) {
  const TriMesh mesh = grid_mesh(3);
  const std::string missing = (dir_ / "missing.json").string();
  try {
    load_layout(missing, mesh);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  const std::string bad = write("bad.json", "{\n\"format\": }");
  expect_load_error(bad, mesh, {"malformed JSON at line 2, column 11"});
}

TEST_F(LayoutFileTest, OnlyRegularFilesOfBoundedSizeAreRead) {
  const TriMesh mesh = grid_mesh(3);
  const std::string folder = (dir_ / "folder.json").string();
  fs::create_directories(folder);
  expect_load_error(folder, mesh, {"cannot open file: it is a directory, not a regular file"});
  expect_load_error("/dev/zero", mesh, {"it is a character device, not a regular file"});
  // A sparse file just over the limit is refused from its size, before anything is read.
  const std::string huge = write("huge.json", "{}");
  fs::resize_file(huge, kMaxLayoutFileBytes + 1);
  expect_load_error(huge, mesh,
                    {"file too large: " + std::to_string(kMaxLayoutFileBytes + 1) +
                     " bytes (the limit is " + std::to_string(kMaxLayoutFileBytes) + " bytes)"});
}

TEST_F(LayoutFileTest, NodeWithAVertexAndAPointElsewhereIsRefused) {
  const TriMesh mesh = grid_mesh(10);
  std::vector<int> corners;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(20))) corners.push_back(vh.idx());
  // Node 4's point is at corner 0 of face 20, its vertex is 88: one of them would be ignored.
  const std::string path =
      write("both.json", doc(R"({"id": 4, "vertex": 88, "point": {"face": 20, "bary": [1, 0, 0]}})",
                             R"({"id": 0, "from": 4, "to": null, "path": [88, 89]})"));
  expect_load_error(path, mesh,
                    {"node 4: has both \"vertex\": 88 and a \"point\" that snaps to vertex " +
                     std::to_string(corners[0])});
  // A point that snaps to the node's vertex (as written for snapped and output nodes) is fine.
  const std::string agree = write(
      "agree.json",
      doc(R"({"id": 4, "vertex": )" + std::to_string(corners[1]) +
              R"(, "point": {"face": 20, "bary": [0.1, 0.8, 0.1]}})",
          R"({"id": 0, "from": 4, "to": null, "path": [)" + std::to_string(corners[1]) + "]}"));
  const Layout x = load_layout(agree, mesh);
  EXPECT_EQ(x.nodes[0].vertex, corners[1]);
}

TEST_F(LayoutFileTest, NodeProblemsAreAllListedWithIds) {
  const TriMesh mesh = grid_mesh(10);
  const std::string path =
      write("nodes.json",
            doc(R"({"id": 5, "vertex": 100}, {"id": 6, "vertex": 250},
             {"id": 7, "point": {"face": 500, "bary": [1, 0, 0]}},
             {"id": 8, "point": {"face": 2, "bary": [0.5, 0.5, 0.5]}},
             {"id": 9, "point": {"face": 2, "bary": [1.1, -0.1, 0]}})",
                R"({"id": 3, "from": 5, "to": 6, "points": [{"face": 1000, "bary": [1, 0, 0]}]})"));
  expect_load_error(
      path, mesh,
      {"node 5: vertex 100 out of range (mesh has 100 vertices)", "node 6: vertex 250 out of range",
       "node 7: point: face 500 out of range (mesh has 162 faces)",
       "node 8: point: barycentric coordinates sum to 1.5",
       "node 9: point: barycentric coordinate -0.1", "arc 3: points[0]: face 1000"});
}

TEST_F(LayoutFileTest, PointNodeIsSnappedAndSaveLoadRoundTrips) {
  const TriMesh mesh = grid_mesh(10);
  std::vector<int> corners;
  for (const auto vh : mesh.fv_range(OpenMesh::FaceHandle(20))) corners.push_back(vh.idx());
  const std::string path = write(
      "points.json",
      doc(R"({"id": 0, "point": {"face": 20, "bary": [0.1, 0.2, 0.7]}}, {"id": 1, "vertex": 88})",
          R"({"id": 0, "from": 0, "to": 1, "points": [{"face": 100, "bary": [0.2, 0.6, 0.2]}]})"));
  const Layout x = load_layout(path, mesh);
  EXPECT_EQ(x.nodes[0].vertex, corners[2]);
  ASSERT_TRUE(x.nodes[0].point.has_value());
  ASSERT_GE(x.arcs[0].path.size(), 2u);
  EXPECT_EQ(x.arcs[0].path.front(), corners[2]);
  EXPECT_EQ(x.arcs[0].path.back(), 88);

  // The writer's output is a valid input: saving and loading again gives the same layout
  // (the routed arc is stored by its path).
  const std::string saved = (dir_ / "saved.json").string();
  save_layout(x, saved, &mesh);
  const Layout y = load_layout(saved, mesh);
  Layout expected = x;
  expected.mesh_vertices = 100;
  expected.mesh_faces = 162;
  expected.arcs[0].points.clear();
  expect_layout_eq(y, expected);
}

TEST_F(LayoutFileTest, OutOfRangePathsAreLeftToTheValidator) {
  const TriMesh mesh = grid_mesh(4);
  const std::string path = write(
      "paths.json",
      doc(R"({"id": 0, "vertex": 1}, {"id": 1, "vertex": 2})",
          R"({"id": 0, "from": 0, "to": 1, "path": [1, 99999, 2]},
             {"id": 1, "from": 0, "to": 1, "path": [1, 7, 2, 3, 12]},
             {"id": 2, "from": 1, "to": 0, "path": []})",
          R"("format": "quadsketch-layout", "version": 1, "features": {"edges": [[1, 123456]]})"));
  const Layout x = load_layout(path, mesh);
  EXPECT_EQ(x.arcs[0].path, (std::vector<int>{1, 99999, 2}));
  EXPECT_EQ(x.arcs[1].path, (std::vector<int>{1, 7, 2, 3, 12}));
  EXPECT_TRUE(x.arcs[2].path.empty());
  EXPECT_EQ(x.feature_edges[0][1], 123456);
}

}  // namespace
}  // namespace qs
