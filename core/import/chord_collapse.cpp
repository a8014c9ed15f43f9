// ChordCollapser::collapse, one poly-chord collapse with its cleanliness checks
// (core/import/chord_collapser.h).
#include <algorithm>
#include <array>
#include <limits>
#include <map>
#include <numeric>
#include <vector>

#include "core/import/chord_collapser.h"

namespace qs {

bool ChordCollapser::collapse(const Chord& chord, std::vector<char>& touched) {
  State s = s_;
  const size_t k = chord.patches.size();
  // Crossed arcs (as darts) and the patches the chord passes twice (it crosses itself there).
  std::vector<int> crossing;
  for (size_t i = 0; i < k; ++i) crossing.push_back(s.patches[chord.patches[i]][chord.entry[i]]);
  if (!chord.closed) {
    const auto& last = s.patches[chord.patches[k - 1]];
    crossing.push_back(last[(chord.entry[k - 1] + 2) % 4] ^ 1);
  }
  std::vector<int> sorted_patches = chord.patches;
  std::sort(sorted_patches.begin(), sorted_patches.end());
  std::vector<char> twice(k, 0);
  int self_crossings = 0;
  for (size_t i = 0; i < k; ++i) {
    twice[i] = std::count(sorted_patches.begin(), sorted_patches.end(), chord.patches[i]) > 1;
    self_crossings += twice[i];
  }
  self_crossings /= 2;
  std::vector<int> seen_arcs;
  for (int d : crossing) {
    if (s.arcs[d >> 1].from == s.arcs[d >> 1].to) return false;
    seen_arcs.push_back(d >> 1);
  }
  // Rails: the two uncrossed sides of each patch passed once. A chord running along itself
  // shares rails between its patches; the identified rails then form chains of arcs.
  std::vector<std::array<int, 2>> rails;
  for (size_t i = 0; i < k; ++i) {
    if (twice[i]) continue;  // all four sides are crossed
    const auto& P = s.patches[chord.patches[i]];
    rails.push_back({P[(chord.entry[i] + 1) % 4], P[(chord.entry[i] + 3) % 4]});
  }
  {
    std::vector<int> v = seen_arcs;
    std::sort(v.begin(), v.end());
    if (std::adjacent_find(v.begin(), v.end()) != v.end()) return false;
    for (const auto& r : rails)
      for (int d : r)
        if (std::binary_search(v.begin(), v.end(), d >> 1)) return false;
  }
  // rail_links[a]: the rails identified with arc a (one or two).
  std::map<int, std::vector<int>> rail_links;
  for (const auto& r : rails) {
    rail_links[r[0] >> 1].push_back(r[1] >> 1);
    rail_links[r[1] >> 1].push_back(r[0] >> 1);
  }
  struct Chain {
    int first_outer, last_outer;  // outer darts of the end arcs (not in a chord patch)
    std::vector<int> arcs;
  };
  std::vector<Chain> chains;
  {
    std::vector<char> in_chord_patch(2 * s.arcs.size(), 0);
    for (const auto& r : rails) in_chord_patch[r[0]] = in_chord_patch[r[1]] = 1;
    std::map<int, char> done;
    for (const auto& [a, links] : rail_links) {
      if (links.size() != 1 || done[a]) continue;
      Chain chain;
      int prev = -1, cur = a;
      while (true) {
        chain.arcs.push_back(cur);
        done[cur] = 1;
        const auto& l = rail_links[cur];
        int next = -1;
        for (int b : l)
          if (b != prev) next = b;
        if (l.size() == 1 && prev >= 0) break;
        if (next < 0 || done[next]) return false;
        prev = cur, cur = next;
      }
      auto outer = [&](int arc) { return in_chord_patch[2 * arc] ? 2 * arc + 1 : 2 * arc; };
      chain.first_outer = outer(chain.arcs.front());
      chain.last_outer = outer(chain.arcs.back());
      if (s.patch_of_dart[chain.first_outer] < 0 && s.patch_of_dart[chain.last_outer] < 0)
        return false;  // would pinch two boundary pieces together
      chains.push_back(std::move(chain));
    }
    for (const auto& [a, links] : rail_links)
      if (!done[a]) return false;  // rails closing a cycle
  }
  // Groups of merged nodes: the crossed arcs' ends. Only the cycles closed around the
  // patches where the chord crosses itself may repeat a union; any other would pinch.
  const int n_nodes = static_cast<int>(s.node_vertex.size());
  std::vector<int> parent(n_nodes);
  std::iota(parent.begin(), parent.end(), 0);
  int unions = 0;
  for (int d : crossing) {
    const int x = find(parent, s.arcs[d >> 1].from), y = find(parent, s.arcs[d >> 1].to);
    if (x == y) continue;
    parent[std::max(x, y)] = std::min(x, y);
    ++unions;
  }
  if (unions != static_cast<int>(crossing.size()) - self_crossings) return false;
  std::vector<int> members;
  for (int d : crossing) {
    members.push_back(s.arcs[d >> 1].from);
    members.push_back(s.arcs[d >> 1].to);
  }
  std::sort(members.begin(), members.end());
  members.erase(std::unique(members.begin(), members.end()), members.end());
  std::vector<int> node_at_vertex(quads_.n_vertices(), -1);
  for (int n = 0; n < n_nodes; ++n)
    if (s.node_alive[n]) node_at_vertex[s.node_vertex[n]] = n;
  std::vector<std::vector<int>> ext(n_nodes);
  std::vector<int> reps, new_vertices;
  std::vector<char> has_ext(n_nodes, 0);
  for (int root : members) {
    if (find(parent, root) != root) continue;
    reps.push_back(root);
    std::vector<int> group, group_arcs;
    for (int n : members)
      if (find(parent, n) == root) group.push_back(n);
    for (int d : crossing)
      if (find(parent, s.arcs[d >> 1].from) == root) group_arcs.push_back(d >> 1);
    std::vector<int> boundary_nodes;
    for (int n : group)
      if (s.node_boundary[n]) boundary_nodes.push_back(n);
    // The merge point: an arc of the group and a vertex index on its path.
    int m_arc = -1;
    size_t m_index = 0;
    if (boundary_nodes.size() >= 2) {
      // Only two boundary nodes joined along the boundary may merge (at the middle).
      const int a = group_arcs[0];
      const bool boundary_arc = s.patch_of_dart[2 * a] < 0 || s.patch_of_dart[2 * a + 1] < 0;
      if (group.size() != 2 || !boundary_arc) return false;
      m_arc = a;
      m_index = paths_[a].size() / 2;
    } else if (boundary_nodes.size() == 1) {
      for (int a : group_arcs) {
        if (s.arcs[a].from == boundary_nodes[0]) m_arc = a, m_index = 0;
        if (s.arcs[a].to == boundary_nodes[0]) m_arc = a, m_index = paths_[a].size() - 1;
      }
    } else {
      // The interior path vertex nearest to the group's centroid.
      Vec3 c(0, 0, 0);
      for (int n : group) c += quads_.point(VH(s.node_vertex[n]));
      c /= static_cast<double>(group.size());
      double best = std::numeric_limits<double>::infinity();
      for (int a : group_arcs) {
        const auto& p = paths_[a];
        for (size_t i = 1; i + 1 < p.size(); ++i) {
          if (quads_.is_boundary(VH(p[i])) || node_at_vertex[p[i]] >= 0) continue;
          const double d = (quads_.point(VH(p[i])) - c).sqrnorm();
          if (d < best) best = d, m_arc = a, m_index = i;
        }
      }
      if (m_arc < 0) {
        // No inner vertex: a node of the group itself.
        m_arc = group_arcs[0];
        m_index = 0;
      }
    }
    if (m_arc < 0) return false;
    const auto& mp = paths_[m_arc];
    const int mv = mp[m_index];
    if (node_at_vertex[mv] >= 0 && find(parent, node_at_vertex[mv]) != root) return false;
    new_vertices.push_back(mv);
    // Walks from every group node to the merge point, over a spanning tree of the group's
    // crossed arcs.
    const int x = s.arcs[m_arc].from, y = s.arcs[m_arc].to;
    ext[x].assign(mp.begin(), mp.begin() + m_index + 1);              // x ... m
    ext[y].assign(mp.rbegin(), mp.rbegin() + (mp.size() - m_index));  // y ... m
    has_ext[x] = has_ext[y] = 1;
    for (bool grew = true; grew;) {
      grew = false;
      for (int a : group_arcs) {
        const int u = s.arcs[a].from, w = s.arcs[a].to;
        if (has_ext[u] == has_ext[w]) continue;
        const auto& p = paths_[a];
        if (has_ext[u]) {  // w ... u ... m
          ext[w].assign(p.rbegin(), p.rend());
          ext[w].insert(ext[w].end(), ext[u].begin() + 1, ext[u].end());
          has_ext[w] = 1;
        } else {  // u ... w ... m
          ext[u] = p;
          ext[u].insert(ext[u].end(), ext[w].begin() + 1, ext[w].end());
          has_ext[u] = 1;
        }
        grew = true;
      }
    }
    bool boundary = false;
    for (int n : group) {
      if (!has_ext[n]) return false;
      reduce_walk(ext[n]);
      boundary = boundary || s.node_boundary[n];
      if (n != root) s.node_alive[n] = 0;
    }
    s.node_vertex[root] = mv;
    s.node_boundary[root] = boundary;
  }
  {
    std::vector<int> v = new_vertices;
    std::sort(v.begin(), v.end());
    if (std::adjacent_find(v.begin(), v.end()) != v.end()) return false;
  }
  for (int d : crossing) s.arcs[d >> 1].alive = 0;
  for (auto& arc : s.arcs) {
    if (!arc.alive) continue;
    arc.from = find(parent, arc.from);
    arc.to = find(parent, arc.to);
  }
  // Extended length of an arc (its old ends, walked on to the merge points).
  auto extended_length = [&](int a) {
    return length_[a] + path_length(ext[s_.arcs[a].from]) + path_length(ext[s_.arcs[a].to]);
  };
  std::vector<int> removed_arcs;
  for (const Chain& chain : chains) {
    int keep = chain.arcs.front(), drop = chain.arcs.back();
    int keep_outer = chain.first_outer, drop_outer = chain.last_outer;
    const bool b0 = s.patch_of_dart[keep_outer] < 0, b1 = s.patch_of_dart[drop_outer] < 0;
    if (b1 || (!b0 && extended_length(drop) < extended_length(keep))) {
      std::swap(keep, drop);
      std::swap(keep_outer, drop_outer);
    }
    // The kept arc's other dart takes the place of the dropped end's outer dart.
    const int q = s.patch_of_dart[drop_outer];
    s.patches[q][position(s, q, drop_outer)] = keep_outer ^ 1;
    s.patch_of_dart[keep_outer ^ 1] = q;
    for (int a : chain.arcs) {
      if (a == keep) continue;
      s.patch_of_dart[2 * a] = s.patch_of_dart[2 * a + 1] = -1;
      s.arcs[a].alive = 0;
      removed_arcs.push_back(a);
    }
  }
  for (int p : chord.patches) s.patch_alive[p] = 0;
  // Checks on the result.
  std::vector<char> affected(n_nodes, 0);
  for (int x : reps) affected[x] = 1;
  for (const auto& arc : s.arcs)
    if (arc.alive && arc.from == arc.to && affected[arc.from]) return false;
  std::vector<int> affected_patches;
  for (size_t p = 0; p < s.patches.size(); ++p) {
    if (!s.patch_alive[p]) continue;
    bool hit = false;
    std::array<int, 4> corner{}, side{};
    for (int i = 0; i < 4; ++i) {
      corner[i] = start_in(s, s.patches[p][i]);
      side[i] = s.patches[p][i] >> 1;
      hit = hit || affected[corner[i]];
    }
    if (!hit) continue;
    for (int i = 0; i < 4; ++i) {
      if (!s.arcs[side[i]].alive || s.patch_of_dart[s.patches[p][i]] != static_cast<int>(p))
        return false;
      if (start_in(s, s.patches[p][i] ^ 1) != corner[(i + 1) % 4]) return false;
    }
    affected_patches.push_back(static_cast<int>(p));
    std::sort(corner.begin(), corner.end());
    std::sort(side.begin(), side.end());
    if (std::adjacent_find(corner.begin(), corner.end()) != corner.end() ||
        std::adjacent_find(side.begin(), side.end()) != side.end())
      return false;
  }
  for (int x : reps)
    if (!in_range(valence_of(s, x), s.node_boundary[x])) return false;

  // Commit: the arcs at merged nodes run on to the merge points.
  for (size_t a = 0; a < s.arcs.size(); ++a) {
    if (!s.arcs[a].alive) continue;
    const int from = s_.arcs[a].from, to = s_.arcs[a].to;
    if (ext[from].size() < 2 && ext[to].size() < 2) continue;
    std::vector<int> p;
    if (s.patch_of_dart[2 * a] < 0 || s.patch_of_dart[2 * a + 1] < 0) {
      // Boundary arcs walk along the boundary to the merge points.
      p.assign(ext[from].rbegin(), ext[from].rend());  // m ... from
      if (!p.empty()) p.pop_back();
      p.insert(p.end(), paths_[a].begin(), paths_[a].end());
      if (!ext[to].empty()) p.insert(p.end(), ext[to].begin() + 1, ext[to].end());  // ... m
    } else {
      // Inner arcs jump straight from the merge points to where they are farther from the
      // old node than the merge point is (so arcs that left the old node in different
      // directions also leave the merge point in different directions, and share no walk).
      const auto& q = paths_[a];
      size_t first = 0, last = q.size() - 1;
      auto reach = [&](int node) {
        return ext[node].empty()
                   ? 0.0
                   : (quads_.point(VH(ext[node].back())) - quads_.point(VH(ext[node].front())))
                         .norm();
      };
      const double r_from = reach(from), r_to = reach(to);
      while (first + 1 < last &&
             (quads_.point(VH(q[first])) - quads_.point(VH(q.front()))).norm() < r_from)
        ++first;
      while (last > first + 1 &&
             (quads_.point(VH(q[last])) - quads_.point(VH(q.back()))).norm() < r_to)
        --last;
      if (!ext[from].empty()) p.push_back(ext[from].back());
      p.insert(p.end(), q.begin() + first, q.begin() + last + 1);
      if (!ext[to].empty()) p.push_back(ext[to].back());
    }
    reduce_walk(p);
    paths_[a] = std::move(p);
    length_[a] = path_length(paths_[a]);
  }
  for (int p : chord.patches) touched[p] = 1;
  for (int p : affected_patches) touched[p] = 1;
  for (int a : removed_arcs) paths_[a].clear();
  for (int d : crossing) paths_[d >> 1].clear();
  s_ = std::move(s);
  return true;
}

}  // namespace qs
