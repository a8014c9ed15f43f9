#include "core/mesh/weld.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <unordered_map>
#include <vector>

#include "core/base/errors.h"
#include "core/mesh/mesh_checks.h"

namespace qs {

namespace {

struct CellHash {
  size_t operator()(const std::array<int64_t, 3>& c) const {
    uint64_t h = 1469598103934665603ull;
    for (int64_t x : c) h = (h ^ static_cast<uint64_t>(x)) * 1099511628211ull;
    return static_cast<size_t>(h);
  }
};

int find_root(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

int weld_coincident_vertices(PolygonSoup& soup, double relative_tolerance) {
  const int n = static_cast<int>(soup.points.size());
  Vec3 lo(HUGE_VAL, HUGE_VAL, HUGE_VAL), hi(-HUGE_VAL, -HUGE_VAL, -HUGE_VAL);
  std::vector<char> finite(n, 0);
  for (int i = 0; i < n; ++i) {
    const Vec3& p = soup.points[i];
    finite[i] = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
    if (!finite[i]) continue;
    lo.minimize(p);
    hi.maximize(p);
  }
  if (!(lo[0] <= hi[0])) return 0;  // no finite point
  const double tolerance = relative_tolerance * (hi - lo).norm();
  // Cells of size tolerance relative to the box's corner: indices stay below 1/relative_tolerance.
  const double cell = tolerance > 0 ? tolerance : 1.0;
  const auto cell_of = [&](const Vec3& p) {
    return std::array<int64_t, 3>{static_cast<int64_t>(std::floor((p[0] - lo[0]) / cell)),
                                  static_cast<int64_t>(std::floor((p[1] - lo[1]) / cell)),
                                  static_cast<int64_t>(std::floor((p[2] - lo[2]) / cell))};
  };
  std::unordered_map<std::array<int64_t, 3>, std::vector<int>, CellHash> cells;
  for (int i = 0; i < n; ++i)
    if (finite[i]) cells[cell_of(soup.points[i])].push_back(i);
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (int i = 0; i < n; ++i) {
    if (!finite[i]) continue;
    const auto c = cell_of(soup.points[i]);
    for (int64_t dx = -1; dx <= 1; ++dx)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find({c[0] + dx, c[1] + dy, c[2] + dz});
          if (it == cells.end()) continue;
          for (int j : it->second) {
            if (j <= i || (soup.points[i] - soup.points[j]).norm() > tolerance) continue;
            const int a = find_root(parent, i), b = find_root(parent, j);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the smallest index leads
          }
        }
  }
  // New index per kept vertex (a group's smallest index), in the old order.
  std::vector<int> new_index(n, -1);
  int kept = 0;
  for (int i = 0; i < n; ++i)
    if (find_root(parent, i) == i) new_index[i] = kept++;
  if (kept == n) return 0;
  std::vector<Vec3> points;
  points.reserve(kept);
  for (int i = 0; i < n; ++i)
    if (new_index[i] >= 0) points.push_back(soup.points[i]);
  for (auto& face : soup.faces)
    for (int& v : face)
      if (v >= 0 && v < n) v = new_index[find_root(parent, v)];
  // Out-of-range indices stay out of range of the shorter point list (the checks name them).
  soup.points = std::move(points);
  return n - kept;
}

WeldedPolyMesh load_poly_mesh_welded(const std::string& path, double relative_tolerance) {
  PolygonSoup soup = read_polygon_soup(path);
  WeldedPolyMesh out;
  {
    MeshReport before;
    build_poly_mesh(soup, before);
    out.parts_before = before.components;
  }
  out.welded = weld_coincident_vertices(soup, relative_tolerance);
  out.report.path = path;
  out.mesh = build_poly_mesh(soup, out.report);
  if (out.report.ok()) return out;
  std::string message = path + ": invalid mesh";
  if (out.welded > 0) {
    message += " after welding " + std::to_string(out.welded) + " coincident vertices";
    if (out.parts_before > 1)
      message +=
          ", at which the file's " + std::to_string(out.parts_before) + " separate parts touch";
    message += " (vertex ids are those after welding)";
  }
  for (const auto& line : out.report.problems()) message += "\n" + line;
  throw InvalidInputError(message);
}

}  // namespace qs
