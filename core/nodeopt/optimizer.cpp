#include "core/nodeopt/optimizer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <future>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "core/base/timing.h"
#include "core/field/curvature.h"
#include "core/layout/validate.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/geodesic.h"
#include "core/nodeopt/symmetric_step.h"

namespace qs {

namespace {

// One solve of field + parameterization. The Pipeline is shared: a later trial without node
// switches re-solves it in place (then it no longer holds this evaluation's solution).
struct Evaluation {
  std::shared_ptr<Pipeline> pipeline;
  double E = 0;
  int foldovers = 0;
};

void solve_and_measure(Evaluation& ev, const PipelineOptions& options) {
  ev.pipeline->compute_field();
  const Parameterization& r = ev.pipeline->compute_parameterization();
  ev.E = unweighted_energy(ev.pipeline->mesh(), ev.pipeline->geometry(),
                           ev.pipeline->field()->theta, r, options.param);
  ev.foldovers = r.foldovers;
}

Evaluation evaluate_fresh(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options,
                          bool validate) {
  Evaluation ev;
  ev.pipeline = std::make_shared<Pipeline>(mesh, layout, options, validate);
  solve_and_measure(ev, options);
  return ev;
}

// Runs \p solve (which returns an Evaluation) and gives its E and fold-overs; false when it
// throws a QsError (a layout the field cannot realize, …). Cancelled passes through.
template <typename Solve>
bool measured(Solve&& solve, double& E, int& foldovers) {
  try {
    const Evaluation ev = solve();
    E = ev.E;
    foldovers = ev.foldovers;
    return true;
  } catch (const Cancelled&) {
    throw;
  } catch (const QsError&) {
    return false;
  }
}

// Same layout, moved vertices: update the geometry of \p pipeline and re-solve.
Evaluation evaluate_reused(std::shared_ptr<Pipeline> pipeline, const TriMesh& mesh,
                           const PipelineOptions& options) {
  Evaluation ev;
  ev.pipeline = std::move(pipeline);
  ev.pipeline->update_positions(mesh);
  solve_and_measure(ev, options);
  return ev;
}

// True when \p p was built for exactly this mesh (positions) and layout (what the solves use).
bool pipeline_matches(const Pipeline& p, const TriMesh& mesh, const Layout& layout) {
  if (!p.parameterization() || !p.field()) return false;
  const TriMesh& m = p.mesh();
  if (m.n_vertices() != mesh.n_vertices() || m.n_faces() != mesh.n_faces()) return false;
  for (auto v : mesh.vertices())
    if (m.point(v) != mesh.point(v)) return false;
  const Layout& l = p.layout();
  if (l.nodes.size() != layout.nodes.size() || l.arcs.size() != layout.arcs.size() ||
      l.feature_edges != layout.feature_edges)
    return false;
  for (size_t n = 0; n < l.nodes.size(); ++n)
    if (l.nodes[n].id != layout.nodes[n].id || l.nodes[n].vertex != layout.nodes[n].vertex ||
        l.nodes[n].pinned != layout.nodes[n].pinned)
      return false;
  for (size_t a = 0; a < l.arcs.size(); ++a)
    if (l.arcs[a].id != layout.arcs[a].id || l.arcs[a].from != layout.arcs[a].from ||
        l.arcs[a].to != layout.arcs[a].to || l.arcs[a].pinned != layout.arcs[a].pinned ||
        l.arcs[a].path != layout.arcs[a].path)
      return false;
  return true;
}

// A node's position on its curve (NodeOptOptions::slide_on_curves): on the segment from its
// vertex's original point towards curve neighbour `toward` at fraction t ∈ [0, 1) (toward −1:
// on the vertex).
struct CurvePoint {
  int toward = -1;
  double t = 0;
};

struct State {
  TriMesh mesh;
  Layout layout;
  std::vector<SurfacePoint> anchor;  // per node, on the original mesh
  std::vector<CurvePoint> curve;     // per node (sliding nodes only)
};

// The same node vertices, arc routes and vertex positions.
bool same_state(const State& a, const State& b) {
  if (a.layout.nodes.size() != b.layout.nodes.size() ||
      a.layout.arcs.size() != b.layout.arcs.size() || a.mesh.n_vertices() != b.mesh.n_vertices())
    return false;
  for (size_t n = 0; n < a.layout.nodes.size(); ++n)
    if (a.layout.nodes[n].vertex != b.layout.nodes[n].vertex) return false;
  for (size_t i = 0; i < a.layout.arcs.size(); ++i)
    if (a.layout.arcs[i].path != b.layout.arcs[i].path) return false;
  for (auto v : a.mesh.vertices())
    if (a.mesh.point(v) != b.mesh.point(v)) return false;
  return true;
}

std::vector<std::array<double, 3>> node_positions(const TriMesh& mesh, const Layout& layout) {
  std::vector<std::array<double, 3>> out;
  for (const auto& n : layout.nodes) {
    const Vec3 p = mesh.point(mesh.vertex_handle(n.vertex));
    out.push_back({p[0], p[1], p[2]});
  }
  return out;
}

// Completes \p r with the node positions of (mesh, layout), appends it to \p reports and
// streams it to the observer.
void emit_step(StepReport r, const TriMesh& mesh, const Layout& layout,
               std::vector<StepReport>& reports, Observer* observer) {
  r.node_positions = node_positions(mesh, layout);
  reports.push_back(std::move(r));
  if (observer) observer->on_step(reports.back());
}

// The curves nodes slide on (NodeOptOptions::slide_on_curves): the layout's feature edges, the
// boundary and, with sharp_edges_as_curves, the sharp edges of \p mesh at the field's sharp
// angle. Empty when off.
CurveNetwork curve_network(const TriMesh& mesh, const GeometryCache& g, const Layout& layout,
                           const PipelineOptions& options, const NodeOptOptions& no) {
  if (!no.slide_on_curves) return {};
  if (!no.sharp_edges_as_curves) return make_curve_network(mesh, layout, no.curve_corner_deg);
  const std::vector<char> sharp =
      sharp_edges(mesh, g, options.field.constraints.sharp_angle_deg, nullptr);
  return make_curve_network(mesh, layout, no.curve_corner_deg, &sharp);
}

}  // namespace

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

// The optimization's state between units (NodeOptimizer::step), and the units themselves.
struct NodeOptimizer::Impl {
  // The caller's; after the initial solve with NodeOptOptions::vertex_ordering, plus the vertex
  // order that every later Pipeline uses (the initial Pipeline's, or computed here).
  PipelineOptions options;
  const NodeOptOptions no;
  const std::chrono::steady_clock::time_point t_start = std::chrono::steady_clock::now();
  const TriMesh original;        // the input positions (each relocated vertex lies on this surface)
  Observer* observer = nullptr;  // the caller's, for the current step() or finish()
  NodeOptResult result;
  NodeOptStats counters;
  State state;
  std::vector<int> movable;
  const GeometryCache original_geometry;
  const double mean_edge;
  // Feature and boundary curves (slide_on_curves; empty when off).
  const CurveNetwork curves;
  Evaluation current;
  // False when current.pipeline was re-solved for a rejected trial (it then holds the trial's
  // positions, not state's).
  bool current_solved = true;
  // Re-routing keeps the patch count: computed once.
  const RerouteContext reroute;
  // Symmetric optimization (NodeOptOptions::symmetry; null when off).
  const std::unique_ptr<const SymmetricStepper> symmetric;
  double alpha;
  // Gradients and node-Voronoi cells depend on the state only: kept across rejected steps.
  std::vector<Vec3> grad;
  double scale = 1;
  std::vector<int> cell;
  bool state_changed = true;
  // Descent phases: the first has max_steps steps; a hop sweep that moves nodes starts a new
  // one (α reset) with at least hop_descent_steps more.
  int step_budget;
  std::unique_ptr<State> pre_polish;  // the state before the first kept hop
  // The accepted state with the fewest fold-overs (equal: the later, lower E), kept while the
  // current state has more: the second fallback of the fold-over removal.
  std::unique_ptr<State> fewest_folds;
  int fewest_folds_count = 0;
  // The start (NodeOptOptions::initial_fallback): the last fallback of the fold-over removal.
  std::unique_ptr<State> initial_state;
  // The candidates of the result rule in finish(), by E: the initial state when it is
  // fold-free (always kept), and the kFoldFreeKept fold-free accepted states with the lowest E.
  static constexpr size_t kFoldFreeKept = 4;
  std::vector<std::pair<double, std::shared_ptr<const State>>> fold_free;
  std::pair<double, std::shared_ptr<const State>> fold_free_initial;
  int phase_halvings = 0;
  int stalled_steps = 0;      // accepted steps in a row with a gain below stall_gain
  double accepted_alpha = 0;  // α of the phase's last accepted descent step (0: none yet)
  // Per movable node: the vertex it switched to in the last trial rejected at the current α, or
  // -1 (switch_tabu); and the targets of the trial being built.
  std::vector<int> rejected_target, target;
  // Per movable node: its step length factor (damp_rejected_slides).
  std::vector<double> damping;
  std::vector<double> deficits;  // angle deficits of the original mesh (hop_cones), on demand
  int polish_rounds = 0;         // sweeps after a descent phase (max_hop_rounds)
  bool started = false;          // the sweep before the descent (hop_cones_first) is done
  bool descent_over = false;     // no further unit: finish() remains
  bool finished = false;

  Impl(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options_in,
       const NodeOptOptions& no_in, Observer* obs, std::shared_ptr<Pipeline> start)
      : options(options_in),
        no(no_in),
        original(mesh),
        observer(obs),
        state{mesh, layout, {}, std::vector<CurvePoint>(layout.nodes.size())},
        original_geometry(build_geometry(mesh)),
        mean_edge(original_geometry.mean_edge_length),
        curves(curve_network(mesh, original_geometry, layout, options_in, no_in)),
        reroute(make_reroute_context(mesh, layout)),
        symmetric(no_in.symmetry
                      ? std::make_unique<const SymmetricStepper>(original, layout, no_in.symmetry)
                      : nullptr),
        alpha(no_in.alpha),
        step_budget(no_in.max_steps) {
    for (const auto& n : layout.nodes) state.anchor.push_back(vertex_surface_point(mesh, n.vertex));
    if (no.orientation_at_end && no.initial_fallback)
      initial_state = std::make_unique<State>(state);
    compute_movable();
    for (int n : movable) result.sliding_nodes += on_curve(state.layout.nodes[n].vertex);
    check_cancel(observer);
    // The vertex order depends on the connectivity only. On large meshes the initial Pipeline
    // computes it beside the field (PipelineOptions::order_vertices); otherwise it is computed
    // here beside the initial solve (the future waits in its destructor if that throws).
    std::future<std::vector<int>> vertex_order;
    if (!no.vertex_ordering)
      options.order_vertices = false;
    else if (!options.param.vertex_order &&
             !pipeline_orders_vertices(options, original_geometry.n_faces))
      vertex_order = std::async(std::launch::async,
                                [this] { return vertex_nested_dissection(original_geometry); });
    if (start && pipeline_matches(*start, mesh, layout)) {
      current.pipeline = std::move(start);
      current.E = unweighted_energy(current.pipeline->mesh(), current.pipeline->geometry(),
                                    current.pipeline->field()->theta,
                                    *current.pipeline->parameterization(), options.param);
      current.foldovers = current.pipeline->parameterization()->foldovers;
      counters.warm_start = true;
    } else {
      current = evaluate_fresh(state.mesh, state.layout, options, true);
      ++counters.fresh_pipelines;
    }
    if (vertex_order.valid()) {
      std::vector<int> order = vertex_order.get();
      if (!order.empty()) {
        options.param.vertex_order = std::make_shared<const std::vector<int>>(std::move(order));
        current.pipeline->set_param_vertex_order(options.param.vertex_order);
      }
    } else if (no.vertex_ordering && !options.param.vertex_order) {
      options.param.vertex_order = current.pipeline->options().param.vertex_order;
    }
    fewest_folds_count = current.foldovers;
    note_fold_free(/*initial=*/true);
    result.E_init = current.E;
    result.foldovers_init = current.foldovers;
    StepReport r;
    r.step = 0;
    r.E = current.E;
    r.accepted = true;
    r.step_size = 0;
    r.foldovers = current.foldovers;
    r.time_s = seconds_since(t_start);
    r.phase = "initial";
    emit_step(r, state.mesh, state.layout, result.reports, observer);
  }

  // A node on this vertex is on a curve: it slides along it while the curve goes on straight
  // there (curves.slides), and stays on a curve end, junction or corner.
  bool on_curve(int vertex) const { return !curves.empty() && !curves.neighbours[vertex].empty(); }

  // The nodes that may move: those off the curves as movable_nodes says, those on a curve
  // (slide_on_curves) when not pinned and not an end of a pinned arc. Whether a node slides or
  // moves freely depends on the vertex it is on at each step.
  void compute_movable() {
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

  // Slides movable node \p i (node n, on a curve) of \p trial along its curve by the projection
  // of −grad[i] (paper §6.1.1): walks the curve polyline (original positions) from the node's
  // position, stops before a curve end, junction, corner, another node or another arc, and
  // relocates the nearer end of the segment it reaches (the node's vertex, or the next one
  // with the arcs along the curve moved with it). False when the node does not move.
  bool slide_on_curve(State& trial, size_t i, int n, bool no_switch, LayoutObstacles& obstacles,
                      std::vector<char>& switched) {
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
    if (remaining < no.min_step_relative * mean_edge) return false;
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
      if (!relocation_keeps_orientation(trial.mesh, original, w == v ? -1 : v, w, at,
                                        no.relocation))
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
        if (!move_node_and_reroute(trial.mesh, trial.layout, n, w, no.relocation, &reroute,
                                   &obstacles, &walk))
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

  // Per vertex: the nodes of the trial layout whose vertex or 1-ring (original connectivity)
  // it is (keep_nodes_apart); empty when off.
  std::vector<int> near_count;
  void count_nodes_near(const Layout& layout) {
    near_count.clear();
    if (!no.keep_nodes_apart) return;
    near_count.assign(original.n_vertices(), 0);
    for (const auto& node : layout.nodes) add_near_count(node.vertex, 1);
  }
  // Adds \p d to the count of vertex \p v and of its 1-ring.
  void add_near_count(int v, int d) {
    const auto vh = original.vertex_handle(v);
    near_count[v] += d;
    for (auto wh : original.vv_range(vh)) near_count[wh.idx()] += d;
  }
  // A node moved from vertex \p from to vertex \p to.
  void move_near_count(int from, int to) {
    if (near_count.empty()) return;
    add_near_count(from, -1);
    add_near_count(to, 1);
  }
  // Vertex \p u is next to a node other than the one at vertex \p own (keep_nodes_apart).
  bool next_to_other_node(int own, int u) const {
    if (near_count.empty()) return false;
    bool mine = u == own;  // the own node's count covers u too
    for (auto wh : original.vv_range(original.vertex_handle(own))) mine |= wh.idx() == u;
    return near_count[u] - (mine ? 1 : 0) > 0;
  }

  // The Pipeline of a state whose nodes moved to other vertices (re-routed layout): continued
  // from the current one (reuse_field: it reuses the field solver, so update_layout needs no
  // analysis and numeric factorizations only for a changed constraint set or a drop pass, and
  // the geometry; see Pipeline(mesh, layout, previous)), or fresh. \p own_solvers: the
  // continued Pipeline copies the field factorizations it shares with the current one, so that
  // it can be solved on another thread (parallel_hops).
  std::shared_ptr<Pipeline> switched_pipeline(const TriMesh& m, const Layout& l, bool own_solvers) {
    if (no.reuse_field && current.pipeline->field()) {
      ++counters.relayouts;
      auto p = std::make_shared<Pipeline>(m, l, *current.pipeline);
      if (own_solvers) p->unshare_solvers();
      return p;
    }
    ++counters.fresh_pipelines;
    return std::make_shared<Pipeline>(m, l, options, false);
  }

  Evaluation evaluate_switched(const TriMesh& m, const Layout& l) {
    Evaluation ev;
    ev.pipeline = switched_pipeline(m, l, false);
    solve_and_measure(ev, options);
    counters.prepared_param_solvers += ev.pipeline->param_solver_prepared();
    return ev;
  }

  // The current (just accepted) state, when it has no fold-over and is among the
  // kFoldFreeKept lowest E of the fold-free states so far: a candidate for the result rule.
  void note_fold_free(bool initial = false) {
    if (current.foldovers > 0) return;
    if (initial) {
      fold_free_initial = {current.E, std::make_shared<const State>(state)};
      return;
    }
    if (fold_free.size() >= kFoldFreeKept && current.E >= fold_free.back().first) return;
    auto at = std::upper_bound(fold_free.begin(), fold_free.end(), current.E,
                               [](double e, const auto& c) { return e < c.first; });
    fold_free.insert(at, {current.E, std::make_shared<const State>(state)});
    if (fold_free.size() > kFoldFreeKept) fold_free.pop_back();
  }

  void note_fold_count(const State& before, int after_folds) {
    if (after_folds <= fewest_folds_count) {  // the new state is the best (equal: lower E)
      fewest_folds.reset();
      fewest_folds_count = after_folds;
    } else if (!fewest_folds) {  // leaving the best state
      fewest_folds = std::make_unique<State>(before);
    }
  }

  // Hop sweep (discrete.h; NodeOptOptions::hop_polish): all relocations undone at once, cone
  // restores and hops, then relocated nodes try the neighbours in the direction of their
  // relocation. Returns true when E fell (state and current updated). \p cones_only: the sweep
  // before the descent (hop_cones_first): only the collective and cone passes, and nothing (no
  // solve, no report) when no node has a cone candidate.
  bool hop_round(bool cones_only) {
    const auto t_hop = std::chrono::steady_clock::now();
    check_cancel(observer);
    // The solved candidate with the lowest E so far (a job may run on the second thread): the
    // sweep's final state is usually one of them, and then needs no second solve at the end.
    std::mutex best_mutex;
    Evaluation best;
    auto keep_if_best = [&](Evaluation ev) {
      if (!no.reuse_hop_solve) return;
      std::lock_guard<std::mutex> lock(best_mutex);
      if (!best.pipeline || ev.E < best.E) best = std::move(ev);
    };
    const HopEvaluator evaluate = [&](const TriMesh& m, const Layout& l, double& E, int& folds) {
      return measured(
          [&] {
            Evaluation ev = evaluate_switched(m, l);
            keep_if_best(ev);
            return ev;
          },
          E, folds);
    };
    // Two at a time (parallel_hops): each job's Pipeline is built here and owns its
    // factorizations before any thread solves it.
    const HopJobMaker make_job = [&](const TriMesh& m, const Layout& l) -> HopJob {
      ++counters.parallel_hop_jobs;
      std::shared_ptr<Pipeline> p;
      try {
        p = switched_pipeline(m, l, true);
      } catch (const QsError&) {
        return [](double&, int&) { return false; };
      }
      const PipelineOptions* opts = &options;
      return [p, opts, &keep_if_best](double& E, int& folds) {
        return measured(
            [&] {
              Evaluation ev;
              ev.pipeline = p;
              solve_and_measure(ev, *opts);
              keep_if_best(ev);
              return ev;
            },
            E, folds);
      };
    };
    const HopJobMaker* jobs =
        no.parallel_hops && std::thread::hardware_concurrency() >= 2 ? &make_job : nullptr;
    State hopped = state;
    HopSweepResult h;
    h.E = current.E;
    h.foldovers = current.foldovers;
    // One hop_sweep of hopped, its result accumulated into h (evaluations too when the sweep
    // draws on the neighbour hops' budget).
    auto run_sweep = [&](const std::vector<int>& nodes, const std::vector<Vec3>& directions,
                         HopSweepOptions sweep, bool counts_evaluations) {
      sweep.relocation = no.relocation;
      sweep.keep_nodes_apart = no.keep_nodes_apart;
      sweep.stop = no.stop;
      if (nodes.empty() || sweep.max_evaluations <= 0) return;
      const HopSweepResult s =
          hop_sweep(original, hopped.mesh, hopped.layout, nodes, directions, h.E, h.foldovers,
                    sweep, evaluate, observer, &reroute, jobs);
      h.moved += s.moved;
      if (counts_evaluations) h.evaluations += s.evaluations;
      h.E = s.E;
      h.foldovers = s.foldovers;
    };
    // The relocated nodes (most strained first), each towards its relocation offset.
    auto sweep_nodes = [&](double min_offset, HopSweepOptions sweep) {
      std::vector<std::pair<double, int>> strained;  // (−offset, node)
      for (int n : movable) {
        if (on_curve(hopped.layout.nodes[n].vertex)) continue;  // not off its curve
        const auto vh = original.vertex_handle(hopped.layout.nodes[n].vertex);
        const double d = (hopped.mesh.point(vh) - original.point(vh)).norm();
        if (d > 0 && d >= min_offset * mean_edge) strained.push_back({-d, n});
      }
      std::sort(strained.begin(), strained.end());
      std::vector<int> nodes;
      std::vector<Vec3> directions;
      for (const auto& [d, n] : strained) {  // directions: the relocation offsets
        const auto vh = original.vertex_handle(hopped.layout.nodes[n].vertex);
        nodes.push_back(n);
        directions.push_back(hopped.mesh.point(vh) - original.point(vh));
      }
      sweep.max_evaluations = no.hop_max_evaluations - h.evaluations;
      run_sweep(nodes, directions, sweep, true);
    };
    // Sharp cone vertices (discrete.h cone_candidates; none on smooth meshes).
    ConeCandidates cones;
    auto find_cones = [&]() {
      if (!no.hop_cones) return;
      if (deficits.empty()) deficits = vertex_angle_deficits(original_geometry);
      std::vector<int> cone_nodes;  // all but the nodes on the boundary
      for (int n : movable)
        if (!original.is_boundary(original.vertex_handle(hopped.layout.nodes[n].vertex)))
          cone_nodes.push_back(n);
      cones = cone_candidates(original, hopped.mesh, hopped.layout, cone_nodes,
                              current.pipeline->topology().valence, deficits, no.hop_cone_tolerance,
                              no.hop_cone_rings, no.hop_cone_targets);
    };
    find_cones();
    if (cones_only && cones.hop_nodes.empty() && cones.snap_nodes.empty()) return false;
    ++result.hop_rounds;
    // All at once first, one solve (single moves miss collective optima: one node on its cone
    // or vertex while its neighbours are not can raise E): every relocation undone and every
    // node off its cone onto its nearest fitting vertex.
    if (no.hop_collective && !stop_requested()) {
      check_cancel(observer);
      State all = hopped;
      int moved = 0;
      for (int n : movable) {
        const auto vh = original.vertex_handle(all.layout.nodes[n].vertex);
        moved += all.mesh.point(vh) != original.point(vh);
      }
      for (size_t i = 0; i < cones.hop_nodes.size(); ++i) {
        const int n = cones.hop_nodes[i];
        const std::vector<char> forbidden =
            forbidden_relocation_vertices(original, all.layout, n, no.keep_nodes_apart);
        for (int w : cones.hop_targets[i])
          if (!forbidden[w] &&
              move_node_and_reroute(all.mesh, all.layout, n, w, no.relocation, &reroute)) {
            ++moved;
            break;
          }
      }
      all.mesh = original;  // every relocation undone
      double E = 0;
      int folds = 0;
      if (moved > 0 && evaluate(all.mesh, all.layout, E, folds) && E < h.E) {
        hopped = std::move(all);
        h.moved += moved;
        h.E = E;
        h.foldovers = folds;
        find_cones();
      }
    }
    // Then one node at a time (own budget): relocations off a fitting cone undone, and hops
    // onto a fitting cone nearby.
    auto cone_sweep = [&](const std::vector<int>& nodes, HopSweepOptions sweep) {
      sweep.max_evaluations = no.hop_cone_max_evaluations;
      sweep.max_failures = no.hop_cone_max_failures;
      run_sweep(nodes, {}, sweep, false);
    };
    {
      HopSweepOptions snap;
      snap.try_restore = true;
      snap.try_neighbours = false;
      cone_sweep(cones.snap_nodes, snap);
      HopSweepOptions onto;
      onto.targets = cones.hop_targets;
      cone_sweep(cones.hop_nodes, onto);
    }
    if (!cones_only) {  // relocated nodes, farthest off their vertex first, try neighbours
      HopSweepOptions sweep;
      sweep.max_candidates = no.hop_candidates;
      sweep.min_direction_cos = no.hop_min_cos;
      sweep.max_failures = no.hop_max_failures;
      sweep_nodes(no.hop_min_offset, sweep);
      // Sliding nodes relocated along their curve hop to the curve neighbour they lean to.
      std::vector<std::pair<double, int>> leaning;  // (−t, node)
      for (int n : movable) {
        const int v = hopped.layout.nodes[n].vertex;
        const auto vh = original.vertex_handle(v);
        if (on_curve(v) && curves.slides[v] && hopped.curve[n].toward >= 0 &&
            hopped.mesh.point(vh) != original.point(vh))
          leaning.push_back({-hopped.curve[n].t, n});
      }
      std::sort(leaning.begin(), leaning.end());
      HopSweepOptions along;
      along.curves = &curves;
      along.max_failures = no.hop_max_failures;
      std::vector<int> nodes;
      for (const auto& [t, n] : leaning) {
        nodes.push_back(n);
        along.targets.push_back({hopped.curve[n].toward});
      }
      along.max_evaluations = no.hop_max_evaluations - h.evaluations;
      run_sweep(nodes, {}, along, true);
    }
    bool kept = false;
    if (h.moved > 0) {
      for (int n : movable) {  // hopped or restored: the node sits at its vertex's original point
        const int v = hopped.layout.nodes[n].vertex;
        const auto vh = original.vertex_handle(v);
        if (v != state.layout.nodes[n].vertex || hopped.mesh.point(vh) != state.mesh.point(vh)) {
          hopped.anchor[n] = vertex_surface_point(original, v);
          hopped.curve[n] = CurvePoint{};
        }
      }
      check_cancel(observer);
      // The kept candidate's own solve when it is the best one solved (always, unless a
      // discarded parallel solve was lower); otherwise the state is solved again.
      Evaluation next;
      if (no.reuse_hop_solve && best.pipeline && best.E == h.E &&
          pipeline_matches(*best.pipeline, hopped.mesh, hopped.layout)) {
        next = std::move(best);
        ++counters.reused_hop_solves;
      } else {
        next = evaluate_switched(hopped.mesh, hopped.layout);
      }
      if (next.E <= current.E) {  // equal to h.E: the same deterministic solve
        if (!pre_polish) pre_polish = std::make_unique<State>(state);
        note_fold_count(state, next.foldovers);
        state = std::move(hopped);
        current = std::move(next);
        note_fold_free();
        current_solved = true;
        state_changed = true;
        result.hops += h.moved;
        kept = true;
      }
    }
    StepReport r;
    r.step = result.steps + result.hop_rounds;
    r.E = current.E;
    r.accepted = kept;
    r.step_size = 0;
    r.foldovers = current.foldovers;
    r.moved_nodes = kept ? h.moved : 0;
    r.time_s = seconds_since(t_hop);
    r.phase = "hop";
    emit_step(r, state.mesh, state.layout, result.reports, observer);
    return kept;
  }

  bool stop_requested() const { return no.stop && no.stop(); }

  // When a descent phase ends: a hop sweep; true when nodes hopped and a new phase begins.
  bool polish() {
    if (!no.hop_polish || polish_rounds >= no.max_hop_rounds) return false;
    ++polish_rounds;
    if (!hop_round(false)) return false;
    alpha = no.hop_alpha_growth > 0 && accepted_alpha > 0
                ? std::min(no.alpha, no.hop_alpha_growth * accepted_alpha)
                : no.alpha;
    accepted_alpha = 0;
    phase_halvings = 0;
    stalled_steps = 0;
    std::fill(rejected_target.begin(), rejected_target.end(), -1);
    std::fill(damping.begin(), damping.end(), 1.0);
    step_budget = std::max(step_budget, result.steps + no.hop_descent_steps);
    return true;
  }

  // One unit of the optimization: the sweep before the descent (hop_cones_first, when it
  // runs), then a descent step, or the hop sweep that ends a descent phase. False when the
  // descent and the polish are over (finish() remains); a last sweep that kept nothing may have
  // run and been reported in that call.
  bool step() {
    if (descent_over) return false;
    if (stop_requested()) {
      result.stopped = true;
      descent_over = true;
      return false;
    }
    if (!started) {
      started = true;
      if (no.hop_polish && no.hop_cones_first && !movable.empty()) {
        const int rounds = result.hop_rounds;
        hop_round(true);
        if (result.hop_rounds > rounds) return true;
      }
    }
    const bool stalled = no.stall_gain > 0 && stalled_steps >= no.stall_steps;
    if (movable.empty() || result.steps >= step_budget || phase_halvings > no.max_halvings ||
        stalled) {
      if (!movable.empty() && polish()) return true;
      descent_over = true;
      return false;
    }
    check_cancel(observer);
    const auto t_step = std::chrono::steady_clock::now();
    if (state_changed) {
      // Node-Voronoi cells on the original mesh, from all node vertices: on the second thread
      // while the gradients are computed (they only read the original mesh and the node list),
      // on meshes large enough for a thread to pay (PipelineOptions::second_thread_min_faces).
      std::vector<int> all_vertices;
      for (const auto& n : state.layout.nodes) all_vertices.push_back(n.vertex);
      std::future<std::vector<int>> cells;
      if (options.param.second_thread &&
          static_cast<int>(original.n_faces()) >= options.second_thread_min_faces)
        cells = std::async(std::launch::async, [this, &all_vertices] {
          return node_voronoi_cells(original, all_vertices);
        });
      // Gradients at the current solution (the future waits in its destructor if they throw).
      std::vector<int> vertices;
      for (int n : movable) vertices.push_back(state.layout.nodes[n].vertex);
      if (no.gradient == GradientMethod::Exact) {
        grad =
            exact_node_gradients(state.mesh, state.layout, options, vertices, no.exact, observer);
        scale = no.exact_scale;
      } else {
        const Pipeline& p = *current.pipeline;
        grad = estimate_node_gradients(p.mesh(), p.geometry(), p.field()->theta,
                                       *p.parameterization(), options.param, vertices);
        scale = no.estimator_scale;
      }
      cell = cells.valid() ? cells.get() : node_voronoi_cells(original, all_vertices);
      state_changed = false;
    } else {
      ++counters.gradient_reuses;
    }

    // The step of movable node i from \p anchor, traced on the original mesh; nullopt when it
    // is shorter than the step resolution.
    auto trace_step = [&](size_t i, const SurfacePoint& anchor) -> std::optional<GeodesicTrace> {
      const int n = movable[i];
      const double len = alpha * damping[i] * scale * grad[i].norm();
      if (len < no.min_step_relative * mean_edge) return std::nullopt;
      auto blocked = [&](int f) {
        if (!no.voronoi_safeguard) return false;
        for (auto vh : original.fv_range(original.face_handle(f)))
          if (cell[vh.idx()] == n || cell[vh.idx()] < 0) return false;
        return true;
      };
      return trace_straightest_geodesic(original, anchor, -grad[i] / grad[i].norm(), len, blocked);
    };
    // Builds the trial state; nodes with no_switch[i] set may only move within faces of their
    // current vertex's original 1-ring. \p sym (symmetric optimization; empty when off): per
    // node, the target that replaces its own step.
    auto build_trial_to = [&](const std::vector<char>& no_switch,
                              const std::vector<SymmetricTarget>& sym, State& trial,
                              std::vector<char>& switched) {
      trial = state;
      switched.assign(movable.size(), 0);
      target.assign(movable.size(), -1);
      int moved = 0;
      // Arc and node obstacles of the trial layout, kept up to date by each re-routing.
      // Vertices on the curves are not relocated for other nodes (paper §6.1.1).
      LayoutObstacles obstacles = make_layout_obstacles(trial.mesh, trial.layout, &curves);
      count_nodes_near(trial.layout);
      for (size_t i = 0; i < movable.size(); ++i) {
        const int n = movable[i];
        if (on_curve(trial.layout.nodes[n].vertex)) {
          moved += slide_on_curve(trial, i, n, no_switch[i], obstacles, switched);
          continue;
        }
        const std::optional<GeodesicTrace> step =
            sym.empty() ? trace_step(i, trial.anchor[n]) : symmetric_trace(sym[n]);
        if (!step) continue;
        const GeodesicTrace& tr = *step;
        const int v = trial.layout.nodes[n].vertex;
        // A step that ends next to a vertex on a sharp edge or feature curve takes the node onto
        // that vertex at its place (such vertices are not relocated for nodes off the curves).
        if (!no_switch[i] && !curves.empty()) {
          int near = -1;
          double near_d = 0.5 * mean_edge;
          for (auto vh : original.fv_range(original.face_handle(tr.end.face))) {
            const double d = (original.point(vh) - tr.end_position).norm();
            if (d < near_d) near_d = d, near = vh.idx();
          }
          if (near >= 0 && near != v && on_curve(near) && !next_to_other_node(v, near) &&
              !original.is_boundary(original.vertex_handle(near)) &&
              !occupied_by_layout(trial.layout, n, obstacles, near) &&
              relocation_keeps_orientation(trial.mesh, original, v, near,
                                           original.point(original.vertex_handle(near)),
                                           no.relocation) &&
              move_node_and_reroute(trial.mesh, trial.layout, n, near, no.relocation, &reroute,
                                    &obstacles)) {
            trial.mesh.set_point(trial.mesh.vertex_handle(v),
                                 original.point(original.vertex_handle(v)));
            move_near_count(v, near);
            trial.anchor[n] = vertex_surface_point(original, near);
            trial.curve[n] = CurvePoint{};
            switched[i] = 1;
            target[i] = near;
            ++moved;
            continue;
          }
        }
        const auto forbidden = [&](int u) {
          return no_switch[i] || relocation_forbidden(trial.layout, n, obstacles, u) ||
                 (u != v && next_to_other_node(v, u));
        };
        const int w = choose_relocation_vertex(trial.mesh, original, tr.end, tr.end_position, v,
                                               forbidden, no.relocation);
        if (w < 0) continue;
        if (w != v) {
          if (!move_node_and_reroute(trial.mesh, trial.layout, n, w, no.relocation, &reroute,
                                     &obstacles))
            continue;
          trial.mesh.set_point(trial.mesh.vertex_handle(v),
                               original.point(original.vertex_handle(v)));
          switched[i] = 1;
          target[i] = w;
          move_near_count(v, w);
        }
        trial.mesh.set_point(trial.mesh.vertex_handle(w), tr.end_position);
        trial.anchor[n] = tr.end;
        ++moved;
      }
      return moved;
    };
    // ---- symmetric optimization (NodeOptOptions::symmetry; symmetric_step.h) ----
    // The trial of the step's targets made symmetric, built again without the pairs it could not
    // realize as mirror images.
    auto build_trial = [&](const std::vector<char>& no_switch, State& trial,
                           std::vector<char>& switched) {
      if (!symmetric) return build_trial_to(no_switch, {}, trial, switched);
      std::vector<SymmetricTarget> sym = symmetric->targets(state.anchor, movable, [&](size_t i) {
        const std::optional<GeodesicTrace> tr = trace_step(i, state.anchor[movable[i]]);
        return tr ? std::optional<SurfacePoint>(tr->end) : std::nullopt;
      });
      for (;;) {
        const int moved = build_trial_to(no_switch, sym, trial, switched);
        if (!symmetric->hold_unmatched(state.mesh, state.layout, trial.mesh, trial.layout, sym))
          return moved;
      }
    };
    // ---- end of symmetric optimization ----
    // A trial without switches has state's layout: re-solve the current Pipeline in place.
    auto try_evaluate = [&](const State& trial, const std::vector<char>& switched,
                            Evaluation& next) {
      check_cancel(observer);
      const bool reuse = std::find(switched.begin(), switched.end(), 1) == switched.end();
      try {
        if (reuse) {
          current_solved = false;
          next = evaluate_reused(current.pipeline, trial.mesh, options);
          ++counters.reused_solves;
        } else {
          next = evaluate_switched(trial.mesh, trial.layout);
        }
        return true;
      } catch (const Cancelled&) {
        throw;
      } catch (const QsError&) {
        return false;  // e.g. a layout the field cannot realize: treat like an increase
      }
    };
    State trial;
    std::vector<char> switched;
    int moved = build_trial(std::vector<char>(movable.size(), 0), trial, switched);
    const std::vector<int> first_target = target;
    ++result.steps;
    StepReport r;
    r.step = result.steps + result.hop_rounds;
    r.step_size = alpha;
    r.moved_nodes = moved;
    r.phase = "descent";
    if (moved == 0) {  // converged: every node is at its optimum within the step resolution
      r.E = current.E;
      r.accepted = false;
      r.foldovers = current.foldovers;
      r.time_s = seconds_since(t_step);
      emit_step(r, state.mesh, state.layout, result.reports, observer);
      if (polish()) return true;
      descent_over = true;
      return false;
    }
    Evaluation next;
    // Mostly the switches of a trial rejected at this α: rejected again without a solve, the
    // retry without switches follows (switch_tabu).
    int n_switched = 0, n_repeated = 0;
    for (size_t i = 0; i < movable.size(); ++i) {
      n_switched += switched[i];
      n_repeated += switched[i] && first_target[i] == rejected_target[i];
    }
    const bool repeated =
        no.switch_tabu && n_switched > 0 && n_repeated >= no.switch_tabu_overlap * n_switched;
    counters.tabu_steps += repeated;
    // The retry without switches (below) does not depend on the re-layout's result: with
    // parallel_retry it is solved on this thread while the re-layout is solved on another.
    State retry;
    std::vector<char> retry_switched;
    bool retry_built = false;
    Evaluation second;
    bool second_ok = false;
    bool ok = false;
    const bool retry_possible = no.retry_without_switches && n_switched > 0 && !repeated;
    if (retry_possible && no.parallel_retry && no.reuse_field && current.pipeline->field() &&
        std::thread::hardware_concurrency() >= 2) {
      retry_built = true;
      const bool retry_moves = build_trial(switched, retry, retry_switched) > 0;
      const bool retry_reuses =
          std::find(retry_switched.begin(), retry_switched.end(), 1) == retry_switched.end();
      if (retry_moves && retry_reuses) {
        check_cancel(observer);
        // The continued Pipeline is built here (it copies the current one, which the retry
        // re-solves in place) and owns its factorizations before the other thread starts.
        std::shared_ptr<Pipeline> p;
        try {
          p = std::make_shared<Pipeline>(trial.mesh, trial.layout, *current.pipeline);
          p->unshare_solvers();
        } catch (const QsError&) {
          p.reset();
        }
        if (p) {
          ++counters.relayouts;
          ++counters.parallel_retries;
          auto first = std::async(std::launch::async, [p, opts = &options]() {
            Evaluation ev;
            ev.pipeline = p;
            solve_and_measure(ev, *opts);
            return ev;
          });
          second_ok = try_evaluate(retry, retry_switched, second);  // waits for first if it throws
          try {
            next = first.get();
            ok = true;
          } catch (const QsError&) {
            ok = false;  // e.g. a layout the field cannot realize: treat like an increase
          }
        } else {
          ok = false;
          second_ok = try_evaluate(retry, retry_switched, second);
        }
      } else {
        ok = try_evaluate(trial, switched, next);
        if (!(ok && next.E <= current.E) && retry_moves)
          second_ok = try_evaluate(retry, retry_switched, second);
      }
    } else {
      ok = !repeated && try_evaluate(trial, switched, next);
    }
    const bool first_ok = ok && next.E <= current.E;
    if (!repeated && n_switched > 0)
      rejected_target = first_ok ? std::vector<int>(movable.size(), -1) : first_target;
    // A node that changed its vertex can raise E discontinuously: retry once with those nodes
    // kept on their vertices before halving α.
    if (no.retry_without_switches && !(ok && next.E <= current.E) && n_switched > 0) {
      if (!retry_built && build_trial(switched, retry, retry_switched) > 0)
        second_ok = try_evaluate(retry, retry_switched, second);
      if (second_ok && second.E <= current.E) {
        trial = std::move(retry);
        next = std::move(second);
        ok = true;
      }
    }
    // The sliding nodes whose switches raised E take half steps from now on (until one of their
    // switches is accepted or a hop sweep starts a new phase).
    if (no.damp_rejected_slides && !repeated && n_switched > 0 && !first_ok)
      for (size_t i = 0; i < movable.size(); ++i)
        if (first_target[i] >= 0 && on_curve(first_target[i])) damping[i] *= 0.5;
    r.accepted = ok && next.E <= current.E;
    r.E = ok ? next.E : current.E;
    r.foldovers = ok ? next.foldovers : current.foldovers;
    if (r.accepted) {
      for (size_t i = 0; i < movable.size(); ++i)
        if (trial.layout.nodes[movable[i]].vertex != state.layout.nodes[movable[i]].vertex)
          damping[i] = 1;
      const bool small_gain = current.E - next.E < no.stall_gain * current.E;
      stalled_steps = small_gain ? stalled_steps + 1 : 0;
      accepted_alpha = alpha;
      note_fold_count(state, next.foldovers);
      state = std::move(trial);
      current = std::move(next);
      note_fold_free();
      current_solved = true;
      state_changed = true;
      ++result.accepted;
    } else {
      alpha *= 0.5;
      ++result.halvings;
      ++phase_halvings;
      std::fill(rejected_target.begin(), rejected_target.end(), -1);
    }
    r.time_s = seconds_since(t_step);
    emit_step(r, state.mesh, state.layout, result.reports, observer);
    return true;
  }

  // The last trial re-solved the current Pipeline in place and was rejected: solve it at the
  // state again.
  void solve_current() {
    if (current_solved) return;
    check_cancel(observer);
    current.pipeline->update_positions(state.mesh);
    current.pipeline->compute_field();
    current.pipeline->compute_parameterization();
    ++counters.reused_solves;
    current_solved = true;
  }

  // Pins changed between steps (NodeOptimizer::set_pinned): per node and, when \p arc_pinned is
  // not empty, per arc (both by index).
  void set_pinned(const std::vector<char>& pinned, const std::vector<char>& arc_pinned) {
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

  // The end of the optimization at the current state: fold-over removal (orientation
  // constraints, earlier states, stiffening) and the result.
  NodeOptResult finish(NodeOptStats* stats) {
    descent_over = true;
    finished = true;
    solve_current();
    // Stiffening (§7.1) of state \p st (its descent solve: \p descent) into \p out when it leaves
    // fewer fold-overs than out's result.
    auto stiffen_into = [&](const State& st, const std::shared_ptr<Pipeline>& descent,
                            NodeOptResult& out) {
      const auto t_st = std::chrono::steady_clock::now();
      const StiffeningResult sr = stiffen(st.mesh, st.layout, options, no.stiffening, observer);
      out.stiffening_iterations = sr.iterations;
      if (sr.foldovers_after < out.foldovers_final) {
        out.orientation_constraints = false;
        out.pipeline = descent;
        out.face_weights = sr.face_weights;
        out.E_final = sr.E_after;
        out.foldovers_final = sr.foldovers_after;
      }
      StepReport r;
      r.step = result.steps + result.hop_rounds + 1;
      r.E = out.E_final;
      r.accepted = !out.face_weights.empty();
      r.step_size = 0;
      r.foldovers = out.foldovers_final;
      r.time_s = seconds_since(t_st);
      r.phase = "stiffening";
      emit_step(r, st.mesh, st.layout, out.reports, observer);
    };
    // Earlier states the fold-over removal falls back to (try_earlier below). With one, stiffening
    // waits until every state's orientation solve was tried: it is the costlier fallback and
    // rarely removes what the constraints could not (the 70K bunny after the polish: 147 → 142
    // fold-overs in 5.6 s), while the orientation solve at an earlier state often succeeds.
    const bool try_fewest = fewest_folds && fewest_folds_count < current.foldovers;
    const bool has_earlier = no.orientation_at_end && (pre_polish || try_fewest);
    // One orientation-constrained solve of \p st (\p untangle: OrientationOptions::untangle;
    // \p fallback: as remove_foldovers'), polled by \p obs; its options, without the observer,
    // into \p used.
    auto oriented_solve = [&](const State& st, bool untangle, bool fallback, Observer* obs,
                              OrientationOptions& used) {
      PipelineOptions oriented = options;
      oriented.param.orientation = no.orientation;
      oriented.param.orientation.enabled = true;
      oriented.param.orientation.observer = obs;  // polled inside the solve (seconds long)
      oriented.param.orientation.untangle = untangle;
      if (fallback) oriented.param.orientation.stop_if_all_faces_infeasible = true;
      auto p = std::make_shared<Pipeline>(st.mesh, st.layout, oriented);
      p->compute_field();
      p->compute_parameterization();
      used = oriented.param.orientation;
      used.observer = nullptr;  // not valid after this call
      return p;
    };
    // Reports a fold-over removal solve begun at \p t as an "orientation" step.
    auto emit_orientation = [&](const State& st, const NodeOptResult& out, bool accepted,
                                std::chrono::steady_clock::time_point t,
                                std::vector<StepReport>& reports, Observer* obs) {
      StepReport r;
      r.step = result.steps + result.hop_rounds + 1;
      r.E = out.E_final;
      r.accepted = accepted;
      r.foldovers = out.foldovers_final;
      r.time_s = seconds_since(t);
      r.phase = "orientation";
      emit_step(r, st.mesh, st.layout, reports, obs);
    };
    // The end of the descent at (state, current): fold-over removal, results into `out`.
    // \p fallback: an earlier state will be tried when fold-overs remain here, so an infeasible
    // all-faces orientation round ends this attempt.
    // \p obs: polled for cancellation and given the reports (the caller's observer; for the
    // speculative attempt its stop flag, the reports then streamed later by try_earlier).
    // \p stiffen: stiffening follows here when fold-overs remain.
    auto remove_foldovers = [&](const State& st_in, const Evaluation& ev, NodeOptResult& out,
                                bool fallback, bool stiffen, Observer* obs) {
      out.pipeline = ev.pipeline;
      out.descent_pipeline = ev.pipeline;
      out.E_descent = ev.E;
      out.foldovers_descent = ev.foldovers;
      out.E_final = ev.E;
      out.foldovers_final = ev.foldovers;

      // Fold-over removal: strict orientation constraints in the last solve (docs/design.md,
      // "Orientation constraints"), stiffening (§7.1) only as the fallback when fold-overs remain.
      const bool at_this_state =
          no.orientation_at_moved_states || (initial_state && same_state(*initial_state, st_in));
      if (no.orientation_at_end && ev.foldovers > 0 && at_this_state) {
        const auto t_or = std::chrono::steady_clock::now();
        check_cancel(obs);
        try {
          // Untangling is the last resort, after every state was tried (below).
          OrientationOptions used;
          auto p = oriented_solve(st_in, false, fallback, obs, used);
          const Parameterization& par = *p->parameterization();
          out.orientation = par.orientation;
          if (par.orientation.success && par.foldovers < ev.foldovers) {
            out.orientation_constraints = true;
            out.orientation_options = used;
            out.E_final =
                unweighted_energy(p->mesh(), p->geometry(), p->field()->theta, par, options.param);
            out.foldovers_final = par.foldovers;
            out.pipeline = std::move(p);
          }
        } catch (const Cancelled&) {
          throw;
        } catch (const QsError& e) {
          out.orientation.message = e.what();
        }
        emit_orientation(st_in, out, out.orientation_constraints, t_or, out.reports, obs);
      }
      if (stiffen && no.stiffen_at_end && out.foldovers_final > 0)
        stiffen_into(st_in, ev.pipeline, out);
    };
    // The fold-over removal at the state before the polish, solved speculatively
    // (parallel_fallback). Declared after the lambda and the states it reads: its destructor
    // waits for it before they go away. `stop` ends it at its next poll once it is not needed.
    struct Speculative {
      Evaluation evaluation;
      NodeOptResult result;
      std::exception_ptr error;
    };
    struct StopFlag : Observer {
      std::atomic<bool> stop{false};
      bool should_cancel() const override { return stop.load(); }
    } speculative_stop;
    std::future<Speculative> speculative;
    struct StopOnExit {  // also on an exception: the future's destructor then waits less
      StopFlag& flag;
      ~StopOnExit() { flag.stop = true; }
    } stop_on_exit{speculative_stop};
    // parallel_fallback: the state before the polish is solved and oriented on a second thread
    // while this one orients the final state; its result (and its reports) are used exactly when
    // the sequential order would have tried it.
    if (no.orientation_at_end && pre_polish && current.foldovers > 0 && no.parallel_fallback &&
        std::thread::hardware_concurrency() >= 2) {
      const State* earlier = pre_polish.get();
      const bool later = try_fewest;
      speculative = std::async(std::launch::async, [&, earlier, later]() {
        Speculative out;
        try {
          out.evaluation = evaluate_fresh(earlier->mesh, earlier->layout, options, false);
          check_cancel(&speculative_stop);
          remove_foldovers(*earlier, out.evaluation, out.result, later, !has_earlier,
                           &speculative_stop);
        } catch (...) {
          out.error = std::current_exception();
        }
        return out;
      });
    }
    remove_foldovers(state, current, result, has_earlier, !has_earlier, observer);
    if (result.foldovers_final == 0) speculative_stop.stop = true;  // not needed
    // The descent and the polish lower E but can end where the fold-over removal fails although
    // it succeeds at an earlier state: the state before the first hop, then the accepted state
    // with the fewest fold-overs, are tried; a result with fewer fold-overs (equal: lower final
    // E) is taken.
    // \p later: another earlier state follows this one.
    // \p stiffen: as remove_foldovers'.
    auto try_earlier = [&](std::unique_ptr<State>& earlier, bool& flag, bool later, bool stiffen) {
      if (result.foldovers_final == 0 || !earlier) return;
      check_cancel(observer);
      NodeOptResult alt;
      if (speculative.valid() && earlier == pre_polish) {
        Speculative done = speculative.get();
        if (done.error) std::rethrow_exception(done.error);
        alt = std::move(done.result);
        ++counters.parallel_fallbacks;
        if (observer)  // streamed now, in the order of the sequential attempt
          for (const StepReport& r : alt.reports) observer->on_step(r);
      } else {
        Evaluation ev = evaluate_fresh(earlier->mesh, earlier->layout, options, false);
        remove_foldovers(*earlier, ev, alt, later, stiffen, observer);
      }
      ++counters.fresh_pipelines;
      result.reports.insert(result.reports.end(), alt.reports.begin(), alt.reports.end());
      if (alt.foldovers_final < result.foldovers_final ||
          (alt.foldovers_final == result.foldovers_final && alt.E_final < result.E_final)) {
        state = std::move(*earlier);
        result.pipeline = alt.pipeline;
        result.descent_pipeline = alt.descent_pipeline;
        result.E_descent = alt.E_descent;
        result.foldovers_descent = alt.foldovers_descent;
        result.E_final = alt.E_final;
        result.foldovers_final = alt.foldovers_final;
        result.orientation_constraints = alt.orientation_constraints;
        result.orientation_options = alt.orientation_options;
        result.orientation = alt.orientation;
        result.face_weights = alt.face_weights;
        result.stiffening_iterations = alt.stiffening_iterations;
        flag = true;
      }
      earlier.reset();
    };
    if (!no.orientation_at_end && !no.stiffen_at_end) pre_polish.reset(), fewest_folds.reset();
    // The initial state last (NodeOptOptions::initial_fallback), unless it is one of the states
    // tried before; with orientation constraints only (no stiffening of it: the state tried
    // before keeps its stiffening). Which states are the initial one, before try_earlier
    // moves them.
    const bool final_is_initial = initial_state && same_state(*initial_state, state);
    const bool pre_polish_is_initial =
        initial_state && pre_polish && same_state(*initial_state, *pre_polish);
    const bool fewest_is_initial =
        initial_state && try_fewest && same_state(*initial_state, *fewest_folds);
    const bool try_initial =
        initial_state && !final_is_initial && !pre_polish_is_initial && !fewest_is_initial;
    try_earlier(pre_polish, result.polish_reverted, try_fewest, !has_earlier);
    if (try_fewest)
      try_earlier(fewest_folds, result.fewest_foldovers_reverted, false, !has_earlier);
    bool initial_taken = false;
    if (try_initial) try_earlier(initial_state, initial_taken, false, false);
    // The state returned is the initial one: taken as such, or as the earlier state that won
    // (the fewest-fold-over state when both earlier states were taken in turn).
    if (initial_taken) result.polish_reverted = result.fewest_foldovers_reverted = false;
    result.initial_reverted =
        initial_taken ||
        (result.fewest_foldovers_reverted ? fewest_is_initial
                                          : result.polish_reverted && pre_polish_is_initial);
    if (has_earlier && no.stiffen_at_end && result.foldovers_final > 0)
      stiffen_into(state, result.descent_pipeline, result);
    // The last resort: the untangling (untangle.h) at the state returned, when the tri-sector
    // constraints left fold-overs at every state tried and stiffening did too. Not inside those
    // attempts: an untangled map has no fold-over but keeps the parametric cones of its state,
    // and the constraints' failure at a state often marks wrong cones that an earlier state does
    // not have (the rocker-arm cage layout: untangled at its final state, 0 fold-overs and 7 bad
    // cones; its fewest-fold-over state embeds structurally equivalent).
    if (no.orientation_at_end && no.orientation.untangle && result.foldovers_final > 0) {
      const auto t_un = std::chrono::steady_clock::now();
      check_cancel(observer);
      try {
        OrientationOptions used;
        auto p = oriented_solve(state, true, false, observer, used);
        const Parameterization& par = *p->parameterization();
        result.orientation.untangle = par.orientation.untangle;  // reported in any case
        if (par.orientation.success && par.foldovers < result.foldovers_final) {
          result.orientation = par.orientation;
          result.orientation_constraints = true;
          result.orientation_options = used;
          result.face_weights.clear();
          result.E_final =
              unweighted_energy(p->mesh(), p->geometry(), p->field()->theta, par, options.param);
          result.foldovers_final = par.foldovers;
          result.pipeline = std::move(p);
          result.untangled = true;
        }
      } catch (const Cancelled&) {
        throw;
      } catch (const QsError& e) {
        result.orientation.message +=
            std::string(result.orientation.message.empty() ? "" : "; ") + "untangling: " + e.what();
      }
      emit_orientation(state, result, result.untangled, t_un, result.reports, observer);
    }
    // The rule for the result: the lowest E among the fold-free, structurally equivalent states,
    // and never worse than a fold-free state visited (the input included). The fold-over
    // removal above can end higher than a fold-free state the descent passed through (the
    // orientation constraints of a folded final state cost E, or its fallbacks are older).
    // Ranks: fold-free and structurally equivalent (2), fold-free (1), folded (0); within a
    // rank the lower E. The kept fold-free states are solved afresh from the lowest E up.
    const auto rank = [](int folds, bool equivalent) { return folds > 0 ? 0 : equivalent ? 2 : 1; };
    int result_rank = rank(result.face_weights.empty() ? result.foldovers_final : 1,
                           result.pipeline && result.pipeline->extract().structurally_equivalent);
    std::shared_ptr<const State> taken;
    Evaluation taken_ev;
    std::vector<std::pair<double, std::shared_ptr<const State>>> candidates = fold_free;
    if (fold_free_initial.second) {
      candidates.push_back(fold_free_initial);
      std::stable_sort(candidates.begin(), candidates.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
    }
    for (const auto& [E, candidate] : candidates) {
      if (result_rank == 2 && E >= result.E_final) break;
      if (same_state(*candidate, state)) continue;
      check_cancel(observer);
      Evaluation ev = evaluate_fresh(candidate->mesh, candidate->layout, options, false);
      ++counters.fresh_pipelines;
      const int r = rank(ev.foldovers, ev.pipeline->extract().structurally_equivalent);
      const double best_E = taken ? taken_ev.E : result.E_final;
      if (r > result_rank || (r == result_rank && r > 0 && ev.E < best_E)) {
        taken = candidate;
        taken_ev = std::move(ev);
        result_rank = r;
      }
      if (result_rank == 2) break;  // the lowest E of the rank-2 states kept
    }
    if (taken) {
      result.initial_reverted = initial_state && same_state(*initial_state, *taken);
      state = *taken;
      result.pipeline = taken_ev.pipeline;
      result.descent_pipeline = taken_ev.pipeline;
      result.E_final = taken_ev.E;
      result.foldovers_final = 0;
      result.orientation_constraints = false;
      result.orientation_options = OrientationOptions{};
      result.face_weights.clear();
      result.untangled = false;
      result.fold_free_reverted = true;
      StepReport r;
      r.step = result.steps + result.hop_rounds + 1;
      r.E = taken_ev.E;
      r.accepted = true;
      r.phase = "fold-free";
      emit_step(r, state.mesh, state.layout, result.reports, observer);
    }
    if (stats) *stats = counters;
    result.mesh = std::move(state.mesh);
    result.layout = std::move(state.layout);
    result.time_s = seconds_since(t_start);
    return std::move(result);
  }
};

std::optional<SeparateNodesResult> separate_movable_nodes(const TriMesh& mesh,
                                                          const Layout& layout) {
  // An invalid layout is left to the initial solve, which names its errors.
  if (!validate_layout(mesh, layout).valid()) return std::nullopt;
  std::vector<char> flags(layout.nodes.size(), 0);
  for (int n : movable_nodes(mesh, layout)) flags[n] = 1;
  return separate_nodes(mesh, layout, flags);
}

NodeOptimizer::NodeOptimizer(const TriMesh& mesh, const Layout& layout,
                             const PipelineOptions& options, const NodeOptOptions& given_options,
                             Observer* observer, std::shared_ptr<Pipeline> start) {
  // Symmetric optimization: what moves single nodes off (symmetric_step.h).
  const NodeOptOptions node_options = symmetric_node_options(given_options);
  std::optional<SeparateNodesResult> separated;
  if (node_options.separate_crowded_nodes) separated = separate_movable_nodes(mesh, layout);
  const bool moved = separated && !separated->moved_nodes.empty();
  impl_ = std::make_unique<Impl>(mesh, moved ? separated->layout : layout, options, node_options,
                                 observer, std::move(start));
  if (separated) {
    impl_->result.separated_nodes = separated->moved_nodes;
    impl_->result.crowded_nodes = static_cast<int>(separated->crowded_nodes.size());
  }
}

NodeOptimizer::~NodeOptimizer() = default;

bool NodeOptimizer::step(Observer* observer) {
  if (impl_->finished) throw std::logic_error("NodeOptimizer::step after finish");
  impl_->observer = observer;
  return impl_->step();
}

void NodeOptimizer::set_pinned(const std::vector<char>& pinned,
                               const std::vector<char>& arc_pinned) {
  if (impl_->finished) throw std::logic_error("NodeOptimizer::set_pinned after finish");
  if (pinned.size() != impl_->state.layout.nodes.size())
    throw std::invalid_argument("NodeOptimizer::set_pinned: one flag per layout node expected");
  if (!arc_pinned.empty() && arc_pinned.size() != impl_->state.layout.arcs.size())
    throw std::invalid_argument("NodeOptimizer::set_pinned: one flag per layout arc expected");
  impl_->set_pinned(pinned, arc_pinned);
}

const TriMesh& NodeOptimizer::mesh() const {
  return impl_->state.mesh;
}

const Layout& NodeOptimizer::layout() const {
  return impl_->state.layout;
}

const std::vector<StepReport>& NodeOptimizer::reports() const {
  return impl_->result.reports;
}

std::shared_ptr<Pipeline> NodeOptimizer::pipeline(Observer* observer) {
  if (impl_->finished) throw std::logic_error("NodeOptimizer::pipeline after finish");
  impl_->observer = observer;
  impl_->solve_current();
  return impl_->current.pipeline;
}

NodeOptResult NodeOptimizer::finish(Observer* observer, NodeOptStats* stats) {
  if (impl_->finished) throw std::logic_error("NodeOptimizer::finish called twice");
  impl_->observer = observer;
  return impl_->finish(stats);
}

NodeOptResult optimize_nodes(const TriMesh& mesh, const Layout& layout,
                             const PipelineOptions& options, const NodeOptOptions& node_options,
                             Observer* observer, std::shared_ptr<Pipeline> start,
                             NodeOptStats* stats) {
  NodeOptimizer optimizer(mesh, layout, options, node_options, observer, std::move(start));
  while (optimizer.step(observer)) {
  }
  return optimizer.finish(observer, stats);
}

}  // namespace qs
