#include "core/layout/layout_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string_view>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/base/input_file.h"
#include "core/layout/routing.h"

namespace qs {

namespace {

using Json = nlohmann::json;
using OrderedJson = nlohmann::ordered_json;

constexpr const char* kFormat = "quadsketch-layout";
constexpr int kVersion = 1;

// ---------------------------------------------------------------------------------------------
// Reading
// ---------------------------------------------------------------------------------------------

//! 1-based line and column (in characters, counting a UTF-8 sequence once) of byte offset
//! \p offset (0-based) of \p text. Offsets past the end refer to the position after the text.
std::pair<int, int> line_column(std::string_view text, size_t offset) {
  offset = std::min(offset, text.size());
  int line = 1;
  int column = 1;
  for (size_t i = 0; i < offset; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == '\n') {
      ++line;
      column = 1;
    } else if ((c & 0xC0) != 0x80) {  // not a UTF-8 continuation byte
      ++column;
    }
  }
  return {line, column};
}

//! The explanation part of a nlohmann exception message, without the "[json.exception...]"
//! prefix and without nlohmann's own position (we compute ours).
std::string json_error_detail(const std::string& what) {
  std::string s = what;
  const size_t bracket = s.find("] ");
  if (s.rfind("[json.exception.", 0) == 0 && bracket != std::string::npos)
    s = s.substr(bracket + 2);
  if (s.rfind("parse error", 0) == 0) {
    const size_t colon = s.find(": ");
    if (colon != std::string::npos) s = s.substr(colon + 2);
  }
  return s;
}

//! Short description of a JSON value for "got ..." messages.
std::string describe(const Json& v) {
  if (v.is_number()) return "number " + v.dump();
  if (v.is_boolean()) return std::string("boolean ") + (v.get<bool>() ? "true" : "false");
  return v.type_name();
}

//! Reads the parsed JSON document into a Layout, with precise error locations.
class LayoutReader {
 public:
  explicit LayoutReader(std::string source) : source_(std::move(source)) {}

  Layout read(const Json& doc) {
    if (!doc.is_object()) fail("", "expected a JSON object at the top level, got " + describe(doc));
    read_header(doc);
    Layout layout;
    if (const Json* mesh = find(doc, "mesh")) read_mesh_block(*mesh, layout);
    const Json& nodes = require(doc, "", "nodes");
    expect_array(nodes, "nodes");
    layout.nodes.reserve(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
      layout.nodes.push_back(read_node(nodes[i], index_path("nodes", i)));
    }
    const Json& arcs = require(doc, "", "arcs");
    expect_array(arcs, "arcs");
    layout.arcs.reserve(arcs.size());
    for (size_t i = 0; i < arcs.size(); ++i) {
      layout.arcs.push_back(read_arc(arcs[i], index_path("arcs", i)));
    }
    if (const Json* features = find(doc, "features")) read_features(*features, layout);
    if (const Json* patches = find(doc, "patches")) {
      expect_array(*patches, "patches");
      for (size_t i = 0; i < patches->size(); ++i) {
        layout.patches.push_back(read_patch((*patches)[i], index_path("patches", i)));
      }
    }
    return layout;
  }

 private:
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw InvalidInputError(source_ + ": " + (where.empty() ? "" : where + ": ") + what);
  }

  static std::string index_path(const std::string& base, size_t i) {
    return base + "[" + std::to_string(i) + "]";
  }
  static std::string field_path(const std::string& base, const char* key) {
    return base.empty() ? std::string(key) : base + "." + key;
  }

  //! The member \p key of object \p obj, or nullptr when absent.
  static const Json* find(const Json& obj, const char* key) {
    const auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
  }

  const Json& require(const Json& obj, const std::string& where, const char* key) const {
    const Json* v = find(obj, key);
    if (!v) fail(where, std::string("missing required field \"") + key + "\"");
    return *v;
  }

  void expect_object(const Json& v, const std::string& where) const {
    if (!v.is_object()) fail(where, "expected an object, got " + describe(v));
  }
  void expect_array(const Json& v, const std::string& where) const {
    if (!v.is_array()) fail(where, "expected an array, got " + describe(v));
  }

  //! An integer that fits an int. Integral floating-point values (e.g. 17.0) are accepted.
  int read_int(const Json& v, const std::string& where, const std::string& what,
               bool non_negative) const {
    int64_t value = 0;
    if (v.is_number_unsigned()) {
      const auto u = v.get<uint64_t>();
      if (u > static_cast<uint64_t>(std::numeric_limits<int>::max())) {
        fail(where, "expected " + what + ", got " + describe(v) + " (too large)");
      }
      value = static_cast<int64_t>(u);
    } else if (v.is_number_integer()) {
      value = v.get<int64_t>();
    } else if (v.is_number_float()) {
      const double d = v.get<double>();
      if (!(std::isfinite(d) && std::floor(d) == d)) {
        fail(where, "expected " + what + ", got " + describe(v));
      }
      if (std::fabs(d) > static_cast<double>(std::numeric_limits<int>::max())) {
        fail(where, "expected " + what + ", got " + describe(v) + " (too large)");
      }
      value = static_cast<int64_t>(d);
    } else {
      fail(where, "expected " + what + ", got " + describe(v));
    }
    if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max()) {
      fail(where, "expected " + what + ", got " + describe(v) + " (too large)");
    }
    if (non_negative && value < 0) fail(where, "expected " + what + " >= 0, got " + describe(v));
    return static_cast<int>(value);
  }

  double read_double(const Json& v, const std::string& where) const {
    if (!v.is_number()) fail(where, "expected a number, got " + describe(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(where, "expected a finite number, got " + describe(v));
    return d;
  }

  bool read_bool(const Json& v, const std::string& where) const {
    if (!v.is_boolean()) fail(where, "expected true or false, got " + describe(v));
    return v.get<bool>();
  }

  template <size_t N>
  std::array<double, N> read_doubles(const Json& v, const std::string& where) const {
    if (!v.is_array() || v.size() != N) {
      fail(where, "expected an array of " + std::to_string(N) + " numbers, got " +
                      (v.is_array() ? "an array of " + std::to_string(v.size()) + " elements"
                                    : describe(v)));
    }
    std::array<double, N> out{};
    for (size_t k = 0; k < N; ++k) out[k] = read_double(v[k], index_path(where, k));
    return out;
  }

  std::vector<int> read_int_list(const Json& v, const std::string& where,
                                 const std::string& what) const {
    expect_array(v, where);
    std::vector<int> out;
    out.reserve(v.size());
    for (size_t k = 0; k < v.size(); ++k) {
      out.push_back(read_int(v[k], index_path(where, k), what, true));
    }
    return out;
  }

  SurfacePoint read_surface_point(const Json& v, const std::string& where) const {
    expect_object(v, where);
    SurfacePoint p;
    p.face = read_int(require(v, where, "face"), field_path(where, "face"), "an integer face index",
                      true);
    p.bary = read_doubles<3>(require(v, where, "bary"), field_path(where, "bary"));
    return p;
  }

  std::vector<SurfacePoint> read_surface_points(const Json& v, const std::string& where) const {
    expect_array(v, where);
    std::vector<SurfacePoint> out;
    out.reserve(v.size());
    for (size_t k = 0; k < v.size(); ++k)
      out.push_back(read_surface_point(v[k], index_path(where, k)));
    return out;
  }

  void read_header(const Json& doc) const {
    const Json* format = find(doc, "format");
    if (!format) {
      fail("", std::string("missing \"format\": \"") + kFormat +
                   "\" (is this a QuadSketch layout file?)");
    }
    if (!format->is_string() || format->get<std::string>() != kFormat) {
      fail("format", std::string("expected \"") + kFormat + "\", got " +
                         (format->is_string() ? "\"" + format->get<std::string>() + "\""
                                              : describe(*format)));
    }
    const Json* version = find(doc, "version");
    if (!version) fail("", "missing \"version\": 1");
    if (!version->is_number_integer() || version->get<int64_t>() != kVersion) {
      fail("version", "unsupported version " + version->dump() + " (this program reads version " +
                          std::to_string(kVersion) + ")");
    }
  }

  void read_mesh_block(const Json& v, Layout& layout) const {
    expect_object(v, "mesh");
    layout.mesh_vertices =
        read_int(require(v, "mesh", "vertices"), "mesh.vertices", "an integer vertex count", true);
    layout.mesh_faces =
        read_int(require(v, "mesh", "faces"), "mesh.faces", "an integer face count", true);
  }

  LayoutNode read_node(const Json& v, const std::string& where) const {
    expect_object(v, where);
    LayoutNode node;
    node.id = read_int(require(v, where, "id"), field_path(where, "id"), "an integer id", true);
    const Json* vertex = find(v, "vertex");
    const Json* point = find(v, "point");
    if (!vertex && !point) fail(where, "a node needs \"vertex\" or \"point\"");
    if (vertex) {
      node.vertex = read_int(*vertex, field_path(where, "vertex"), "an integer vertex index", true);
    }
    if (point) node.point = read_surface_point(*point, field_path(where, "point"));
    if (const Json* pinned = find(v, "pinned")) {
      node.pinned = read_bool(*pinned, field_path(where, "pinned"));
    }
    if (const Json* position = find(v, "position")) {
      node.position = read_doubles<3>(*position, field_path(where, "position"));
    }
    if (const Json* valence = find(v, "valence")) {
      node.valence = read_int(*valence, field_path(where, "valence"), "an integer valence", true);
    }
    return node;
  }

  LayoutArc read_arc(const Json& v, const std::string& where) const {
    expect_object(v, where);
    LayoutArc arc;
    arc.id = read_int(require(v, where, "id"), field_path(where, "id"), "an integer id", true);
    arc.from =
        read_int(require(v, where, "from"), field_path(where, "from"), "an integer node id", true);
    const Json& to = require(v, where, "to");
    arc.to = to.is_null() ? -1
                          : read_int(to, field_path(where, "to"),
                                     "an integer node id (or null for a dangling arc)", true);
    const Json* path = find(v, "path");
    const Json* points = find(v, "points");
    if (path && points) fail(where, "an arc has either \"path\" or \"points\", not both");
    if (!path && !points) fail(where, "an arc needs \"path\" or \"points\"");
    if (path) arc.path = read_int_list(*path, field_path(where, "path"), "an integer vertex index");
    if (points) {
      arc.points = read_surface_points(*points, field_path(where, "points"));
      if (arc.points.empty()) {
        fail(field_path(where, "points"),
             "expected at least one surface point (give \"path\" for an explicit route)");
      }
    }
    if (const Json* pinned = find(v, "pinned")) {
      arc.pinned = read_bool(*pinned, field_path(where, "pinned"));
    }
    if (const Json* label = find(v, "label")) {
      const std::string w = field_path(where, "label");
      if (!label->is_string()) fail(w, "expected \"u\" or \"v\", got " + describe(*label));
      arc.label = label->get<std::string>();
      if (arc.label != "u" && arc.label != "v") {
        fail(w, "expected \"u\" or \"v\", got \"" + arc.label + "\"");
      }
    }
    if (const Json* polyline = find(v, "polyline")) {
      const std::string w = field_path(where, "polyline");
      expect_array(*polyline, w);
      arc.polyline.reserve(polyline->size());
      for (size_t k = 0; k < polyline->size(); ++k) {
        arc.polyline.push_back(read_doubles<3>((*polyline)[k], index_path(w, k)));
      }
    }
    if (const Json* samples = find(v, "samples")) {
      arc.samples = read_surface_points(*samples, field_path(where, "samples"));
    }
    return arc;
  }

  void read_features(const Json& v, Layout& layout) const {
    expect_object(v, "features");
    const Json* edges = find(v, "edges");
    if (!edges) return;
    expect_array(*edges, "features.edges");
    layout.feature_edges.reserve(edges->size());
    for (size_t k = 0; k < edges->size(); ++k) {
      const std::string w = index_path("features.edges", k);
      const Json& e = (*edges)[k];
      if (!e.is_array() || e.size() != 2) {
        fail(w, "expected a pair of vertex indices [a, b], got " +
                    (e.is_array() ? "an array of " + std::to_string(e.size()) + " elements"
                                  : describe(e)));
      }
      layout.feature_edges.push_back(
          {read_int(e[0], index_path(w, 0), "an integer vertex index", true),
           read_int(e[1], index_path(w, 1), "an integer vertex index", true)});
    }
  }

  LayoutPatch read_patch(const Json& v, const std::string& where) const {
    expect_object(v, where);
    LayoutPatch patch;
    patch.id = read_int(require(v, where, "id"), field_path(where, "id"), "an integer id", true);
    patch.nodes =
        read_int_list(require(v, where, "nodes"), field_path(where, "nodes"), "an integer node id");
    patch.arcs =
        read_int_list(require(v, where, "arcs"), field_path(where, "arcs"), "an integer arc id");
    if (const Json* size = find(v, "size")) {
      patch.size = read_doubles<2>(*size, field_path(where, "size"));
    }
    return patch;
  }

  std::string source_;
};

// ---------------------------------------------------------------------------------------------
// Writing
// ---------------------------------------------------------------------------------------------

class LayoutWriter {
 public:
  OrderedJson surface_point(const SurfacePoint& p, const std::string& where) const {
    OrderedJson j = OrderedJson::object();
    j["face"] = p.face;
    j["bary"] = doubles(p.bary, where + ".bary");
    return j;
  }

  template <size_t N>
  OrderedJson doubles(const std::array<double, N>& a, const std::string& where) const {
    OrderedJson j = OrderedJson::array();
    for (double d : a) {
      // JSON has no NaN/inf (nlohmann would print null, which we could not read back).
      if (!std::isfinite(d)) throw QsError("cannot write layout: " + where + " is not finite");
      j.push_back(d);
    }
    return j;
  }

  OrderedJson node(const LayoutNode& n) const {
    const std::string where = "node " + std::to_string(n.id);
    OrderedJson j = OrderedJson::object();
    j["id"] = n.id;
    // A node that only has a `point` (parsed, not yet snapped) is written without `vertex`.
    if (n.vertex >= 0 || !n.point) j["vertex"] = n.vertex;
    if (n.point) j["point"] = surface_point(*n.point, where + " point");
    j["pinned"] = n.pinned;
    if (n.position) j["position"] = doubles(*n.position, where + " position");
    if (n.valence >= 0) j["valence"] = n.valence;
    return j;
  }

  OrderedJson arc(const LayoutArc& a) const {
    const std::string where = "arc " + std::to_string(a.id);
    OrderedJson j = OrderedJson::object();
    j["id"] = a.id;
    j["from"] = a.from;
    j["to"] = a.dangling() ? OrderedJson(nullptr) : OrderedJson(a.to);
    // A routed arc keeps its input `points` in memory; its `path` supersedes them (an arc may
    // not carry both in the file).
    if (!a.path.empty() || a.points.empty()) {
      j["path"] = a.path;
    } else {
      OrderedJson pts = OrderedJson::array();
      for (size_t k = 0; k < a.points.size(); ++k) {
        pts.push_back(surface_point(a.points[k], where + " points[" + std::to_string(k) + "]"));
      }
      j["points"] = std::move(pts);
    }
    j["pinned"] = a.pinned;
    if (!a.label.empty()) j["label"] = a.label;
    if (!a.polyline.empty()) {
      OrderedJson poly = OrderedJson::array();
      for (size_t k = 0; k < a.polyline.size(); ++k) {
        poly.push_back(doubles(a.polyline[k], where + " polyline[" + std::to_string(k) + "]"));
      }
      j["polyline"] = std::move(poly);
    }
    if (!a.samples.empty()) {
      OrderedJson samples = OrderedJson::array();
      for (size_t k = 0; k < a.samples.size(); ++k) {
        samples.push_back(
            surface_point(a.samples[k], where + " samples[" + std::to_string(k) + "]"));
      }
      j["samples"] = std::move(samples);
    }
    return j;
  }

  OrderedJson patch(const LayoutPatch& p) const {
    OrderedJson j = OrderedJson::object();
    j["id"] = p.id;
    j["nodes"] = p.nodes;
    j["arcs"] = p.arcs;
    j["size"] = doubles(p.size, "patch " + std::to_string(p.id) + " size");
    return j;
  }
};

//! Appends \p v on one line, with ", " and ": " separators (like the examples in
//! interfaces.md). Scalars are printed by nlohmann: escaped strings, round-trip doubles.
void append_inline(const OrderedJson& v, std::string& out) {
  if (v.is_object()) {
    out += '{';
    bool first = true;
    for (auto it = v.begin(); it != v.end(); ++it) {
      if (!first) out += ", ";
      first = false;
      out += OrderedJson(it.key()).dump();
      out += ": ";
      append_inline(it.value(), out);
    }
    out += '}';
  } else if (v.is_array()) {
    out += '[';
    for (size_t k = 0; k < v.size(); ++k) {
      if (k) out += ", ";
      append_inline(v[k], out);
    }
    out += ']';
  } else {
    out += v.dump();
  }
}

//! Appends `"key": [` + one element per line + `]`.
void append_list(const std::string& key, const std::vector<OrderedJson>& items, std::string& out) {
  out += "  \"" + key + "\": [";
  if (items.empty()) {
    out += "]";
    return;
  }
  out += "\n";
  for (size_t k = 0; k < items.size(); ++k) {
    out += "    ";
    append_inline(items[k], out);
    out += k + 1 < items.size() ? ",\n" : "\n";
  }
  out += "  ]";
}

// ---------------------------------------------------------------------------------------------
// Resolution on a mesh
// ---------------------------------------------------------------------------------------------

//! Problem with a surface point on \p mesh ("" when fine). Same checks as snap_to_vertex.
std::string surface_point_problem(const TriMesh& mesh, const SurfacePoint& p) {
  const int nf = static_cast<int>(mesh.n_faces());
  if (p.face < 0 || p.face >= nf) {
    return "face " + std::to_string(p.face) + " out of range (mesh has " + std::to_string(nf) +
           " faces)";
  }
  try {
    snap_to_vertex(mesh, p);
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return {};
}

}  // namespace

Layout parse_layout_json(const std::string& text, const std::string& source_name) {
  // A leading UTF-8 byte-order mark (written by some editors) is skipped, so that error
  // columns on the first line count from the first visible character.
  constexpr std::string_view kBom = "\xEF\xBB\xBF";
  std::string_view body = text;
  if (body.substr(0, kBom.size()) == kBom) body.remove_prefix(kBom.size());
  Json doc;
  try {
    doc = Json::parse(body.begin(), body.end());
  } catch (const Json::parse_error& e) {
    // e.byte is the 1-based index of the offending byte (one past the end at end of input).
    const auto [line, column] = line_column(body, e.byte > 0 ? e.byte - 1 : 0);
    throw InvalidInputError(source_name + ": malformed JSON at line " + std::to_string(line) +
                            ", column " + std::to_string(column) + ": " +
                            json_error_detail(e.what()));
  } catch (const Json::exception& e) {
    // E.g. "number overflow parsing '1e400'": no position from nlohmann; locate the literal.
    std::string where;
    const std::string what = e.what();
    const size_t q1 = what.find('\'');
    const size_t q2 = q1 == std::string::npos ? q1 : what.find('\'', q1 + 1);
    if (q2 != std::string::npos && q2 > q1 + 1) {
      const size_t at = body.find(what.substr(q1 + 1, q2 - q1 - 1));
      if (at != std::string::npos) {
        const auto [line, column] = line_column(body, at);
        where = " at line " + std::to_string(line) + ", column " + std::to_string(column);
      }
    }
    throw InvalidInputError(source_name + ": malformed JSON" + where + ": " +
                            json_error_detail(what));
  }
  return LayoutReader(source_name).read(doc);
}

void check_layout_on_mesh(const std::string& path, Layout& layout, const TriMesh& mesh,
                          bool snap_points) {
  const int nv = static_cast<int>(mesh.n_vertices());
  const int nf = static_cast<int>(mesh.n_faces());
  if (layout.mesh_vertices >= 0 && (layout.mesh_vertices != nv || layout.mesh_faces != nf)) {
    throw InvalidInputError(path + ": mesh block says " + std::to_string(layout.mesh_vertices) +
                            " vertices / " + std::to_string(layout.mesh_faces) +
                            " faces but the mesh has " + std::to_string(nv) + " / " +
                            std::to_string(nf));
  }

  std::vector<std::string> problems;
  for (LayoutNode& node : layout.nodes) {
    const std::string who = "node " + std::to_string(node.id);
    if (node.vertex >= nv) {
      problems.push_back(who + ": vertex " + std::to_string(node.vertex) +
                         " out of range (mesh has " + std::to_string(nv) + " vertices)");
    }
    if (node.point) {
      const std::string problem = surface_point_problem(mesh, *node.point);
      if (!problem.empty()) {
        problems.push_back(who + ": point: " + problem);
      } else if (node.vertex < 0) {
        if (snap_points) node.vertex = snap_to_vertex(mesh, *node.point);
      } else if (node.vertex < nv) {
        // Both given (as written for snapped and output nodes): they must name the same vertex,
        // else one of them would be ignored silently.
        const int snapped = snap_to_vertex(mesh, *node.point);
        if (snapped != node.vertex) {
          problems.push_back(who + ": has both \"vertex\": " + std::to_string(node.vertex) +
                             " and a \"point\" that snaps to vertex " + std::to_string(snapped) +
                             " (give only one, or a point at that vertex)");
        }
      }
    }
  }
  for (const LayoutArc& arc : layout.arcs) {
    const std::string who = "arc " + std::to_string(arc.id);
    for (size_t k = 0; k < arc.points.size(); ++k) {
      const std::string problem = surface_point_problem(mesh, arc.points[k]);
      if (!problem.empty()) {
        problems.push_back(who + ": points[" + std::to_string(k) + "]: " + problem);
      }
    }
    for (size_t k = 0; k < arc.samples.size(); ++k) {
      const std::string problem = surface_point_problem(mesh, arc.samples[k]);
      if (!problem.empty()) {
        problems.push_back(who + ": samples[" + std::to_string(k) + "]: " + problem);
      }
    }
  }
  if (!problems.empty()) {
    std::string msg = path + ": ";
    for (size_t k = 0; k < problems.size(); ++k) msg += (k ? "; " : "") + problems[k];
    throw InvalidInputError(msg);
  }
}

Layout read_layout_file(const std::string& path) {
  return parse_layout_json(read_input_file(path, kMaxLayoutFileBytes), path);
}

void resolve_layout(const std::string& path, Layout& layout, const TriMesh& mesh) {
  check_layout_on_mesh(path, layout, mesh, /*snap_points=*/true);
  try {
    route_layout(mesh, layout);
  } catch (const InvalidInputError& e) {
    throw InvalidInputError(path + ": " + e.what());
  }
}

Layout load_layout(const std::string& path, const TriMesh& mesh) {
  Layout layout = read_layout_file(path);
  resolve_layout(path, layout, mesh);
  return layout;
}

std::string layout_to_json(const Layout& layout, const TriMesh* mesh) {
  const LayoutWriter writer;
  std::string out = "{\n";
  out += "  \"format\": \"" + std::string(kFormat) + "\",\n";
  out += "  \"version\": " + std::to_string(kVersion) + ",\n";
  int mesh_vertices = layout.mesh_vertices;
  int mesh_faces = layout.mesh_faces;
  if (mesh) {
    mesh_vertices = static_cast<int>(mesh->n_vertices());
    mesh_faces = static_cast<int>(mesh->n_faces());
  }
  if (mesh_vertices >= 0 && mesh_faces >= 0) {
    out += "  \"mesh\": {\"vertices\": " + std::to_string(mesh_vertices) +
           ", \"faces\": " + std::to_string(mesh_faces) + "},\n";
  }

  std::vector<OrderedJson> items;
  items.reserve(layout.nodes.size());
  for (const LayoutNode& n : layout.nodes) items.push_back(writer.node(n));
  append_list("nodes", items, out);

  items.clear();
  for (const LayoutArc& a : layout.arcs) items.push_back(writer.arc(a));
  out += ",\n";
  append_list("arcs", items, out);

  if (!layout.feature_edges.empty()) {
    OrderedJson edges = OrderedJson::array();
    for (const auto& e : layout.feature_edges) edges.push_back({e[0], e[1]});
    OrderedJson features = OrderedJson::object();
    features["edges"] = std::move(edges);
    out += ",\n  \"features\": ";
    append_inline(features, out);
  }

  if (!layout.patches.empty()) {
    items.clear();
    for (const LayoutPatch& p : layout.patches) items.push_back(writer.patch(p));
    out += ",\n";
    append_list("patches", items, out);
  }
  out += "\n}\n";
  return out;
}

void save_layout(const Layout& layout, const std::string& path, const TriMesh* mesh) {
  write_file_atomic(path, layout_to_json(layout, mesh));
}

}  // namespace qs
