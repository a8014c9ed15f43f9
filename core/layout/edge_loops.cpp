#include "core/layout/edge_loops.h"

#include <algorithm>
#include <string>

#include "core/base/errors.h"
#include "core/layout/path_finder.h"
#include "core/layout/routing.h"
#include "core/layout/validate.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

void require_valid(const TriMesh& mesh, const Layout& layout, const char* what) {
  const ValidationResult v = validate_layout(mesh, layout);
  if (v.valid()) return;
  for (const auto& issue : v.issues)
    if (issue.severity == IssueSeverity::Error)
      throw InvalidInputError(std::string(what) + " needs a valid layout: " + format_issue(issue));
}

std::string arc_name(const Layout& layout, int a) {
  return "arc " + std::to_string(layout.arcs[a].id);
}

std::string node_name(const Layout& layout, int n) {
  return "node " + std::to_string(layout.nodes[n].id);
}

std::string patch_name(const Layout& layout, const LayoutTopology& topo, int p) {
  std::string out = "the patch with corners (nodes";
  const auto& corners = topo.patches[p].corners;
  for (std::size_t k = 0; k < corners.size(); ++k)
    out += (k ? ", " : " ") + std::to_string(layout.nodes[corners[k]].id);
  return out + ")";
}

bool four_sided(const LayoutTopology::Patch& p) {
  return p.darts.size() == 4 && p.corners.size() == 4 && !p.trimmed && p.border_cycles == 1 &&
         p.euler == 1;
}

// The surface point at vertex v (in one of its faces).
SurfacePoint vertex_point(const TriMesh& mesh, int v) {
  for (const auto heh : mesh.voh_range(VH(v))) {
    const auto fh = mesh.face_handle(heh);
    if (!fh.is_valid()) continue;
    SurfacePoint p;
    p.face = fh.idx();
    int k = 0;
    for (const auto wh : mesh.fv_range(fh)) p.bary[k++] = wh.idx() == v ? 1.0 : 0.0;
    return p;
  }
  throw InvalidInputError("vertex " + std::to_string(v) + " has no face");
}

// The point at (1 − t)·a + t·b on edge (a, b), in a face of the edge.
SurfacePoint edge_point(const TriMesh& mesh, int a, int b, double t) {
  auto h = mesh.find_halfedge(VH(a), VH(b));
  if (!h.is_valid())
    throw InvalidInputError("no mesh edge between vertices " + std::to_string(a) + " and " +
                            std::to_string(b));
  auto fh = mesh.face_handle(h);
  if (!fh.is_valid()) fh = mesh.face_handle(mesh.opposite_halfedge_handle(h));
  SurfacePoint p;
  p.face = fh.idx();
  int k = 0;
  for (const auto wh : mesh.fv_range(fh)) {
    p.bary[k] = wh.idx() == a ? 1.0 - t : wh.idx() == b ? t : 0.0;
    ++k;
  }
  return p;
}

std::vector<SurfacePoint> vertex_points(const TriMesh& mesh, const std::vector<int>& path,
                                        std::size_t begin, std::size_t end) {
  std::vector<SurfacePoint> out;
  for (std::size_t k = begin; k < end; ++k) out.push_back(vertex_point(mesh, path[k]));
  return out;
}

void clear_outputs(Layout& layout) {
  for (auto& arc : layout.arcs) {
    arc.label.clear();
    arc.polyline.clear();
    arc.samples.clear();
  }
  for (auto& node : layout.nodes) {
    node.position.reset();
    node.valence = -1;
  }
  layout.patches.clear();
}

// The patch to the left of each half-arc (-1 when none: the mesh boundary), and the half-arc's
// position in that patch's darts.
struct DartPatches {
  std::vector<int> patch, position;
};

DartPatches dart_patches(const LayoutTopology& topo) {
  DartPatches d;
  d.patch.assign(2 * topo.num_arcs, -1);
  d.position.assign(2 * topo.num_arcs, -1);
  for (int p = 0; p < int(topo.patches.size()); ++p)
    for (int k = 0; k < int(topo.patches[p].darts.size()); ++k) {
      d.patch[topo.patches[p].darts[k]] = p;
      d.position[topo.patches[p].darts[k]] = k;
    }
  return d;
}

// An arc as a sequence from one end to the other: its node ids (-1: a dangling end), path and
// points in that order.
struct Piece {
  int start = -1, end = -1;
  std::vector<int> path;
  std::vector<SurfacePoint> points;
  void reverse() {
    std::swap(start, end);
    std::reverse(path.begin(), path.end());
    std::reverse(points.begin(), points.end());
  }
};

Piece piece_of(const LayoutArc& arc) {
  return Piece{arc.from, arc.to, arc.path, arc.points};
}

}  // namespace

PolyChord find_poly_chord(const Layout& layout, const LayoutTopology& topo, int arc_index) {
  if (arc_index < 0 || arc_index >= int(layout.arcs.size()))
    throw InvalidInputError("no arc at index " + std::to_string(arc_index));
  if (layout.arcs[arc_index].dangling())
    throw InvalidInputError(arc_name(layout, arc_index) +
                            " is dangling: edge loops run through patches with 4 arc sides");
  const DartPatches dp = dart_patches(topo);
  // Walks from half-arc h across the patch on its left, and on across the opposite side, until
  // the mesh boundary or back at the start arc. Returns the patches and the far arcs.
  auto walk = [&](int h, std::vector<int>& patches, std::vector<int>& arcs) {
    const int guard = int(topo.patches.size()) + 1;
    for (int steps = 0; steps <= guard; ++steps) {
      const int p = dp.patch[h];
      if (p < 0) return false;  // the mesh boundary
      if (!four_sided(topo.patches[p]))
        throw InvalidInputError("the poly-chord through " + arc_name(layout, arc_index) +
                                " reaches " + patch_name(layout, topo, p) +
                                ", which is not a 4-sided disk: edge loops need 4-sided patches");
      const int opposite = topo.patches[p].darts[(dp.position[h] + 2) % 4];
      patches.push_back(p);
      arcs.push_back(LayoutTopology::arc_of(opposite));
      if (arcs.back() == arc_index) return true;  // closed
      if (layout.arcs[arcs.back()].dangling())
        throw InvalidInputError("the poly-chord through " + arc_name(layout, arc_index) +
                                " reaches the dangling " + arc_name(layout, arcs.back()) +
                                ": edge loops need patches with 4 arc sides");
      h = sigma(opposite);
    }
    throw InvalidInputError("the poly-chord through " + arc_name(layout, arc_index) +
                            " does not close");
  };
  PolyChord chord;
  std::vector<int> fwd_patches, fwd_arcs;
  chord.closed = walk(2 * arc_index, fwd_patches, fwd_arcs);
  if (chord.closed) {
    chord.patches = fwd_patches;
    chord.arcs = {arc_index};
    chord.arcs.insert(chord.arcs.end(), fwd_arcs.begin(), fwd_arcs.end() - 1);
  } else {
    std::vector<int> back_patches, back_arcs;
    walk(2 * arc_index + 1, back_patches, back_arcs);  // cannot close: fwd did not
    chord.patches.assign(back_patches.rbegin(), back_patches.rend());
    chord.patches.insert(chord.patches.end(), fwd_patches.begin(), fwd_patches.end());
    chord.arcs.assign(back_arcs.rbegin(), back_arcs.rend());
    chord.arcs.push_back(arc_index);
    chord.arcs.insert(chord.arcs.end(), fwd_arcs.begin(), fwd_arcs.end());
  }
  if (chord.patches.empty())
    throw InvalidInputError(arc_name(layout, arc_index) + " has no patch on either side");
  std::vector<int> sorted = chord.patches;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k + 1 < sorted.size(); ++k)
    if (sorted[k] == sorted[k + 1])
      throw InvalidInputError("the poly-chord through " + arc_name(layout, arc_index) +
                              " crosses itself in " + patch_name(layout, topo, sorted[k]) +
                              ": edge loops need a chord that passes every patch once");
  if (chord.closed && chord.patches.size() == 1)
    throw InvalidInputError("the poly-chord through " + arc_name(layout, arc_index) +
                            " is a single patch joined to itself: no room for an edge loop");
  return chord;
}

EdgeLoopInsertion insert_edge_loop(const TriMesh& mesh, const Layout& layout, int arc_id) {
  const int start = layout.arc_index(arc_id);
  if (start < 0) throw InvalidInputError("unknown arc " + std::to_string(arc_id));
  require_valid(mesh, layout, "inserting an edge loop");
  const LayoutTopology topo = build_topology(mesh, layout);
  EdgeLoopInsertion result;
  result.chord = find_poly_chord(layout, topo, start);
  const PolyChord& chord = result.chord;
  Layout& out = result.layout;
  out = layout;
  clear_outputs(out);
  int next_node = 0, next_arc = 0;
  for (const auto& node : layout.nodes) next_node = std::max(next_node, node.id + 1);
  for (const auto& a : layout.arcs) next_arc = std::max(next_arc, a.id + 1);

  // Split every crossed arc at its midpoint.
  std::vector<int> node_vertex;
  for (int a : chord.arcs) {
    const LayoutArc& arc = layout.arcs[a];
    const auto& path = arc.path;
    if (path.size() < 3)
      throw InvalidInputError(arc_name(layout, a) +
                              " runs along a single mesh edge: no vertex for the node of an edge "
                              "loop (refine the mesh, or route the arc longer)");
    std::vector<double> cum{0.0};
    for (std::size_t k = 0; k + 1 < path.size(); ++k)
      cum.push_back(cum.back() + (mesh.point(VH(path[k + 1])) - mesh.point(VH(path[k]))).norm());
    const double half = 0.5 * cum.back();
    std::size_t j = 0;
    while (j + 2 < path.size() && cum[j + 1] < half) ++j;
    const double len = cum[j + 1] - cum[j];
    double t = len > 0.0 ? std::clamp((half - cum[j]) / len, 0.0, 1.0) : 0.5;
    // The node's vertex is the edge end the point snaps to; never one of the arc's end nodes.
    if (j == 0) t = std::max(t, 0.5 + 1e-6);
    if (j + 2 == path.size()) t = std::min(t, 0.5 - 1e-6);
    const std::size_t vi = t > 0.5 ? j + 1 : j;
    LayoutNode node;
    node.id = next_node++;
    node.vertex = path[vi];
    node.point = edge_point(mesh, path[j], path[j + 1], t);
    if (snap_to_vertex(mesh, *node.point) != node.vertex) node.point = vertex_point(mesh, path[vi]);
    out.nodes.push_back(node);
    result.new_nodes.push_back(node.id);
    node_vertex.push_back(node.vertex);

    LayoutArc& first = out.arcs[a];
    LayoutArc second = first;
    first.to = node.id;
    first.path.clear();
    first.points = vertex_points(mesh, path, 1, vi);
    second.id = next_arc++;
    second.from = node.id;
    second.path.clear();
    second.points = vertex_points(mesh, path, vi + 1, path.size() - 1);
    result.split_arcs.push_back(second.id);
    out.arcs.push_back(std::move(second));
  }

  // An arc of the loop across every patch of the chord.
  const RoutingObstacles obstacles = obstacles_of_layout(mesh, layout);
  PathFinder finder(mesh);
  const int n = int(chord.arcs.size());
  for (int k = 0; k < int(chord.patches.size()); ++k) {
    const int p = chord.patches[k];
    const int u = k, w = (k + 1) % n;
    std::vector<char> allowed(mesh.n_vertices(), 0);
    for (const auto fh : mesh.faces())
      if (topo.face_patch[fh.idx()] == p)
        for (const auto vh : mesh.fv_range(fh)) allowed[vh.idx()] = 1;
    const std::vector<int> route = finder.find(node_vertex[u], node_vertex[w], obstacles, &allowed);
    LayoutArc arc;
    arc.id = next_arc++;
    arc.from = result.new_nodes[u];
    arc.to = result.new_nodes[w];
    if (route.size() >= 2) arc.points = vertex_points(mesh, route, 1, route.size() - 1);
    result.new_arcs.push_back(arc.id);
    out.arcs.push_back(std::move(arc));
  }
  return result;
}

EdgeLoop find_edge_loop(const TriMesh& mesh, const Layout& layout, const LayoutTopology& topo,
                        int arc_index) {
  if (arc_index < 0 || arc_index >= int(layout.arcs.size()))
    throw InvalidInputError("no arc at index " + std::to_string(arc_index));
  const std::string start_name = arc_name(layout, arc_index);
  auto dangling = [&](int a) {
    return InvalidInputError("the edge loop through " + start_name + " runs into the dangling " +
                             arc_name(layout, a) + ": only loops between nodes can be removed");
  };
  if (layout.arcs[arc_index].dangling()) throw dangling(arc_index);
  auto on_boundary = [&](int node) { return mesh.is_boundary(VH(layout.nodes[node].vertex)); };
  // From half-arc h_in (at its node) on through the node, until a boundary node or back at the
  // start arc. Appends the nodes passed and the arcs after them; returns true when closed.
  auto walk = [&](int h_in, std::vector<int>& nodes, std::vector<int>& arcs) {
    const int guard = int(layout.arcs.size()) + 1;
    for (int steps = 0; steps <= guard; ++steps) {
      const int node = topo.half_node[h_in];
      nodes.push_back(node);
      const int valence = topo.valence[node];
      if (on_boundary(node)) {
        if (valence != 3)
          throw InvalidInputError("the edge loop through " + start_name + " ends at " +
                                  node_name(layout, node) + " on the mesh boundary, of valence " +
                                  std::to_string(valence) +
                                  ": only a loop ending at boundary nodes of valence 3 can be "
                                  "removed");
        return false;
      }
      if (valence != 4)
        throw InvalidInputError("the edge loop through " + start_name + " reaches " +
                                node_name(layout, node) + " of valence " + std::to_string(valence) +
                                ": only a loop through nodes of valence 4 can be removed");
      const auto& around = topo.node_half_arcs[node];
      const auto it = std::find(around.begin(), around.end(), h_in);
      const int h_out = around[(it - around.begin() + 2) % 4];
      const int a = LayoutTopology::arc_of(h_out);
      if (a == arc_index) return true;
      if (layout.arcs[a].dangling()) throw dangling(a);
      arcs.push_back(a);
      h_in = sigma(h_out);
    }
    throw InvalidInputError("the edge loop through " + start_name + " does not close");
  };
  EdgeLoop loop;
  std::vector<int> fwd_nodes, fwd_arcs;
  loop.closed = walk(2 * arc_index + 1, fwd_nodes, fwd_arcs);
  if (loop.closed) {
    loop.arcs = {arc_index};
    loop.arcs.insert(loop.arcs.end(), fwd_arcs.begin(), fwd_arcs.end());
    loop.nodes = fwd_nodes;
  } else {
    std::vector<int> back_nodes, back_arcs;
    walk(2 * arc_index, back_nodes, back_arcs);
    loop.arcs.assign(back_arcs.rbegin(), back_arcs.rend());
    loop.arcs.push_back(arc_index);
    loop.arcs.insert(loop.arcs.end(), fwd_arcs.begin(), fwd_arcs.end());
    loop.nodes.assign(back_nodes.rbegin(), back_nodes.rend());
    loop.nodes.insert(loop.nodes.end(), fwd_nodes.begin(), fwd_nodes.end());
  }
  std::vector<int> sorted = loop.nodes;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 0; k + 1 < sorted.size(); ++k)
    if (sorted[k] == sorted[k + 1])
      throw InvalidInputError("the edge loop through " + start_name + " passes " +
                              node_name(layout, sorted[k]) +
                              " twice: a loop that crosses itself cannot be removed");
  return loop;
}

Layout remove_edge_loop(const TriMesh& mesh, const Layout& layout, int arc_id) {
  const int start = layout.arc_index(arc_id);
  if (start < 0) throw InvalidInputError("unknown arc " + std::to_string(arc_id));
  require_valid(mesh, layout, "removing an edge loop");
  const LayoutTopology topo = build_topology(mesh, layout);
  const EdgeLoop loop = find_edge_loop(mesh, layout, topo, start);
  Layout out = layout;
  clear_outputs(out);
  std::vector<int> loop_ids, node_ids;
  for (int a : loop.arcs) loop_ids.push_back(layout.arcs[a].id);
  for (int n : loop.nodes) node_ids.push_back(layout.nodes[n].id);
  std::erase_if(out.arcs, [&](const LayoutArc& a) {
    return std::find(loop_ids.begin(), loop_ids.end(), a.id) != loop_ids.end();
  });
  for (int id : node_ids) {
    std::vector<int> at;  // arcs (indices into out) ending at the node
    for (int a = 0; a < int(out.arcs.size()); ++a)
      if (out.arcs[a].from == id || out.arcs[a].to == id) at.push_back(a);
    if (at.size() != 2 || out.arcs[at[0]].from == out.arcs[at[0]].to)
      throw InvalidInputError("node " + std::to_string(id) + " of the edge loop through arc " +
                              std::to_string(arc_id) + " does not join exactly two other arcs");
    const int keep = out.arcs[at[0]].id < out.arcs[at[1]].id ? at[0] : at[1];
    const int other = keep == at[0] ? at[1] : at[0];
    Piece a = piece_of(out.arcs[keep]);
    Piece b = piece_of(out.arcs[other]);
    // a's direction is kept: join b before it (a starts at the node) or after it.
    const bool after = a.end == id;
    if (after ? b.start != id : b.end != id) b.reverse();
    Piece joined;
    Piece& first = after ? a : b;
    Piece& second = after ? b : a;
    joined.start = first.start;
    joined.end = second.end;
    joined.path = first.path;
    if (!second.path.empty())
      joined.path.insert(joined.path.end(), second.path.begin() + (first.path.empty() ? 0 : 1),
                         second.path.end());
    joined.points = first.points;
    const int ni = out.node_index(id);
    if (first.path.empty() && out.nodes[ni].point) joined.points.push_back(*out.nodes[ni].point);
    joined.points.insert(joined.points.end(), second.points.begin(), second.points.end());
    if (!joined.path.empty()) joined.points.clear();
    if (joined.start < 0) {  // a dangling end first: dangling arcs start at their node
      if (joined.end < 0)
        throw InvalidInputError("removing the edge loop through arc " + std::to_string(arc_id) +
                                " would join two dangling arcs at node " + std::to_string(id));
      joined.reverse();
    }
    LayoutArc& kept = out.arcs[keep];
    kept.from = joined.start;
    kept.to = joined.end;
    kept.path = std::move(joined.path);
    kept.points = std::move(joined.points);
    kept.pinned = kept.pinned || out.arcs[other].pinned;
    out.arcs.erase(out.arcs.begin() + other);
    out.nodes.erase(out.nodes.begin() + ni);
  }
  return out;
}

}  // namespace qs
