#include "core/extract/quads.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numeric>
#include <ostream>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"

namespace qs {

namespace {

using V2 = std::array<double, 2>;
using P3 = std::array<double, 3>;

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void unite(int a, int b) { parent[find(a)] = find(b); }
};

// Patches that take part in the grid: quad patches whose border arcs all traced.
std::vector<char> usable_patches(const LayoutTopology& topo, const Extraction& ex) {
  std::vector<char> usable(topo.patches.size(), 0);
  for (size_t p = 0; p < topo.patches.size(); ++p) {
    const auto& P = topo.patches[p];
    if (!is_quad_patch(P)) continue;
    bool ok = true;
    for (int d : P.darts) {
      const int a = d >> 1;
      ok &= ex.arcs[a].ok && topo.half_node[2 * a] >= 0 && topo.half_node[2 * a + 1] >= 0;
    }
    usable[p] = ok;
  }
  return usable;
}

// Segments per arc: the max of ⌈L/q⌉ over the arc's poly-chord class (opposite sides of every
// usable patch are in one class), at least 1. 0 for arcs on no usable patch.
std::vector<int> arc_segment_counts(const LayoutTopology& topo, const Extraction& ex,
                                    const std::vector<char>& usable, double q) {
  const int na = topo.num_arcs;
  UnionFind uf(na);
  std::vector<char> used(na, 0);
  for (size_t p = 0; p < topo.patches.size(); ++p) {
    if (!usable[p]) continue;
    const auto& d = topo.patches[p].darts;
    uf.unite(d[0] >> 1, d[2] >> 1);
    uf.unite(d[1] >> 1, d[3] >> 1);
    for (int x : d) used[x >> 1] = 1;
  }
  std::vector<int> class_count(na, 1);
  for (int a = 0; a < na; ++a) {
    if (!used[a]) continue;
    // The factor keeps exact multiples of q from rounding up by one.
    const double c = std::ceil(ex.arcs[a].param_length / q * (1 - 1e-9));
    const int k = static_cast<int>(std::clamp(c, 1.0, 1e7));
    int& cc = class_count[uf.find(a)];
    cc = std::max(cc, k);
  }
  std::vector<int> out(na, 0);
  for (int a = 0; a < na; ++a)
    if (used[a]) out[a] = class_count[uf.find(a)];
  return out;
}

// Points at equal parametric spacing along a traced arc: segments + 1 positions from its start
// to its end (the end points are the first/last samples exactly).
std::vector<P3> sample_arc(const TriMesh& mesh, const GeometryCache& g, const std::vector<V2>& uv,
                           const TracedArc& t, int segments) {
  const size_t n = t.samples.size();
  std::vector<double> pos(n, 0.0);
  for (size_t i = 0; i + 1 < n; ++i) {
    // Segment i → i+1 lies in the face of sample i+1 (tracing.h).
    const V2 a = uv_in_face(mesh, g, uv, t.samples[i], t.samples[i + 1].face);
    pos[i + 1] = pos[i] + std::hypot(t.uv[i + 1][0] - a[0], t.uv[i + 1][1] - a[1]);
  }
  const double total = pos.back();
  std::vector<P3> out;
  out.push_back(t.polyline.front());
  size_t seg = 0;
  for (int k = 1; k < segments; ++k) {
    const double tau = total * k / segments;
    while (seg + 2 < n && pos[seg + 1] < tau) ++seg;
    const double span = pos[seg + 1] - pos[seg];
    const double lambda = span > 0 ? std::clamp((tau - pos[seg]) / span, 0.0, 1.0) : 0.0;
    const P3& x0 = t.polyline[seg];
    const P3& x1 = t.polyline[seg + 1];
    out.push_back({x0[0] + lambda * (x1[0] - x0[0]), x0[1] + lambda * (x1[1] - x0[1]),
                   x0[2] + lambda * (x1[2] - x0[2])});
  }
  out.push_back(t.polyline.back());
  return out;
}

std::string fmt3(const char* tag, const P3& p) {
  char line[128];
  std::snprintf(line, sizeof line, "%s %.17g %.17g %.17g\n", tag, p[0], p[1], p[2]);
  return line;
}

}  // namespace

int QuadMesh::gridded_patches() const {
  int n = 0;
  for (const auto& p : patches) n += p.ok;
  return n;
}

long count_quads(const LayoutTopology& topo, const Extraction& ex, double q) {
  const auto usable = usable_patches(topo, ex);
  const auto counts = arc_segment_counts(topo, ex, usable, q);
  long total = 0;
  for (size_t p = 0; p < topo.patches.size(); ++p)
    if (usable[p]) {
      const auto& d = topo.patches[p].darts;
      total += static_cast<long>(counts[d[0] >> 1]) * counts[d[1] >> 1];
    }
  return total;
}

double quad_size_for_count(const LayoutTopology& topo, const Extraction& ex, int quad_count) {
  if (quad_count <= 0) throw InvalidInputError("quad count must be positive");
  const auto usable = usable_patches(topo, ex);
  double area = 0;
  for (size_t p = 0; p < topo.patches.size(); ++p)
    if (usable[p]) {
      const auto& d = topo.patches[p].darts;
      area += ex.arcs[d[0] >> 1].param_length * ex.arcs[d[1] >> 1].param_length;
    }
  if (!(area > 0)) throw InvalidInputError("no patch of the layout can be gridded");
  const double q0 = std::sqrt(area / quad_count);
  // count(q) is non-increasing: bisect (in log q) for the smallest q with count ≤ N.
  double lo = q0 / 64, hi = q0 * 64;
  for (int it = 0; it < 80; ++it) {
    const double mid = std::sqrt(lo * hi);
    if (count_quads(topo, ex, mid) <= quad_count)
      hi = mid;
    else
      lo = mid;
  }
  const long c_hi = count_quads(topo, ex, hi), c_lo = count_quads(topo, ex, lo);
  return std::labs(c_lo - quad_count) < std::labs(quad_count - c_hi) ? lo : hi;
}

QuadMesh build_quad_mesh(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                         const LayoutTopology& topo, const Extraction& ex,
                         const std::vector<int>& period_jump, const std::vector<V2>& uv,
                         const QuadMeshOptions& opt) {
  QuadMesh out;
  if (opt.quad_size > 0)
    out.quad_size = opt.quad_size;
  else if (opt.quad_count > 0)
    out.quad_size = quad_size_for_count(topo, ex, opt.quad_count);
  else
    throw InvalidInputError("quad mesh: give a quad size > 0 or a quad count > 0");
  const double q = out.quad_size;
  const auto usable = usable_patches(topo, ex);
  out.arc_segments = arc_segment_counts(topo, ex, usable, q);
  out.arc_vertices.assign(topo.num_arcs, {});
  out.node_vertex.assign(topo.num_nodes, -1);
  for (int a = 0; a < topo.num_arcs; ++a)
    if (!ex.arcs[a].ok)
      out.warnings.push_back("arc " + std::to_string(layout.arcs[a].id) +
                             " failed to trace: " + ex.arcs[a].failure);

  auto node_vertex = [&](int n) {
    if (out.node_vertex[n] < 0) {
      const auto& x = mesh.point(mesh.vertex_handle(layout.nodes[n].vertex));
      out.node_vertex[n] = static_cast<int>(out.vertices.size());
      out.vertices.push_back({x[0], x[1], x[2]});
    }
    return out.node_vertex[n];
  };
  // The shared vertices of arc a (created once, on first use).
  auto arc_vertices = [&](int a) -> const std::vector<int>& {
    auto& av = out.arc_vertices[a];
    if (av.empty()) {
      const auto pts = sample_arc(mesh, g, uv, ex.arcs[a], out.arc_segments[a]);
      av.push_back(node_vertex(topo.half_node[2 * a]));
      for (size_t k = 1; k + 1 < pts.size(); ++k) {
        av.push_back(static_cast<int>(out.vertices.size()));
        out.vertices.push_back(pts[k]);
      }
      av.push_back(node_vertex(topo.half_node[2 * a + 1]));
    }
    return av;
  };

  out.patches.resize(topo.patches.size());
  for (size_t p = 0; p < topo.patches.size(); ++p) {
    QuadPatch& qp = out.patches[p];
    qp.patch = static_cast<int>(p);
    const auto& P = topo.patches[p];
    auto skip = [&](const std::string& why) {
      qp.failure = why;
      out.warnings.push_back("patch " + std::to_string(p) + " skipped: " + why);
    };
    if (!usable[p]) {
      if (!is_quad_patch(P))
        skip(P.trimmed
                 ? "trimmed patch (bare mesh boundary on its border)"
                 : "not a 4-sided disk patch (" + std::to_string(P.darts.size()) + " arc sides)");
      else
        skip("an arc of its border failed to trace");
      continue;
    }
    for (int k = 0; k < 4; ++k) qp.nodes[k] = P.corners[k], qp.darts[k] = P.darts[k];
    const PatchChart chart = build_patch_chart(mesh, g, layout, topo, ex, period_jump, uv,
                                               static_cast<int>(p), opt.chart);
    if (!chart.ok) {
      skip("chart: " + chart.failure);
      continue;
    }
    const int m = out.arc_segments[P.darts[0] >> 1], n = out.arc_segments[P.darts[1] >> 1];
    qp.size = {chart.w, chart.h};
    qp.grid = {m, n};
    // Interior points first: a patch whose location fails is skipped before it adds vertices.
    std::vector<P3> interior;
    interior.reserve(static_cast<size_t>(std::max(0, m - 1)) * std::max(0, n - 1));
    bool located = true;
    for (int j = 1; j < n && located; ++j)
      for (int i = 1; i < m && located; ++i) {
        SurfacePoint sp;
        if (!chart.locate({chart.w * i / m, chart.h * j / n}, sp)) {
          located = false;
          break;
        }
        const Vec3 x = surface_position(mesh, g, sp);
        interior.push_back({x[0], x[1], x[2]});
      }
    if (!located) {
      skip("grid point outside the chart (fold-over in the parameterization?)");
      continue;
    }
    auto side = [&](int k) {
      std::vector<int> s = arc_vertices(P.darts[k] >> 1);
      if (P.darts[k] & 1) std::reverse(s.begin(), s.end());
      return s;
    };
    const auto s0 = side(0), s1 = side(1), s2 = side(2), s3 = side(3);
    qp.grid_vertices.assign(static_cast<size_t>(m + 1) * (n + 1), -1);
    auto at = [&](int i, int j) -> int& { return qp.grid_vertices[j * (m + 1) + i]; };
    for (int i = 0; i <= m; ++i) at(i, 0) = s0[i], at(m - i, n) = s2[i];
    for (int j = 0; j <= n; ++j) at(m, j) = s1[j], at(0, n - j) = s3[j];
    size_t next = 0;
    for (int j = 1; j < n; ++j)
      for (int i = 1; i < m; ++i) {
        at(i, j) = static_cast<int>(out.vertices.size());
        out.vertices.push_back(interior[next++]);
      }
    qp.first_quad = static_cast<int>(out.quads.size());
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < m; ++i) {
        out.quads.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
        out.quad_patch.push_back(static_cast<int>(p));
      }
    qp.num_quads = m * n;
    qp.ok = true;
  }
  return out;
}

void write_quads_obj(const QuadMesh& qm, const std::string& path, const UvAtlasOptions& atlas) {
  std::vector<std::array<double, 2>> sizes;
  for (const auto& qp : qm.patches)
    if (qp.ok) sizes.push_back(qp.size);
  const std::vector<UvRect> rects = uv_atlas(sizes, atlas);
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# QuadSketch quad mesh: " << qm.vertices.size() << " vertices, " << qm.quads.size()
        << " quads, " << qm.gridded_patches() << " patches, quad size " << qm.quad_size << "\n";
    if (atlas.layout == UvAtlasLayout::kPacked)
      out << "# vt: packed atlas, patch coordinates (s, t) scaled by one factor for all patches,"
             " non-overlapping rectangles in [0,1]^2\n";
    else
      out << "# vt: normalized patch coordinates (s/w, t/h) per face corner\n";
    for (const auto& v : qm.vertices) out << fmt3("v", v);
    char line[96];
    size_t k = 0;
    for (const auto& qp : qm.patches) {
      if (!qp.ok) continue;
      const UvRect& r = rects[k++];
      for (int j = 0; j <= qp.grid[1]; ++j)
        for (int i = 0; i <= qp.grid[0]; ++i) {
          const double s = static_cast<double>(i) / qp.grid[0];
          const double t = static_cast<double>(j) / qp.grid[1];
          std::snprintf(line, sizeof line, "vt %.17g %.17g\n", r.u0 + s * (r.u1 - r.u0),
                        r.v0 + t * (r.v1 - r.v0));
          out << line;
        }
    }
    long vt_base = 1;
    for (const auto& qp : qm.patches) {
      if (!qp.ok) continue;
      const int m = qp.grid[0], n = qp.grid[1];
      out << "g patch_" << qp.patch << "\n";
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < m; ++i) {
          const int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
          out << 'f';
          for (int c = 0; c < 4; ++c)
            out << ' ' << qp.grid_vertices[cj[c] * (m + 1) + ci[c]] + 1 << '/'
                << vt_base + cj[c] * (m + 1) + ci[c];
          out << '\n';
        }
      vt_base += static_cast<long>(m + 1) * (n + 1);
    }
  });
}

void write_patches_json(const QuadMesh& qm, const Layout& layout, const Extraction& ex,
                        const std::string& path) {
  using nlohmann::json;
  json patches = json::array(), skipped = json::array();
  for (const auto& qp : qm.patches) {
    if (!qp.ok) {
      skipped.push_back({{"id", qp.patch}, {"reason", qp.failure}});
      continue;
    }
    json nodes = json::array(), arcs = json::array(), reversed = json::array();
    json curves = json::array(), corners = json::array();
    for (int k = 0; k < 4; ++k) {
      const int a = qp.darts[k] >> 1;
      nodes.push_back(layout.nodes[qp.nodes[k]].id);
      arcs.push_back(layout.arcs[a].id);
      reversed.push_back((qp.darts[k] & 1) == 1);
      auto poly = ex.arcs[a].polyline;
      if (qp.darts[k] & 1) std::reverse(poly.begin(), poly.end());
      json c = json::array();
      for (const auto& x : poly) c.push_back({x[0], x[1], x[2]});
      curves.push_back(std::move(c));
      const auto& x = qm.vertices[qm.node_vertex[qp.nodes[k]]];
      corners.push_back({x[0], x[1], x[2]});
    }
    patches.push_back({{"id", qp.patch},
                       {"group", "patch_" + std::to_string(qp.patch)},
                       {"nodes", nodes},
                       {"arcs", arcs},
                       {"arcs_reversed", reversed},
                       {"size", {qp.size[0], qp.size[1]}},
                       {"grid", {qp.grid[0], qp.grid[1]}},
                       {"quads", {{"first", qp.first_quad}, {"count", qp.num_quads}}},
                       {"corners", corners},
                       {"curves", curves}});
  }
  json doc = {{"format", "quadsketch-patches"},
              {"version", 1},
              {"quad_size", qm.quad_size},
              {"vertices", qm.vertices.size()},
              {"quads", qm.quads.size()},
              {"patches", patches},
              {"skipped", skipped},
              {"warnings", qm.warnings}};
  write_file_atomic(path, doc.dump(1) + "\n");
}

void write_layout_curves_obj(const Layout& layout, const Extraction& ex, const std::string& path) {
  const size_t num_arcs = ex.arcs.size();
  // Node positions: the start of an arc from the node, or the end of a traced arc to it.
  std::vector<const P3*> node_x(layout.nodes.size(), nullptr);
  auto from_node = [&](size_t a) { return layout.node_index(layout.arcs[a].from); };
  auto to_node = [&](size_t a) {
    return layout.arcs[a].to >= 0 && ex.arcs[a].ok ? layout.node_index(layout.arcs[a].to) : -1;
  };
  for (size_t a = 0; a < num_arcs; ++a) {
    const auto& poly = ex.arcs[a].polyline;
    if (poly.empty()) continue;
    const int from = from_node(a), to = to_node(a);
    if (from >= 0 && !node_x[from]) node_x[from] = &poly.front();
    if (to >= 0 && !node_x[to]) node_x[to] = &poly.back();
  }
  // OBJ vertex indices (1-based): the nodes first, then each arc's own vertices.
  std::vector<const P3*> vertices;
  std::vector<long> node_v(layout.nodes.size(), 0);
  for (size_t n = 0; n < node_x.size(); ++n)
    if (node_x[n]) {
      vertices.push_back(node_x[n]);
      node_v[n] = static_cast<long>(vertices.size());
    }
  const size_t num_nodes = vertices.size();
  std::vector<std::vector<long>> arc_v(num_arcs);  // per arc: one index per polyline point
  for (size_t a = 0; a < num_arcs; ++a) {
    const auto& poly = ex.arcs[a].polyline;
    if (poly.size() < 2) continue;
    const int from = from_node(a), to = to_node(a);
    auto& idx = arc_v[a];
    for (size_t i = 0; i < poly.size(); ++i) {
      const bool first = i == 0, last = i + 1 == poly.size();
      if (first && from >= 0) {
        idx.push_back(node_v[from]);
      } else if (last && to >= 0) {
        idx.push_back(node_v[to]);
      } else {
        vertices.push_back(&poly[i]);
        idx.push_back(static_cast<long>(vertices.size()));
      }
    }
  }
  write_file_atomic(path, [&](std::ostream& out) {
    out << "# QuadSketch layout: nodes and traced arcs. Vertices 1.." << num_nodes
        << " are the nodes, shared by the arcs that end there; then the arcs' inner points.\n"
        << "# Group arc_<id>: that arc's polyline from its from node to its to node, one\n"
        << "# 2-vertex line (l) per segment. Group nodes: the node vertices as points (p).\n";
    out << "o layout_curves\n";
    for (const P3* x : vertices) out << fmt3("v", *x);
    for (size_t a = 0; a < num_arcs; ++a) {
      const auto& idx = arc_v[a];
      if (idx.empty()) continue;
      out << "g arc_" << layout.arcs[a].id << '\n';
      for (size_t i = 0; i + 1 < idx.size(); ++i)
        out << "l " << idx[i] << ' ' << idx[i + 1] << '\n';
    }
    if (num_nodes > 0) {
      out << "g nodes\np";
      for (size_t v = 1; v <= num_nodes; ++v) out << ' ' << v;
      out << '\n';
    }
  });
}

void write_quad_exports(const QuadMesh& qm, const Layout& layout, const Extraction& ex,
                        const std::string& dir, const UvAtlasOptions& atlas) {
  const std::filesystem::path d(dir);
  write_quads_obj(qm, (d / "quads.obj").string(), atlas);
  write_patches_json(qm, layout, ex, (d / "patches.json").string());
  write_layout_curves_obj(layout, ex, (d / "layout_curves.obj").string());
}

}  // namespace qs
