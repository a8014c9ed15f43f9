#include "core/import/patch_import.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/layout/validate.h"

namespace qs {

namespace {

using HH = OpenMesh::HalfedgeHandle;
using VH = OpenMesh::VertexHandle;
using FH = OpenMesh::FaceHandle;

std::vector<long long> read_integers(const std::string& path, const std::string& what) {
  std::ifstream in(path);
  if (!in) throw InvalidInputError("cannot read the " + what + " file " + path);
  std::vector<long long> values;
  std::string token;
  while (in >> token) {
    try {
      size_t used = 0;
      const long long v = std::stoll(token, &used);
      if (used != token.size()) throw std::invalid_argument(token);
      values.push_back(v);
    } catch (const std::exception&) {
      throw InvalidInputError("the " + what + " file " + path + " has a non-integer entry '" +
                              token + "' (entry " + std::to_string(values.size() + 1) + ")");
    }
  }
  return values;
}

std::string patch_name(int p) {
  return "patch " + std::to_string(p);
}

// One end choice of a path: a vertex and the extra cost of ending there.
struct TargetChoice {
  int vertex = -1;
  double cost = 0;
};

// Vertex-disjoint edge paths from \p centre, one to a vertex of every group of \p targets
// (result in group order, each path ending at the chosen vertex), through vertices with
// interior[v] != 0 only, of least total length plus end costs: a min-cost flow on the
// vertex-split graph (successive shortest paths, Bellman–Ford on the residual graph; the graphs
// are one patch, so small). Groups must not share vertices. Empty when no such paths exist. In
// a disk with the targets on its boundary, disjoint paths leave the centre in the targets'
// cyclic order.
std::vector<std::vector<int>> disjoint_paths(const TriMesh& mesh, int centre,
                                             const std::vector<std::vector<TargetChoice>>& targets,
                                             const std::vector<int>& region,
                                             const std::vector<char>& interior) {
  // Graph nodes: in and out per region vertex, the source (centre), one node per target
  // choice, one per group, the sink.
  std::vector<int> local(mesh.n_vertices(), -1);
  for (size_t i = 0; i < region.size(); ++i) local[region[i]] = static_cast<int>(i);
  const int n_region = static_cast<int>(region.size());
  const int source = 2 * n_region, first_choice = source + 1;
  std::vector<int> choice_vertex, choice_group;
  std::vector<double> choice_cost;
  std::vector<int> choice_of(mesh.n_vertices(), -1);
  for (size_t g = 0; g < targets.size(); ++g) {
    for (const TargetChoice& t : targets[g]) {
      choice_of[t.vertex] = static_cast<int>(choice_vertex.size());
      choice_vertex.push_back(t.vertex);
      choice_group.push_back(static_cast<int>(g));
      choice_cost.push_back(t.cost);
    }
  }
  const int first_group = first_choice + static_cast<int>(choice_vertex.size());
  const int sink = first_group + static_cast<int>(targets.size());
  struct Edge {
    int to, cap;
    double cost;
  };
  std::vector<Edge> edges;
  std::vector<std::vector<int>> out(sink + 1);
  auto add = [&](int u, int w, double cost) {
    out[u].push_back(static_cast<int>(edges.size()));
    edges.push_back({w, 1, cost});
    out[w].push_back(static_cast<int>(edges.size()));
    edges.push_back({u, 0, -cost});
  };
  auto length = [&](int u, int w) { return (mesh.point(VH(u)) - mesh.point(VH(w))).norm(); };
  for (size_t c = 0; c < choice_vertex.size(); ++c) {
    add(first_choice + static_cast<int>(c), first_group + choice_group[c], choice_cost[c]);
  }
  for (size_t g = 0; g < targets.size(); ++g) add(first_group + static_cast<int>(g), sink, 0);
  auto connect = [&](int from_node, int from_vertex, int w) {
    if (choice_of[w] >= 0) {
      add(from_node, first_choice + choice_of[w], length(from_vertex, w));
    } else if (local[w] >= 0 && interior[w] && w != centre) {
      add(from_node, 2 * local[w], length(from_vertex, w));
    }
  };
  for (int i = 0; i < n_region; ++i) {
    const int v = region[i];
    if (v == centre || !interior[v] || choice_of[v] >= 0) continue;
    add(2 * i, 2 * i + 1, 0);
    for (const auto w : mesh.vv_range(VH(v))) connect(2 * i + 1, v, w.idx());
  }
  for (const auto w : mesh.vv_range(VH(centre))) connect(source, centre, w.idx());

  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> dist(sink + 1);
  std::vector<int> via(sink + 1);
  std::vector<char> queued(sink + 1);
  for (size_t unit = 0; unit < targets.size(); ++unit) {
    std::fill(dist.begin(), dist.end(), inf);
    std::fill(via.begin(), via.end(), -1);
    std::fill(queued.begin(), queued.end(), 0);
    dist[source] = 0;
    // Bellman–Ford (queue-based); residual costs may be negative, no negative cycles.
    std::vector<int> queue{source};
    queued[source] = 1;
    for (size_t head = 0; head < queue.size(); ++head) {
      const int u = queue[head];
      queued[u] = 0;
      for (int e : out[u]) {
        if (edges[e].cap <= 0) continue;
        const double nd = dist[u] + edges[e].cost;
        if (nd < dist[edges[e].to] - 1e-15) {
          dist[edges[e].to] = nd;
          via[edges[e].to] = e;
          if (!queued[edges[e].to]) queued[edges[e].to] = 1, queue.push_back(edges[e].to);
        }
      }
    }
    if (dist[sink] == inf) return {};
    for (int v = sink; v != source; v = edges[via[v] ^ 1].to) {
      edges[via[v]].cap -= 1;
      edges[via[v] ^ 1].cap += 1;
    }
  }
  // Decompose: follow saturated forward edges from the source.
  std::vector<std::vector<int>> paths(targets.size());
  for (int e0 : out[source]) {
    if ((e0 & 1) || edges[e0].cap != 0) continue;
    std::vector<int> path{centre};
    int node = edges[e0].to;
    while (node < first_choice) {
      path.push_back(region[node / 2]);
      int next = -1;
      for (int e : out[node | 1]) {
        if (!(e & 1) && edges[e].cap == 0) next = edges[e].to;
      }
      if (next < 0) return {};  // cannot happen for a valid flow
      node = next;
    }
    const int c = node - first_choice;
    path.push_back(choice_vertex[c]);
    paths[choice_group[c]] = std::move(path);
  }
  for (const auto& path : paths) {
    if (path.empty()) return {};
  }
  return paths;
}

// An arc from a patch centre: to a ring node (target) or to the second centre.
struct Spoke {
  int centre = 0;  // 0 or 1
  int target = -1;
  std::vector<int> path;  // centre vertex first
};

// Two centres for a patch that no single centre fits (e.g. a neck of the patch hides several
// sides): its sides' midpoint groups (counter-clockwise) are split into two cyclic ranges that
// overlap in their end midpoints x and y; centre 0 is joined to x, .., y and centre 1 to
// y, .., x, so besides one quad per corner there is the quad (centre 0, x, centre 1, y): k + 1
// quads. Tries every pair (x, y) and a few centre candidates per range (the interior vertices
// with the least hop distance to the farthest midpoint of their range), routing the larger
// range first. Empty when nothing fits.
std::vector<Spoke> two_centre_spokes(const TriMesh& mesh,
                                     const std::vector<std::vector<TargetChoice>>& groups,
                                     const std::vector<int>& interior_vertices,
                                     const std::vector<int>& region, std::vector<char>& interior,
                                     const std::vector<int>& hops) {
  const int k = static_cast<int>(groups.size());
  // Hop distance from every group (any of its vertices) through the interior.
  std::vector<std::vector<int>> dist(k, std::vector<int>(mesh.n_vertices(), -1));
  for (int g = 0; g < k; ++g) {
    std::vector<int> queue;
    for (const TargetChoice& t : groups[g]) dist[g][t.vertex] = 0, queue.push_back(t.vertex);
    for (size_t head = 0; head < queue.size(); ++head) {
      const int v = queue[head];
      for (const auto w : mesh.vv_range(VH(v))) {
        if (interior[w.idx()] && dist[g][w.idx()] < 0) {
          dist[g][w.idx()] = dist[g][v] + 1;
          queue.push_back(w.idx());
        }
      }
    }
  }
  auto best_centres = [&](const std::vector<int>& which, int avoid) {
    std::vector<std::pair<int, int>> scored;
    for (int v : interior_vertices) {
      if (v == avoid || hops[v] <= 0 || mesh.valence(VH(v)) < which.size()) continue;
      int worst = 0;
      for (int g : which) worst = dist[g][v] < 0 ? 1 << 20 : std::max(worst, dist[g][v]);
      if (worst < (1 << 20)) scored.push_back({worst, v});
    }
    std::sort(scored.begin(), scored.end());
    std::vector<int> out;
    for (size_t i = 0; i < scored.size() && i < 3; ++i) out.push_back(scored[i].second);
    return out;
  };
  for (int x = 0; x < k; ++x) {
    for (int len = 2; len <= k; ++len) {  // range 0: x, x+1, .., x+len−1 (= y)
      const int y = (x + len - 1) % k;
      std::vector<int> range[2];
      for (int i = 0; i < len; ++i) range[0].push_back((x + i) % k);
      for (int i = 0; i <= k - len + 1; ++i) range[1].push_back((y + i) % k);
      if (range[1].size() < 2 || range[1].size() > range[0].size()) continue;  // each split once
      const std::vector<int> first_candidates = best_centres(range[0], -1);
      for (int c0 : first_candidates) {
        std::vector<std::vector<TargetChoice>> g0;
        for (int g : range[0]) g0.push_back(groups[g]);
        auto paths0 = disjoint_paths(mesh, c0, g0, region, interior);
        if (paths0.empty()) continue;
        std::vector<int> used;
        for (const auto& path : paths0)
          for (int v : path)
            if (interior[v]) interior[v] = 0, used.push_back(v);
        std::vector<std::vector<TargetChoice>> g1;
        for (int g : range[1]) g1.push_back(groups[g]);
        g1.front() = {{paths0.back().back(), 0.0}};  // y, as chosen by centre 0
        g1.back() = {{paths0.front().back(), 0.0}};  // x
        std::vector<std::vector<int>> paths1;
        for (int c1 : best_centres(range[1], c0)) {
          if (!interior[c1]) continue;
          paths1 = disjoint_paths(mesh, c1, g1, region, interior);
          if (!paths1.empty()) break;
        }
        for (int v : used) interior[v] = 1;
        if (paths1.empty()) continue;
        std::vector<Spoke> spokes;
        for (auto& path : paths0) spokes.push_back({0, path.back(), std::move(path)});
        for (auto& path : paths1) spokes.push_back({1, path.back(), std::move(path)});
        return spokes;
      }
    }
  }
  return {};
}

}  // namespace

PatchPartition load_quadwild_partition(const TriMesh& mesh, const std::string& patch_file,
                                       const std::string& corners_file) {
  const std::vector<long long> ids = read_integers(patch_file, "patch");
  const std::vector<long long> cs = read_integers(corners_file, "corners");
  if (cs.empty() || cs[0] <= 0) {
    throw InvalidInputError("the corners file " + corners_file +
                            " must start with a positive patch count");
  }
  const long long n_patches = cs[0];
  PatchPartition partition;
  size_t at = 1;
  for (long long p = 0; p < n_patches; ++p) {
    if (at >= cs.size() || cs[at] < 0 || cs[at] > static_cast<long long>(cs.size() - at - 1)) {
      throw InvalidInputError("the corners file " + corners_file + " ends inside " +
                              patch_name(static_cast<int>(p)) + " (it announces " +
                              std::to_string(n_patches) + " patches)");
    }
    std::vector<int> corners;
    for (long long k = 0; k < cs[at]; ++k) {
      const long long v = cs[at + 1 + k];
      if (v < 0 || v >= static_cast<long long>(mesh.n_vertices())) {
        throw InvalidInputError("the corners file " + corners_file + ": " +
                                patch_name(static_cast<int>(p)) + " has corner vertex " +
                                std::to_string(v) + ", but the mesh has " +
                                std::to_string(mesh.n_vertices()) + " vertices");
      }
      corners.push_back(static_cast<int>(v));
    }
    at += 1 + cs[at];
    partition.corners.push_back(std::move(corners));
  }
  if (at != cs.size()) {
    throw InvalidInputError("the corners file " + corners_file + " has " +
                            std::to_string(cs.size() - at) + " extra entries after " +
                            std::to_string(n_patches) + " patches");
  }
  if (ids.empty() || ids[0] != static_cast<long long>(mesh.n_faces()) ||
      ids.size() != mesh.n_faces() + 1) {
    throw InvalidInputError("the patch file " + patch_file + " must hold the face count (" +
                            std::to_string(mesh.n_faces()) +
                            " for this mesh) and one patch id per face; it holds " +
                            std::to_string(ids.size()) + " entries" +
                            (ids.empty() ? "" : " starting with " + std::to_string(ids[0])));
  }
  for (size_t f = 0; f + 1 < ids.size(); ++f) {
    const long long p = ids[f + 1];
    if (p < 0 || p >= n_patches) {
      throw InvalidInputError("the patch file " + patch_file + ": face " + std::to_string(f) +
                              " has patch id " + std::to_string(p) + ", expected 0 .. " +
                              std::to_string(n_patches - 1));
    }
    partition.face_patch.push_back(static_cast<int>(p));
  }
  return partition;
}

Layout layout_from_partition(const TriMesh& mesh, const PatchPartition& partition,
                             PatchLayoutStats* stats, int* bad_patch) {
  if (bad_patch) *bad_patch = -1;
  auto blame = [&](int p) {
    if (bad_patch) *bad_patch = p;
  };
  const int nv = static_cast<int>(mesh.n_vertices());
  const int n_patches = static_cast<int>(partition.corners.size());
  if (partition.face_patch.size() != mesh.n_faces()) {
    throw InvalidInputError("the patch partition has " +
                            std::to_string(partition.face_patch.size()) + " face ids for " +
                            std::to_string(mesh.n_faces()) + " faces");
  }
  for (int p : partition.face_patch) {
    if (p < 0 || p >= n_patches) {
      throw InvalidInputError("patch id " + std::to_string(p) + " out of range (" +
                              std::to_string(n_patches) + " patches)");
    }
  }
  auto patch_of = [&](HH h) {
    const FH f = mesh.face_handle(h);
    return f.is_valid() ? partition.face_patch[f.idx()] : -1;
  };
  // Patch boundaries: edges between different patches and mesh boundary edges.
  std::vector<char> marked(mesh.n_edges(), 0);
  std::vector<int> degree(nv, 0);
  for (const auto e : mesh.edges()) {
    const HH h0 = mesh.halfedge_handle(e, 0), h1 = mesh.halfedge_handle(e, 1);
    if (patch_of(h0) == patch_of(h1)) continue;
    marked[e.idx()] = 1;
    ++degree[mesh.from_vertex_handle(h0).idx()];
    ++degree[mesh.to_vertex_handle(h0).idx()];
  }
  // Nodes: listed corners and every vertex where 3 or more boundary edges meet.
  std::vector<char> is_corner(nv, 0);
  for (int p = 0; p < n_patches; ++p) {
    for (int v : partition.corners[p]) {
      if (v < 0 || v >= nv) {
        throw InvalidInputError(patch_name(p) + " has corner vertex " + std::to_string(v) +
                                " out of range");
      }
      if (degree[v] == 0) {
        throw InvalidInputError(patch_name(p) + ": corner vertex " + std::to_string(v) +
                                " is not on any patch boundary");
      }
      is_corner[v] = 1;
    }
  }
  for (int v = 0; v < nv; ++v) is_corner[v] = is_corner[v] || degree[v] >= 3;

  // Sides (arcs of the partition): maximal chains of boundary edges between corners.
  std::vector<std::vector<int>> sides;
  std::vector<int> side_of_edge(mesh.n_edges(), -1);
  for (int v = 0; v < nv; ++v) {
    if (!is_corner[v]) continue;
    for (const HH start : mesh.voh_range(VH(v))) {
      if (!marked[mesh.edge_handle(start).idx()] ||
          side_of_edge[mesh.edge_handle(start).idx()] >= 0)
        continue;
      const int s = static_cast<int>(sides.size());
      std::vector<int> path{v};
      HH h = start;
      while (true) {
        side_of_edge[mesh.edge_handle(h).idx()] = s;
        const VH w = mesh.to_vertex_handle(h);
        path.push_back(w.idx());
        if (is_corner[w.idx()]) break;
        HH next;
        for (const HH g : mesh.voh_range(w)) {
          const int e = mesh.edge_handle(g).idx();
          if (marked[e] && side_of_edge[e] < 0) next = g;
        }
        if (!next.is_valid()) break;  // cannot happen: non-corners have two boundary edges
        h = next;
      }
      sides.push_back(std::move(path));
    }
  }
  for (const auto e : mesh.edges()) {
    if (marked[e.idx()] && side_of_edge[e.idx()] < 0) {
      const HH h = mesh.halfedge_handle(e, 0);
      const int p = std::max(patch_of(h), patch_of(mesh.opposite_halfedge_handle(h)));
      blame(p);
      throw InvalidInputError("the boundary loop of " + patch_name(p) + " through vertex " +
                              std::to_string(mesh.from_vertex_handle(h).idx()) + " has no corner");
    }
  }
  // Midpoint candidates of every side: its interior vertices that the interiors of both
  // adjacent patches reach (a vertex with an interior neighbour on either side), each with the
  // cost of ending a centre path there (its distance along the side from half the side's
  // length); vertices farther than 30% of the side's length from its middle only when nothing
  // else fits. The midpoint is fixed by the first patch that routes to it.
  auto reachable_from_both = [&](int v) {
    int sides_reached = 0, sides_needed = 0;
    for (const HH h : mesh.voh_range(VH(v))) {
      // Each patch boundary edge at v starts a sector of faces of one patch (or the outside).
      if (!marked[mesh.edge_handle(h).idx()] || !mesh.face_handle(h).is_valid()) continue;
      ++sides_needed;
      bool reached = false;
      for (HH g = h; !reached;) {
        reached = degree[mesh.to_vertex_handle(g).idx()] == 0;
        g = mesh.opposite_halfedge_handle(mesh.prev_halfedge_handle(g));  // counter-clockwise
        if (marked[mesh.edge_handle(g).idx()]) break;
      }
      sides_reached += reached;
    }
    return sides_reached == sides_needed;
  };
  std::vector<std::vector<TargetChoice>> side_choices(sides.size());
  std::vector<int> side_mid(sides.size(), -1);  // index into the side's path once fixed
  for (size_t s = 0; s < sides.size(); ++s) {
    const auto& p = sides[s];
    if (p.size() < 3) {
      const HH h = mesh.find_halfedge(VH(p[0]), VH(p[1]));
      blame(std::max(patch_of(h), patch_of(mesh.opposite_halfedge_handle(h))));
      throw InvalidInputError("the side from vertex " + std::to_string(p.front()) + " to " +
                              std::to_string(p.back()) +
                              " is a single mesh edge, so it has no midpoint vertex (the mesh "
                              "is too coarse there)");
    }
    std::vector<double> along(p.size(), 0);
    for (size_t k = 1; k < p.size(); ++k)
      along[k] = along[k - 1] + (mesh.point(VH(p[k])) - mesh.point(VH(p[k - 1]))).norm();
    const double half = 0.5 * along.back();
    std::vector<TargetChoice> near, far;
    for (size_t k = 1; k + 1 < p.size(); ++k) {
      if (!reachable_from_both(p[k])) continue;
      const double off = std::abs(along[k] - half);
      (off <= 0.3 * along.back() ? near : far).push_back({p[k], off});
    }
    side_choices[s] = near.empty() ? far : near;
    if (side_choices[s].empty()) {
      // No vertex of the side reaches both interiors: keep the middle one (routing fails there
      // with a clear error).
      size_t best = 1;
      for (size_t k = 1; k + 1 < p.size(); ++k)
        if (std::abs(along[k] - half) < std::abs(along[best] - half)) best = k;
      side_choices[s].push_back({p[best], 0.0});
    }
  }

  // Each patch: one boundary loop, as its sides in counter-clockwise order (side, forward?).
  struct PatchSide {
    int side = -1;
    bool forward = true;  // the loop runs along the side from its first to its last vertex
  };
  std::vector<std::vector<PatchSide>> patch_sides(n_patches);
  std::vector<int> face_count(n_patches, 0);
  for (int p : partition.face_patch) ++face_count[p];
  std::vector<char> halfedge_done(mesh.n_halfedges(), 0);
  std::vector<int> loops(n_patches, 0);
  for (const auto h0 : mesh.halfedges()) {
    const int p = patch_of(h0);
    if (p < 0 || halfedge_done[h0.idx()] || !marked[mesh.edge_handle(h0).idx()]) continue;
    ++loops[p];
    HH h = h0;
    do {
      halfedge_done[h.idx()] = 1;
      const int s = side_of_edge[mesh.edge_handle(h).idx()];
      const auto& path = sides[s];
      const bool starts_side = mesh.from_vertex_handle(h).idx() == path.front() &&
                               mesh.to_vertex_handle(h).idx() == path[1];
      const bool starts_back = mesh.from_vertex_handle(h).idx() == path.back() &&
                               mesh.to_vertex_handle(h).idx() == path[path.size() - 2];
      if (loops[p] == 1 && (starts_side || starts_back)) {
        patch_sides[p].push_back({s, starts_side && !(starts_back && path.size() == 2)});
      }
      // Next boundary halfedge of the patch: turn around the to-vertex inside the patch.
      HH g = mesh.next_halfedge_handle(h);
      while (!marked[mesh.edge_handle(g).idx()])
        g = mesh.next_halfedge_handle(mesh.opposite_halfedge_handle(g));
      h = g;
    } while (h != h0);
  }
  // Disk check: one boundary loop and Euler characteristic 1.
  {
    std::vector<int> vcount(n_patches, 0), ecount(n_patches, 0);
    std::vector<int> seen(nv, -1);
    std::vector<std::vector<int>> patch_faces(n_patches);
    for (const auto f : mesh.faces()) patch_faces[partition.face_patch[f.idx()]].push_back(f.idx());
    for (int p = 0; p < n_patches; ++p) {
      for (int f : patch_faces[p]) {
        for (const auto v : mesh.fv_range(FH(f))) {
          if (seen[v.idx()] != p) seen[v.idx()] = p, ++vcount[p];
        }
        for (const HH h : mesh.fh_range(FH(f))) {
          const HH o = mesh.opposite_halfedge_handle(h);
          // Count an edge once: from the face with the larger index, or when the other side
          // is another patch or outside.
          if (patch_of(o) != p || mesh.face_handle(o).idx() < f) ++ecount[p];
        }
      }
      if (face_count[p] == 0) {
        blame(p);
        throw InvalidInputError(patch_name(p) + " has no faces");
      }
      const int euler = vcount[p] - ecount[p] + face_count[p];
      if (loops[p] != 1 || euler != 1) {
        blame(p);
        throw InvalidInputError(patch_name(p) + " is not a disk (" + std::to_string(loops[p]) +
                                " boundary loop(s), Euler characteristic " + std::to_string(euler) +
                                ")");
      }
      if (patch_sides[p].size() < 2) {
        blame(p);
        throw InvalidInputError(patch_name(p) + " has " + std::to_string(patch_sides[p].size()) +
                                " side(s); at least 2 are needed");
      }
    }
  }

  // Centres and their paths to the side midpoints, patch by patch: the patches with the most
  // sides and the least room first (they need the freedom to choose midpoints).
  std::vector<char> allowed(nv, 0);
  std::vector<int> hops(nv, -1);
  std::vector<std::vector<int>> patch_vertices(n_patches);
  {
    std::vector<int> seen(nv, -1);
    for (const auto f : mesh.faces()) {
      const int p = partition.face_patch[f.idx()];
      for (const auto v : mesh.fv_range(f)) {
        if (degree[v.idx()] == 0 && seen[v.idx()] != p) {
          seen[v.idx()] = p;
          patch_vertices[p].push_back(v.idx());
        }
      }
    }
  }
  std::vector<int> patch_order(n_patches);
  for (int p = 0; p < n_patches; ++p) patch_order[p] = p;
  std::stable_sort(patch_order.begin(), patch_order.end(), [&](int a, int b) {
    if (patch_sides[a].size() != patch_sides[b].size())
      return patch_sides[a].size() > patch_sides[b].size();
    return patch_vertices[a].size() < patch_vertices[b].size();
  });
  auto mid_vertex = [&](int s) { return sides[s][side_mid[s]]; };
  auto fix_mid = [&](int s, int v) {
    side_mid[s] =
        static_cast<int>(std::find(sides[s].begin(), sides[s].end(), v) - sides[s].begin());
  };
  std::vector<std::vector<Spoke>> patch_spokes(n_patches);
  std::vector<int> patch_quads(n_patches, 0), patch_centre_count(n_patches, 0);
  for (int p : patch_order) {
    const auto& ps = patch_sides[p];
    const int k = static_cast<int>(ps.size());
    // Hop distance from the patch boundary (multi-source BFS over the patch's vertices).
    std::vector<int> queue;
    for (int v : patch_vertices[p]) {
      allowed[v] = 1;
      for (const auto w : mesh.vv_range(VH(v))) {
        if (degree[w.idx()] > 0) {
          hops[v] = 1;
          queue.push_back(v);
          break;
        }
      }
    }
    for (size_t head = 0; head < queue.size(); ++head) {
      const int v = queue[head];
      for (const auto w : mesh.vv_range(VH(v))) {
        if (allowed[w.idx()] && hops[w.idx()] < 0) {
          hops[w.idx()] = hops[v] + 1;
          queue.push_back(w.idx());
        }
      }
    }
    std::vector<int> candidates;
    for (int v : patch_vertices[p]) {
      if (static_cast<int>(mesh.valence(VH(v))) >= k && hops[v] > 0) candidates.push_back(v);
    }
    std::stable_sort(candidates.begin(), candidates.end(),
                     [&](int a, int b) { return hops[a] > hops[b]; });
    std::vector<int> region = patch_vertices[p];
    std::vector<std::vector<TargetChoice>> groups;
    for (const PatchSide& side : ps) {
      const int s = side.side;
      groups.push_back(side_mid[s] >= 0 ? std::vector<TargetChoice>{{mid_vertex(s), 0.0}}
                                        : side_choices[s]);
      for (const TargetChoice& t : groups.back()) region.push_back(t.vertex);
    }

    // One centre joined to a midpoint of every side (k quads) ...
    std::vector<Spoke> spokes;
    for (size_t ci = 0; ci < candidates.size() && ci < 16 && spokes.empty(); ++ci) {
      auto paths = disjoint_paths(mesh, candidates[ci], groups, region, allowed);
      for (auto& path : paths) spokes.push_back({0, path.back(), std::move(path)});
    }
    int n_centres = 1;
    if (!spokes.empty()) {
      for (int i = 0; i < k; ++i) fix_mid(ps[i].side, spokes[i].target);
    } else {
      // ... else two centres sharing two midpoints (k + 1 quads).
      n_centres = 2;
      spokes = two_centre_spokes(mesh, groups, patch_vertices[p], region, allowed, hops);
      for (const Spoke& spoke : spokes) {
        for (const PatchSide& side : ps) {
          const auto& path = sides[side.side];
          if (std::find(path.begin() + 1, path.end() - 1, spoke.target) != path.end() - 1)
            fix_mid(side.side, spoke.target);
        }
      }
    }
    for (int v : patch_vertices[p]) allowed[v] = 0, hops[v] = -1;
    if (spokes.empty()) {
      blame(p);
      throw InvalidInputError(
          patch_name(p) + " (" + std::to_string(k) + " sides, " +
          std::to_string(patch_vertices[p].size()) +
          " interior vertices) cannot be split into quads: no interior vertex (or pair of "
          "vertices) reaches the midpoints of its sides by disjoint edge paths (the mesh is "
          "too coarse there)");
    }
    patch_spokes[p] = std::move(spokes);
    patch_centre_count[p] = n_centres;
    patch_quads[p] = n_centres == 1 ? k : k + 1;
  }

  // Nodes: corners (ascending vertex), side midpoints (side order), centres (patch order).
  Layout layout;
  layout.mesh_vertices = nv;
  layout.mesh_faces = static_cast<int>(mesh.n_faces());
  std::vector<int> node_of_vertex(nv, -1);
  auto add_node = [&](int v) {
    LayoutNode node;
    node.id = static_cast<int>(layout.nodes.size());
    node.vertex = v;
    node_of_vertex[v] = node.id;
    layout.nodes.push_back(node);
    return node.id;
  };
  int n_corners = 0;
  for (int v = 0; v < nv; ++v) {
    if (is_corner[v]) add_node(v), ++n_corners;
  }
  std::vector<int> mid_node(sides.size());
  for (size_t s = 0; s < sides.size(); ++s) mid_node[s] = add_node(mid_vertex(s));
  std::vector<std::vector<int>> patch_centres(n_patches);
  for (int p = 0; p < n_patches; ++p) {
    for (int i = 0; i < patch_centre_count[p]; ++i) {
      for (const Spoke& spoke : patch_spokes[p]) {
        if (spoke.centre == i) {
          patch_centres[p].push_back(add_node(spoke.path.front()));
          break;
        }
      }
    }
  }
  auto add_arc = [&](int from, int to, std::vector<int> path) {
    LayoutArc arc;
    arc.id = static_cast<int>(layout.arcs.size());
    arc.from = from;
    arc.to = to;
    arc.path = std::move(path);
    layout.arcs.push_back(std::move(arc));
  };
  for (size_t s = 0; s < sides.size(); ++s) {
    const auto& p = sides[s];
    const auto mid = p.begin() + side_mid[s];
    add_arc(node_of_vertex[p.front()], mid_node[s], std::vector<int>(p.begin(), mid + 1));
    add_arc(mid_node[s], node_of_vertex[p.back()], std::vector<int>(mid, p.end()));
  }
  for (int p = 0; p < n_patches; ++p) {
    for (Spoke& spoke : patch_spokes[p]) {
      add_arc(patch_centres[p][spoke.centre], node_of_vertex[spoke.target], std::move(spoke.path));
    }
  }

  if (stats) {
    *stats = {};
    stats->partition_patches = n_patches;
    stats->partition_nodes = n_corners;
    stats->partition_arcs = static_cast<int>(sides.size());
    for (int p = 0; p < n_patches; ++p) {
      stats->sides.push_back(static_cast<int>(patch_sides[p].size()));
      stats->quads.push_back(patch_quads[p]);
      stats->expected_patches += patch_quads[p];
    }
    stats->centres = patch_centres;
  }
  require_valid_layout(mesh, layout, "the layout of the patch partition");
  return layout;
}

}  // namespace qs
