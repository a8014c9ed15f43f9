#include "app/gui/sketch_edits.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/layout/edge_loops.h"
#include "core/layout/routing.h"
#include "core/layout/validate.h"

namespace qs::app {

namespace {

Vec3 vertex_position(const TriMesh& mesh, int v) {
  return mesh.point(OpenMesh::VertexHandle(v));
}

Vec3 node_position(const TriMesh& mesh, const Layout& layout, int id) {
  return vertex_position(mesh, layout.nodes[layout.node_index(id)].vertex);
}

int node_vertex(const Layout& layout, int id) {
  const int k = layout.node_index(id);
  return k < 0 ? -1 : layout.nodes[k].vertex;
}

// Largest distance from the reflection of a vertex of \p a to the nearest vertex of \p b.
double path_deviation(const TriMesh& mesh, const Mirror& m, const std::vector<int>& a,
                      const std::vector<int>& b) {
  double worst = 0.0;
  for (int v : a) {
    const Vec3 r = m.plane.reflect(vertex_position(mesh, v));
    double best = std::numeric_limits<double>::infinity();
    for (int w : b) best = std::min(best, (vertex_position(mesh, w) - r).norm());
    worst = std::max(worst, best);
  }
  return worst;
}

bool distinct_vertices(std::vector<int> path) {
  std::sort(path.begin(), path.end());
  return std::adjacent_find(path.begin(), path.end()) == path.end();
}

// The mirror node of node \p id, created on the mirror vertex when there is none; -1 with
// \p error when its place is taken.
int ensure_mirror_node(const TriMesh& mesh, const Mirror& m, Layout& layout, int id,
                       std::string* error) {
  if (const int existing = mirror_node_id(mesh, layout, m, id); existing >= 0) return existing;
  const int v = mirror_vertex(mesh, *m.tree, m.plane, node_vertex(layout, id));
  if (const int other = node_at_vertex(layout, v); other >= 0) return other;
  if (const int arc = arc_through_vertex(layout, v); arc >= 0) {
    *error =
        "the mirror image of node " + std::to_string(id) + " falls on arc " + std::to_string(arc);
    return -1;
  }
  LayoutNode node;
  node.id = next_node_id(layout);
  node.vertex = v;
  layout.nodes.push_back(node);
  return node.id;
}

// An arc between a node and its mirror made symmetric: its half up to the vertex nearest to
// the plane, then that half's mirror image. False (path unchanged) when no vertex of it lies on
// the plane or the mirror half cannot be routed.
bool symmetrize_crossing_arc(const TriMesh& mesh, const Mirror& m, Layout& layout, int index) {
  LayoutArc& arc = layout.arcs[index];
  const std::vector<int> s = arc.path;
  if (s.size() < 3) return false;
  std::size_t c = 1;
  for (std::size_t k = 1; k + 1 < s.size(); ++k)
    if (std::abs(m.plane.signed_distance(vertex_position(mesh, s[k]))) <
        std::abs(m.plane.signed_distance(vertex_position(mesh, s[c]))))
      c = k;
  if (std::abs(m.plane.signed_distance(vertex_position(mesh, s[c]))) > m.on_plane) return false;
  Layout others = layout;
  others.arcs.erase(others.arcs.begin() + index);
  RoutingObstacles obstacles = obstacles_of_layout(mesh, others);
  for (std::size_t k = 0; k < c; ++k) obstacles.vertex_blocked[s[k]] = 1;
  std::vector<int> half(s.begin(), s.begin() + static_cast<long>(c) + 1);
  std::vector<int> reversed(half.rbegin(), half.rend());
  const std::vector<int> second =
      mirror_path(mesh, *m.tree, m.plane, reversed, obstacles, s[c], s.back());
  if (second.size() < 2) return false;
  half.insert(half.end(), second.begin() + 1, second.end());
  if (!distinct_vertices(half)) return false;
  arc.path = std::move(half);
  return true;
}

// Adds the mirror image of arc \p id (and the mirror nodes of its ends when missing); nothing
// when the arc is its own mirror image. "" or why it cannot.
std::string add_mirror_arc(const TriMesh& mesh, const Mirror& m, Layout& layout, int id) {
  const int index = layout.arc_index(id);
  if (index < 0) return "unknown arc " + std::to_string(id);
  const LayoutArc arc = layout.arcs[index];
  std::string error;
  const int mf = ensure_mirror_node(mesh, m, layout, arc.from, &error);
  if (mf < 0) return error;
  const int mt = arc.dangling() ? -1 : ensure_mirror_node(mesh, m, layout, arc.to, &error);
  if (!arc.dangling() && mt < 0) return error;
  if (!arc.dangling() && mf == arc.to && mt == arc.from) {
    symmetrize_crossing_arc(mesh, m, layout, layout.arc_index(id));  // its own mirror image
    return {};
  }
  if (mf == arc.from && mt == arc.to &&
      path_deviation(mesh, m, arc.path, arc.path) <= m.pair_distance)
    return {};  // along the plane
  const RoutingObstacles obstacles = obstacles_of_layout(mesh, layout);
  std::vector<int> path =
      mirror_path(mesh, *m.tree, m.plane, arc.path, obstacles, node_vertex(layout, mf),
                  mt >= 0 ? node_vertex(layout, mt) : -1);
  if (path.size() < 2)
    return "the mirror image of arc " + std::to_string(id) +
           " cannot be routed (other arcs are in the way)";
  if (arc.dangling() && (!mesh.is_boundary(OpenMesh::VertexHandle(path.back())) ||
                         obstacles.vertex_blocked[path.back()]))
    return "the mirror image of dangling arc " + std::to_string(id) +
           " does not end on a free boundary vertex";
  LayoutArc mirrored;
  mirrored.id = next_arc_id(layout);
  mirrored.from = mf;
  mirrored.to = mt;
  mirrored.path = std::move(path);
  mirrored.pinned = arc.pinned;
  layout.arcs.push_back(std::move(mirrored));
  return {};
}

// The arcs of node \p id (ids).
std::vector<int> arcs_of(const Layout& layout, int id) {
  std::vector<int> out;
  for (const auto& a : layout.arcs)
    if (a.from == id || a.to == id) out.push_back(a.id);
  return out;
}

// Re-routes arc \p id in \p layout: the mirror image of arc \p partner (oriented to match), or
// the shortest free path when partner is -1. "" or why it cannot.
std::string reroute(const TriMesh& mesh, const Mirror& m, Layout& layout, int id, int partner,
                    const Layout& before) {
  const int index = layout.arc_index(id);
  LayoutArc arc = layout.arcs[index];
  layout.arcs.erase(layout.arcs.begin() + index);
  const RoutingObstacles obstacles = obstacles_of_layout(mesh, layout);
  const int from = node_vertex(layout, arc.from);
  const int to = arc.dangling() ? -1 : node_vertex(layout, arc.to);
  std::vector<int> path;
  const int pi = partner >= 0 ? layout.arc_index(partner) : -1;
  if (pi >= 0) {
    std::vector<int> source = layout.arcs[pi].path;
    // Orientation: the partner's start mirrors this arc's start (in the layout before).
    if (mirror_node_id(mesh, before, m, layout.arcs[pi].from) != arc.from)
      std::reverse(source.begin(), source.end());
    path = mirror_path(mesh, *m.tree, m.plane, source, obstacles, from, to);
  } else if (arc.dangling()) {
    path = shortest_path_to_boundary(mesh, from, obstacles);
  } else {
    path = shortest_path(mesh, from, to, obstacles);
  }
  if (path.size() < 2)
    return "arc " + std::to_string(id) + " cannot follow its mirror image (no free route)";
  arc.path = std::move(path);
  clear_arc_outputs(arc);
  layout.arcs.push_back(std::move(arc));
  return {};
}

void sort_arcs(Layout& layout) {
  std::sort(layout.arcs.begin(), layout.arcs.end(),
            [](const LayoutArc& a, const LayoutArc& b) { return a.id < b.id; });
}

}  // namespace

Mirror make_mirror(const TriMesh& mesh, const MirrorPlane& plane,
                   std::shared_ptr<const ClosestPointTree> tree) {
  double sum = 0.0;
  for (const auto eh : mesh.edges()) sum += mesh.calc_edge_length(eh);
  const double h = mesh.n_edges() > 0 ? sum / double(mesh.n_edges()) : 0.0;
  Mirror m;
  m.plane = plane;
  m.tree = std::move(tree);
  m.on_plane = 0.5 * h;
  m.snap = h;
  m.pair_distance = 1.5 * h;
  return m;
}

int mirror_node_id(const TriMesh& mesh, const Layout& layout, const Mirror& m, int id) {
  if (layout.node_index(id) < 0) return -1;
  const Vec3 x = node_position(mesh, layout, id);
  if (std::abs(m.plane.signed_distance(x)) <= m.on_plane) return id;
  auto nearest = [&](const Vec3& p) {
    int best = -1;
    double best_d = m.pair_distance;
    for (const auto& n : layout.nodes) {
      const double d = (vertex_position(mesh, n.vertex) - p).norm();
      if (d <= best_d) {
        best_d = d;
        best = n.id;
      }
    }
    return best;
  };
  const int j = nearest(m.plane.reflect(x));
  if (j < 0 || j == id) return -1;
  return nearest(m.plane.reflect(node_position(mesh, layout, j))) == id ? j : -1;
}

int mirror_arc_id(const TriMesh& mesh, const Layout& layout, const Mirror& m, int id) {
  const int index = layout.arc_index(id);
  if (index < 0) return -1;
  const LayoutArc& arc = layout.arcs[index];
  const int mf = mirror_node_id(mesh, layout, m, arc.from);
  const int mt = arc.dangling() ? -1 : mirror_node_id(mesh, layout, m, arc.to);
  if (mf < 0 || (!arc.dangling() && mt < 0)) return -1;
  int best = -1;
  double best_d = 2.0 * m.pair_distance;
  for (const auto& b : layout.arcs) {
    const bool ends = arc.dangling() ? b.dangling() && b.from == mf
                                     : !b.dangling() && ((b.from == mf && b.to == mt) ||
                                                         (b.from == mt && b.to == mf));
    if (!ends) continue;
    const double d = path_deviation(mesh, m, arc.path, b.path);
    if (d <= best_d) {
      best_d = d;
      best = b.id;
    }
  }
  return best;
}

std::string follow_mirror(const TriMesh& mesh, const Mirror& m, const Layout& before, Layout& moved,
                          int node_id) {
  const int mid = mirror_node_id(mesh, before, m, node_id);
  if (mid < 0 || moved.node_index(node_id) < 0 || moved.node_index(mid) < 0) return {};
  // The arcs to re-route, each with its partner (the arc it mirrors), from the layout before.
  std::vector<std::pair<int, int>> follow;  // (arc, partner or -1)
  if (mid == node_id) {
    // On the plane: of each pair of mirror arcs at the node, the second follows the first.
    for (int a : arcs_of(before, node_id)) {
      const int b = mirror_arc_id(mesh, before, m, a);
      if (b > a && before.arc_index(b) >= 0) follow.emplace_back(b, a);
    }
  } else {
    const int v = node_vertex(moved, node_id);
    const int mv = mirror_vertex(mesh, *m.tree, m.plane, v);
    LayoutNode& mirror_node = moved.nodes[moved.node_index(mid)];
    if (mirror_node.vertex != mv) {
      if (const int other = node_at_vertex(moved, mv); other >= 0 && other != mid)
        return "the mirror node " + std::to_string(mid) + " cannot go to vertex " +
               std::to_string(mv) + ": node " + std::to_string(other) + " is there";
      Layout without = moved;
      std::erase_if(without.arcs, [&](const LayoutArc& a) { return a.from == mid || a.to == mid; });
      if (const int arc = arc_through_vertex(without, mv); arc >= 0)
        return "the mirror node " + std::to_string(mid) + " cannot go to vertex " +
               std::to_string(mv) + ": it lies on arc " + std::to_string(arc);
      mirror_node.vertex = mv;
      clear_node_outputs(mirror_node);
    }
    for (int b : arcs_of(moved, mid)) {
      const LayoutArc& arc = moved.arcs[moved.arc_index(b)];
      const bool crossing = (arc.from == node_id || arc.to == node_id);
      const int partner = crossing ? -1 : mirror_arc_id(mesh, before, m, b);
      follow.emplace_back(b, partner);
    }
  }
  // Every follower leaves the obstacles first, then each is routed back.
  Layout routed = moved;
  std::vector<LayoutArc> followers;
  for (const auto& [b, partner] : follow) {
    const int k = routed.arc_index(b);
    followers.push_back(routed.arcs[k]);
    routed.arcs.erase(routed.arcs.begin() + k);
  }
  for (std::size_t i = 0; i < follow.size(); ++i) {
    LayoutArc arc = followers[i];
    arc.path.clear();
    routed.arcs.push_back(arc);
    const auto [b, partner] = follow[i];
    if (std::string error = reroute(mesh, m, routed, b, partner, before); !error.empty())
      return error;
    const LayoutArc& done = routed.arcs.back();
    if (!done.dangling() && mirror_node_id(mesh, before, m, done.from) == done.to)
      symmetrize_crossing_arc(mesh, m, routed, int(routed.arcs.size()) - 1);
  }
  sort_arcs(routed);
  moved = std::move(routed);
  return {};
}

EditResult sketch_add_node(LayoutEditor& editor, const Mirror* m, int vertex) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh || vertex < 0 || vertex >= int(mesh->n_vertices()))
    return editor.add_node(vertex);
  const Vec3 x = vertex_position(*mesh, vertex);
  if (std::abs(m->plane.signed_distance(x)) <= m->snap)
    return editor.add_node(plane_vertex(*mesh, *m->tree, m->plane, x));  // onto the plane
  return editor.group(
      "add node " + std::to_string(next_node_id(editor.layout())) + " and its mirror", [&] {
        const EditResult r = editor.add_node(vertex);
        if (!r) return r;
        const EditResult mirrored = editor.edit("mirror", [&](Layout& layout) {
          std::string error;
          ensure_mirror_node(*mesh, *m, layout, r.id, &error);
          return error;
        });
        return mirrored ? r : mirrored;
      });
}

namespace {

// A new arc by \p add, then its mirror image, as one step.
EditResult with_mirror_arc(LayoutEditor& editor, const Mirror* m, const std::string& label,
                           const std::function<EditResult()>& add) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh) return add();
  return editor.group(label, [&] {
    const EditResult r = add();
    if (!r) return r;
    const EditResult mirrored = editor.edit(
        "mirror", [&](Layout& layout) { return add_mirror_arc(*mesh, *m, layout, r.id); });
    return mirrored ? r : mirrored;
  });
}

}  // namespace

EditResult sketch_add_arc(LayoutEditor& editor, const Mirror* m, int from_id, int to_id) {
  return with_mirror_arc(editor, m, "add arc and its mirror",
                         [&] { return editor.add_arc(from_id, to_id); });
}

EditResult sketch_add_stroke_arc(LayoutEditor& editor, const Mirror* m, int from_id, int to_id,
                                 const std::vector<SurfacePoint>& stroke) {
  return with_mirror_arc(editor, m, "stroke arc and its mirror",
                         [&] { return editor.add_stroke_arc(from_id, to_id, stroke); });
}

EditResult sketch_add_dangling_arc(LayoutEditor& editor, const Mirror* m, int from_id,
                                   int boundary_vertex) {
  return with_mirror_arc(editor, m, "dangling arc and its mirror",
                         [&] { return editor.add_dangling_arc(from_id, boundary_vertex); });
}

EditResult sketch_delete_node(LayoutEditor& editor, const Mirror* m, int id) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh) return editor.delete_node(id);
  const int mid = mirror_node_id(*mesh, editor.layout(), *m, id);
  return editor.group("delete node " + std::to_string(id) + " and its mirror", [&] {
    const EditResult r = editor.delete_node(id);
    if (!r || mid < 0 || mid == id) return r;
    return editor.delete_node(mid);
  });
}

EditResult sketch_delete_arc(LayoutEditor& editor, const Mirror* m, int id) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh) return editor.delete_arc(id);
  const int mid = mirror_arc_id(*mesh, editor.layout(), *m, id);
  return editor.group("delete arc " + std::to_string(id) + " and its mirror", [&] {
    const EditResult r = editor.delete_arc(id);
    if (!r || mid < 0 || mid == id) return r;
    return editor.delete_arc(mid);
  });
}

EditResult sketch_move_node(LayoutEditor& editor, const Mirror* m, int id, int vertex) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh || editor.layout().node_index(id) < 0 || vertex < 0 ||
      vertex >= int(mesh->n_vertices()))
    return editor.move_node(id, vertex);
  const Layout before = editor.layout();
  if (mirror_node_id(*mesh, before, *m, id) == id)  // on the plane: stays on it
    vertex = plane_vertex(*mesh, *m->tree, m->plane, vertex_position(*mesh, vertex));
  return editor.group("move node " + std::to_string(id) + " and its mirror", [&] {
    const EditResult r = editor.move_node(id, vertex);
    if (!r) return r;
    const EditResult mirrored = editor.edit(
        "mirror", [&](Layout& layout) { return follow_mirror(*mesh, *m, before, layout, id); });
    return mirrored ? r : mirrored;
  });
}

EditResult sketch_split_arc(LayoutEditor& editor, const Mirror* m, int arc_id, int vertex) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh) return editor.split_arc(arc_id, vertex);
  const int mid = mirror_arc_id(*mesh, editor.layout(), *m, arc_id);
  return editor.group("split arc " + std::to_string(arc_id) + " and its mirror", [&] {
    const EditResult r = editor.split_arc(arc_id, vertex);
    if (!r || mid < 0) return r;
    const Vec3 x = vertex_position(*mesh, vertex);
    if (mid == arc_id && std::abs(m->plane.signed_distance(x)) <= m->on_plane) return r;
    // The interior vertex nearest to the reflection, on the mirror arc (or, for an arc that is
    // its own mirror, on either of its parts).
    const Vec3 target = m->plane.reflect(x);
    const Layout& layout = editor.layout();
    int best_arc = -1, best_vertex = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (const auto& a : layout.arcs) {
      const bool candidate = mid != arc_id ? a.id == mid : a.from == r.id || a.to == r.id;
      if (!candidate) continue;
      for (std::size_t k = 1; k + 1 < a.path.size(); ++k) {
        const double d = (vertex_position(*mesh, a.path[k]) - target).norm();
        if (d < best_d) {
          best_d = d;
          best_arc = a.id;
          best_vertex = a.path[k];
        }
      }
    }
    if (best_arc < 0 || best_d > m->pair_distance)
      return EditResult::fail("the mirror arc has no vertex at the mirror image of vertex " +
                              std::to_string(vertex));
    const EditResult second = editor.split_arc(best_arc, best_vertex);
    return second ? r : second;
  });
}

EditResult sketch_toggle_node_pin(LayoutEditor& editor, const Mirror* m, int id) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh) return editor.toggle_node_pin(id);
  const int mid = mirror_node_id(*mesh, editor.layout(), *m, id);
  return editor.group("pin node " + std::to_string(id) + " and its mirror", [&] {
    const EditResult r = editor.toggle_node_pin(id);
    if (!r || mid < 0 || mid == id) return r;
    return editor.toggle_node_pin(mid);
  });
}

EditResult sketch_toggle_arc_pin(LayoutEditor& editor, const Mirror* m, int id) {
  const TriMesh* mesh = editor.mesh();
  if (!m || !mesh) return editor.toggle_arc_pin(id);
  const int mid = mirror_arc_id(*mesh, editor.layout(), *m, id);
  return editor.group("pin arc " + std::to_string(id) + " and its mirror", [&] {
    const EditResult r = editor.toggle_arc_pin(id);
    if (!r || mid < 0 || mid == id) return r;
    return editor.toggle_arc_pin(mid);
  });
}

namespace {

// One edge-loop insertion as an edit; \p chord_ids receives the ids of the crossed arcs.
EditResult insert_loop(LayoutEditor& editor, int arc_id, std::vector<int>* chord_ids) {
  const TriMesh& mesh = *editor.mesh();
  int first_node = -1;
  EditResult r =
      editor.edit("insert edge loop at arc " + std::to_string(arc_id), [&](Layout& layout) {
        const EdgeLoopInsertion ins = insert_edge_loop(mesh, layout, arc_id);
        Layout out = ins.layout;
        route_layout(mesh, out);
        for (auto& node : out.nodes) node.point.reset();  // the editor's nodes are on vertices
        const ValidationResult v = validate_layout(mesh, out);
        if (!v.valid())
          for (const auto& issue : v.issues)
            if (issue.severity == IssueSeverity::Error)
              return "the layout with the loop is not valid: " + issue.message;
        if (chord_ids)
          for (int a : ins.chord.arcs) chord_ids->push_back(layout.arcs[a].id);
        first_node = ins.new_nodes.front();
        layout = std::move(out);
        return std::string();
      });
  if (r) r.id = first_node;
  return r;
}

}  // namespace

EditResult sketch_insert_edge_loop(LayoutEditor& editor, const Mirror* m, int arc_id,
                                   bool* mirror_loop) {
  if (mirror_loop) *mirror_loop = false;
  const TriMesh* mesh = editor.mesh();
  if (!mesh) return EditResult::fail("no mesh loaded");
  if (!m) return insert_loop(editor, arc_id, nullptr);
  const int mid = mirror_arc_id(*mesh, editor.layout(), *m, arc_id);
  return editor.group("insert edge loop at arc " + std::to_string(arc_id) + " and its mirror", [&] {
    std::vector<int> chord;
    const EditResult r = insert_loop(editor, arc_id, &chord);
    if (!r || mid < 0 || std::find(chord.begin(), chord.end(), mid) != chord.end()) return r;
    const EditResult second = insert_loop(editor, mid, nullptr);
    if (mirror_loop) *mirror_loop = second.ok;
    return second ? r : second;
  });
}

EditResult sketch_remove_edge_loop(LayoutEditor& editor, const Mirror* m, int arc_id,
                                   bool* mirror_loop) {
  if (mirror_loop) *mirror_loop = false;
  const TriMesh* mesh = editor.mesh();
  if (!mesh) return EditResult::fail("no mesh loaded");
  auto remove = [&](int id) {
    return editor.edit("remove edge loop at arc " + std::to_string(id), [&](Layout& layout) {
      Layout out = remove_edge_loop(*mesh, layout, id);
      const ValidationResult v = validate_layout(*mesh, out);
      if (!v.valid())
        for (const auto& issue : v.issues)
          if (issue.severity == IssueSeverity::Error)
            return "the layout without the loop is not valid: " + issue.message;
      layout = std::move(out);
      return std::string();
    });
  };
  if (!m) return remove(arc_id);
  const Layout& before = editor.layout();
  const int mid = mirror_arc_id(*mesh, before, *m, arc_id);
  std::vector<int> loop_ids;
  if (before.arc_index(arc_id) >= 0 && validate_layout(*mesh, before).valid()) {
    try {
      const EdgeLoop loop =
          find_edge_loop(*mesh, before, build_topology(*mesh, before), before.arc_index(arc_id));
      for (int a : loop.arcs) loop_ids.push_back(before.arcs[a].id);
    } catch (const std::exception&) {
      // remove() reports why
    }
  }
  return editor.group("remove edge loop at arc " + std::to_string(arc_id) + " and its mirror", [&] {
    const EditResult r = remove(arc_id);
    if (!r || mid < 0 || std::find(loop_ids.begin(), loop_ids.end(), mid) != loop_ids.end())
      return r;
    const EditResult second = remove(mid);
    if (mirror_loop) *mirror_loop = second.ok;
    return second ? r : second;
  });
}

}  // namespace qs::app
