#include "core/layout/path_finder.h"

#include <algorithm>
#include <functional>
#include <limits>
#include <queue>
#include <utility>

namespace qs {

namespace {

bool flag(const std::vector<char>* flags, int i) {
  return flags && static_cast<size_t>(i) < flags->size() && (*flags)[i] != 0;
}

}  // namespace

PathFinder::PathFinder(const TriMesh& mesh)
    : mesh_(mesh),
      dist_(mesh.n_vertices(), std::numeric_limits<double>::infinity()),
      parent_(mesh.n_vertices(), -1) {}

std::vector<int> PathFinder::find(int source, int target, const RoutingObstacles& obstacles,
                                  const std::vector<char>* allowed,
                                  const std::vector<double>* vertex_cost) {
  const int nv = static_cast<int>(mesh_.n_vertices());
  if (source < 0 || target < 0 || source >= nv || target >= nv) return {};
  if (source == target) return {source};
  auto cost_of = [&](int v) { return vertex_cost ? (*vertex_cost)[v] : 1.0; };
  using Entry = std::pair<double, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> queue;
  dist_[source] = 0.0;
  touched_.push_back(source);
  queue.emplace(0.0, source);
  bool found = false;
  while (!queue.empty()) {
    const auto [d, v] = queue.top();
    queue.pop();
    if (d > dist_[v]) continue;
    if (v == target) {
      found = true;
      break;
    }
    const OpenMesh::VertexHandle vh(v);
    for (const auto heh : mesh_.voh_range(vh)) {
      if (flag(&obstacles.edge_blocked, mesh_.edge_handle(heh).idx())) continue;
      const int w = mesh_.to_vertex_handle(heh).idx();
      if (w != target && (flag(&obstacles.vertex_blocked, w) || (allowed && !flag(allowed, w)))) {
        continue;
      }
      const double length = (mesh_.point(mesh_.to_vertex_handle(heh)) - mesh_.point(vh)).norm();
      const double nd = d + length * 0.5 * (cost_of(v) + cost_of(w));
      if (nd < dist_[w]) {
        if (dist_[w] == std::numeric_limits<double>::infinity()) touched_.push_back(w);
        dist_[w] = nd;
        parent_[w] = v;
        queue.emplace(nd, w);
      }
    }
  }
  std::vector<int> path;
  if (found) {
    for (int v = target; v >= 0; v = parent_[v]) path.push_back(v);
    std::reverse(path.begin(), path.end());
  }
  for (int v : touched_) {
    dist_[v] = std::numeric_limits<double>::infinity();
    parent_[v] = -1;
  }
  touched_.clear();
  return path;
}

}  // namespace qs
