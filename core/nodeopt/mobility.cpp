// Which nodes move and how (docs/design.md, "Node optimization", "Node relocation"): the movable
// nodes (pins, pinned arcs, features and the boundary), changing pins between steps, the
// separation of crowded nodes before the start, the curves nodes slide on (slide_on_curves)
// and the slide of a node along its curve in a descent trial, and the counts that keep nodes
// apart (keep_nodes_apart). Part of NodeOptimizer::Impl (optimizer_impl.h).
#include <algorithm>
#include <memory>
#include <optional>
#include <vector>

#include "core/field/curvature.h"
#include "core/layout/node_shift.h"
#include "core/layout/validate.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/optimizer_impl.h"
#include "core/nodeopt/relocation.h"

namespace qs {

namespace nodeopt_detail {

CurveNetwork curve_network(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                           const PipelineOptions& options, const NodeOptOptions& no) {
  if (!no.moves.slide_on_curves) return {};
  if (!no.moves.sharp_edges_as_curves) return make_curve_network(mesh, layout, kCurveCornerDeg);
  const std::vector<char> sharp =
      sharp_edges(mesh, g, options.field.constraints.sharp_angle_deg, nullptr);
  return make_curve_network(mesh, layout, kCurveCornerDeg, &sharp);
}

}  // namespace nodeopt_detail

namespace {

// The node is pinned or an end of a pinned arc: it never moves.
bool held(const Layout& layout, const LayoutNode& node) {
  if (node.pinned) return true;
  for (const auto& arc : layout.arcs)
    if (arc.pinned && (arc.from == node.id || arc.to == node.id)) return true;
  return false;
}

}  // namespace

std::vector<int> movable_nodes(const TriMesh& mesh, const Layout& layout) {
  std::vector<char> feature(mesh.n_vertices(), 0);
  for (const auto& [a, b] : layout.feature_edges) feature[a] = feature[b] = 1;
  std::vector<int> out;
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n) {
    const LayoutNode& node = layout.nodes[n];
    if (!feature[node.vertex] && !mesh.is_boundary(mesh.vertex_handle(node.vertex)) &&
        !held(layout, node))
      out.push_back(n);
  }
  return out;
}

std::optional<SeparateNodesResult> separate_movable_nodes(const TriMesh& mesh,
                                                          const Layout& layout) {
  // An invalid layout is left to the initial solve, which names its errors.
  if (!validate_layout(mesh, layout).valid()) return std::nullopt;
  std::vector<char> flags(layout.nodes.size(), 0);
  for (int n : movable_nodes(mesh, layout)) flags[n] = 1;
  return separate_nodes(mesh, layout, flags);
}

void NodeOptimizer::Impl::compute_movable() {
  if (curves.empty()) {
    movable = movable_nodes(original, state.layout);
  } else {  // every vertex movable_nodes leaves out (boundary, feature) is on a curve
    movable.clear();
    for (int n = 0; n < static_cast<int>(state.layout.nodes.size()); ++n)
      if (!held(state.layout, state.layout.nodes[n])) movable.push_back(n);
  }
  rejected_target.assign(movable.size(), -1);
  damping.assign(movable.size(), 1.0);
}

bool NodeOptimizer::Impl::slide_on_curve(State& trial, size_t i, int n, bool no_switch,
                                         LayoutObstacles& obstacles, std::vector<char>& switched) {
  const int v = trial.layout.nodes[n].vertex;
  if (!curves.slides[v]) return false;  // it reached a curve end, junction or corner: it stays
  auto point = [&](int x) { return original.point(original.vertex_handle(x)); };
  const CurvePoint cp = trial.curve[n];
  const Vec3 start = cp.toward < 0 ? point(v) : point(v) + cp.t * (point(cp.toward) - point(v));
  // Travel order: seq[0] behind the start, seq[1] ahead.
  const Vec3 d = -grad[i];
  std::vector<int> seq;
  double best = 0;
  auto consider = [&](int behind, int ahead) {
    const Vec3 tangent = point(ahead) - start;
    const double l = tangent.norm();
    if (l <= 0) return;
    const double along = (d | tangent) / l;
    if (along > best) best = along, seq = {behind, ahead};
  };
  if (cp.toward >= 0) {
    consider(v, cp.toward);
    consider(cp.toward, v);
  } else {
    for (int x : curves.neighbours[v]) consider(v, x);
  }
  if (seq.empty()) return false;
  double remaining = alpha * damping[i] * scale * best;
  if (remaining < nodeopt_detail::kMinStepRelative * mean_edge) return false;
  // Vertices the walk may not pass or take: other nodes and other arcs; it stops on a free
  // curve end, junction or corner (the node then sits on that vertex, which keeps its place).
  auto occupied = [&](int c) {
    return c != v &&
           (occupied_by_layout(trial.layout, n, obstacles, c) || next_to_other_node(v, c));
  };
  // Walk: the point ends on segment (seq[k], seq[k+1]) at fraction s from seq[k].
  size_t k = 0;
  Vec3 from = start;
  double s = 0;
  bool stopped = false;
  for (size_t guard = 0; guard < curves.neighbours.size(); ++guard) {
    const Vec3 a = point(seq[k]), b = point(seq[k + 1]);
    const double seg = (b - a).norm();
    const double left = (b - from).norm();
    if (remaining < left || seg <= 0) {
      s = seg > 0 ? 1 - (left - remaining) / seg : 0;
      break;
    }
    remaining -= left;
    const int c = seq[k + 1];
    if (occupied(c)) {  // stop on the segment, halfway to c
      s = 0.5;
      stopped = true;
      break;
    }
    if (!curves.slides[c]) {  // on the curve's end, junction or corner
      s = 1;
      break;
    }
    const auto& nb = curves.neighbours[c];
    const int next = nb[0] == seq[k] ? nb[1] : nb[0];
    if (next == v || std::find(seq.begin(), seq.end(), next) != seq.end()) {  // a closed loop
      s = 0.5;
      stopped = true;
      break;
    }
    seq.push_back(next);
    ++k;
    from = point(c);
  }
  if (stopped && k == 0) {  // not past the start
    const double seg = (point(seq[1]) - point(seq[0])).norm();
    if (seg <= 0 || (start - point(seq[0])).norm() >= 0.5 * seg) return false;
  }
  const size_t iv = std::find(seq.begin(), seq.end(), v) - seq.begin();
  const std::vector<CurveCarrier> carriers = curve_carriers(
      seq[k], seq[k + 1], s, v, curves.slides, [&](int w) { return !no_switch && !occupied(w); });
  for (const CurveCarrier& carrier : carriers) {
    const int w = carrier.vertex;
    const double f = carrier.fraction;
    const Vec3 at = f <= 0   ? point(seq[k])
                    : f >= 1 ? point(seq[k + 1])
                             : point(seq[k]) + f * (point(seq[k + 1]) - point(seq[k]));
    if (!relocation_keeps_orientation(trial.mesh, original, w == v ? -1 : v, w, at, relocation))
      continue;
    if (w != v && next_to_other_node(v, w)) continue;
    if (w != v) {
      const size_t iw = std::find(seq.begin(), seq.end(), w) - seq.begin();
      std::vector<int> path;  // the curve vertices from v to w
      if (iw >= iv)
        path.assign(seq.begin() + iv, seq.begin() + iw + 1);
      else
        for (size_t j = iv + 1; j-- > iw;) path.push_back(seq[j]);
      const CurveWalk walk = make_curve_walk(curves, std::move(path));
      if (!move_node_and_reroute(trial.mesh, trial.layout, n, w, relocation, &reroute, &obstacles,
                                 &walk))
        continue;
      trial.mesh.set_point(trial.mesh.vertex_handle(v), point(v));
      switched[i] = 1;
      target[i] = w;
      move_near_count(v, w);
    }
    trial.mesh.set_point(trial.mesh.vertex_handle(w), at);
    const int other = w == seq[k] ? seq[k + 1] : seq[k];
    const double t = w == seq[k] ? carrier.fraction : 1 - carrier.fraction;
    trial.curve[n] = t > 0 ? CurvePoint{other, t} : CurvePoint{};
    return true;
  }
  return false;
}

void NodeOptimizer::Impl::count_nodes_near(const Layout& layout) {
  near_count.clear();
  if (!no.moves.keep_nodes_apart) return;
  near_count.assign(original.n_vertices(), 0);
  for (const auto& node : layout.nodes) add_near_count(node.vertex, 1);
}

void NodeOptimizer::Impl::add_near_count(int v, int d) {
  const auto vh = original.vertex_handle(v);
  near_count[v] += d;
  for (auto wh : original.vv_range(vh)) near_count[wh.idx()] += d;
}

void NodeOptimizer::Impl::move_near_count(int from, int to) {
  if (near_count.empty()) return;
  add_near_count(from, -1);
  add_near_count(to, 1);
}

bool NodeOptimizer::Impl::next_to_other_node(int own, int u) const {
  if (near_count.empty()) return false;
  bool mine = u == own;  // the own node's count covers u too
  for (auto wh : original.vv_range(original.vertex_handle(own))) mine |= wh.idx() == u;
  return near_count[u] - (mine ? 1 : 0) > 0;
}

void NodeOptimizer::Impl::set_pinned(const std::vector<char>& pinned,
                                     const std::vector<char>& arc_pinned) {
  bool changed = false;
  // An earlier state in which a newly pinned node or arc stands elsewhere is no fallback any
  // more: the node's vertex or its position, an arc's route or its end nodes' vertices.
  auto node_differs = [&](const State& st, size_t n) {
    const int v = state.layout.nodes[n].vertex;
    const auto vh = original.vertex_handle(v);
    return st.layout.nodes[n].vertex != v || st.mesh.point(vh) != state.mesh.point(vh);
  };
  auto arc_differs = [&](const State& st, size_t a) {
    const LayoutArc& arc = state.layout.arcs[a];
    if (st.layout.arcs[a].path != arc.path) return true;
    for (int id : {arc.from, arc.to}) {
      const int n = state.layout.node_index(id);
      if (n >= 0 && node_differs(st, size_t(n))) return true;
    }
    return false;
  };
  for (size_t n = 0; n < state.layout.nodes.size() && n < pinned.size(); ++n) {
    LayoutNode& node = state.layout.nodes[n];
    if (node.pinned == bool(pinned[n])) continue;
    changed = true;
    node.pinned = pinned[n];
    for (std::unique_ptr<State>* earlier : {&pre_polish, &fewest_folds, &initial_state}) {
      if (!*earlier) continue;
      (*earlier)->layout.nodes[n].pinned = node.pinned;
      if (node.pinned && node_differs(**earlier, n)) earlier->reset();
    }
  }
  for (size_t a = 0; a < state.layout.arcs.size() && a < arc_pinned.size(); ++a) {
    LayoutArc& arc = state.layout.arcs[a];
    if (arc.pinned == bool(arc_pinned[a])) continue;
    changed = true;
    arc.pinned = arc_pinned[a];
    for (std::unique_ptr<State>* earlier : {&pre_polish, &fewest_folds, &initial_state}) {
      if (!*earlier) continue;
      (*earlier)->layout.arcs[a].pinned = arc.pinned;
      if (arc.pinned && arc_differs(**earlier, a)) earlier->reset();
    }
  }
  if (!changed) return;
  compute_movable();
  state_changed = true;  // gradients of the new movable set
}

}  // namespace qs
