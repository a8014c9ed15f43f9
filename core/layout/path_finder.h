// Shortest edge paths restricted to a vertex region, with per-vertex cost factors. Used to route
// transferred arcs inside a corridor (quad_import) and re-route arcs of moved nodes (perturb).
#pragma once

#include <vector>

#include "core/layout/routing.h"
#include "core/mesh/mesh.h"

namespace qs {

//! Dijkstra over mesh edges that reuses its work arrays between queries, so a query costs
//! O(visited · log) instead of O(#V) (many short queries on large meshes).
class PathFinder {
 public:
  explicit PathFinder(const TriMesh& mesh);

  //! Shortest path from \p source to \p target (vertex indices, source first; {source} when
  //! they are equal; empty when unreachable or out of range).
  //! - \p obstacles: blocked vertices are never entered (except \p target), blocked edges never
  //!   crossed (RoutingObstacles' rules, see routing.h).
  //! - \p allowed (size #V, or nullptr for all): other vertices are never entered (except
  //!   \p target).
  //! - \p vertex_cost (size #V, or nullptr for 1): edge (u, w) costs
  //!   |x_u − x_w| · (cost[u] + cost[w]) / 2 (length units of the mesh); factors must be > 0.
  std::vector<int> find(int source, int target, const RoutingObstacles& obstacles,
                        const std::vector<char>* allowed = nullptr,
                        const std::vector<double>* vertex_cost = nullptr);

 private:
  const TriMesh& mesh_;
  std::vector<double> dist_;
  std::vector<int> parent_;
  std::vector<int> touched_;
};

}  // namespace qs
