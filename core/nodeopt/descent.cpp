// The descent step of the node optimization (docs/design.md, "Node optimization", "Gradient",
// "Step length", "Straightest geodesics", "Retries"): gradients and node-Voronoi cells at the
// state, a trial that moves every movable node along −∇E (straightest geodesics, relocations,
// slides on curves), its solve (in place when no node changed its vertex), accept or reject
// (α halved), the retry without switches, the switch tabu and the damping of rejected slides;
// a phase that ends hands over to the hop polish. Part of NodeOptimizer::Impl
// (optimizer_impl.h).
#include <algorithm>
#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/nodeopt/geodesic.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/optimizer_impl.h"
#include "core/nodeopt/relocation.h"

namespace qs {

using nodeopt_detail::emit_step;
using nodeopt_detail::Evaluation;
using nodeopt_detail::kEstimatorScale;
using nodeopt_detail::kExactScale;
using nodeopt_detail::kMaxHalvings;
using nodeopt_detail::kMinStepRelative;
using nodeopt_detail::kSwitchTabuOverlap;
using nodeopt_detail::solve_and_measure;

namespace {

// Same layout, moved vertices: update the geometry of \p pipeline and re-solve.
Evaluation evaluate_reused(std::shared_ptr<Pipeline> pipeline, const TriMesh& mesh,
                           const PipelineOptions& options) {
  Evaluation ev;
  ev.pipeline = std::move(pipeline);
  ev.pipeline->update_positions(mesh);
  solve_and_measure(ev, options);
  return ev;
}

}  // namespace

bool NodeOptimizer::Impl::step() {
  if (descent_over) return false;
  if (stop_requested()) {
    result.stopped = true;
    descent_over = true;
    return false;
  }
  if (!started) {
    started = true;
    if (no.polish.enabled && !movable.empty()) {
      const int rounds = result.hop_rounds;
      hop_round(true);
      if (result.hop_rounds > rounds) return true;
    }
  }
  const bool stalled = no.tuning.stall_gain > 0 && stalled_steps >= no.tuning.stall_steps;
  if (movable.empty() || result.steps >= step_budget || phase_halvings > kMaxHalvings || stalled) {
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
    if (no.descent.gradient == GradientMethod::Exact) {
      grad = exact_node_gradients(state.mesh, state.layout, options, vertices,
                                  ExactGradientOptions{}, observer);
      scale = kExactScale;
    } else {
      const Pipeline& p = *current.pipeline;
      grad = estimate_node_gradients(p.mesh(), p.geometry(), p.field()->theta,
                                     *p.parameterization(), options.param, vertices);
      scale = kEstimatorScale;
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
    if (len < kMinStepRelative * mean_edge) return std::nullopt;
    // The Voronoi safeguard: the trace stays in the node's Dijkstra-Voronoi cell.
    auto blocked = [&](int f) {
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
                                         relocation) &&
            move_node_and_reroute(trial.mesh, trial.layout, n, near, relocation, &reroute,
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
                                             forbidden, relocation);
      if (w < 0) continue;
      if (w != v) {
        if (!move_node_and_reroute(trial.mesh, trial.layout, n, w, relocation, &reroute,
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
  // ---- symmetric optimization (NodeOptOptions::Moves::symmetry; symmetric_step.h) ----
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
  auto try_evaluate = [&](const State& trial, const std::vector<char>& switched, Evaluation& next) {
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
    } catch (const InfeasibleLayoutError&) {
      return false;  // e.g. a layout the field cannot realize: treat like an increase
    } catch (const SolverError&) {
      return false;
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
  // retry without switches follows (tuning.switch_tabu).
  int n_switched = 0, n_repeated = 0;
  for (size_t i = 0; i < movable.size(); ++i) {
    n_switched += switched[i];
    n_repeated += switched[i] && first_target[i] == rejected_target[i];
  }
  const bool repeated =
      no.tuning.switch_tabu && n_switched > 0 && n_repeated >= kSwitchTabuOverlap * n_switched;
  counters.tabu_steps += repeated;
  // The retry without switches (below) does not depend on the re-layout's result: with
  // run.threads ≥ 3 it is solved on this thread while the re-layout is solved on another.
  State retry;
  std::vector<char> retry_switched;
  bool retry_built = false;
  Evaluation second;
  bool second_ok = false;
  bool ok = false;
  const bool retry_possible = n_switched > 0 && !repeated;
  if (retry_possible && parallel(3) && no.run.reuse_field && current.pipeline->field()) {
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
      } catch (const InfeasibleLayoutError&) {
        p.reset();
      } catch (const SolverError&) {
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
        } catch (const InfeasibleLayoutError&) {
          ok = false;  // e.g. a layout the field cannot realize: treat like an increase
        } catch (const SolverError&) {
          ok = false;
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
  if (!(ok && next.E <= current.E) && n_switched > 0) {
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
  if (!repeated && n_switched > 0 && !first_ok)
    for (size_t i = 0; i < movable.size(); ++i)
      if (first_target[i] >= 0 && on_curve(first_target[i])) damping[i] *= 0.5;
  r.accepted = ok && next.E <= current.E;
  r.E = ok ? next.E : current.E;
  r.foldovers = ok ? next.foldovers : current.foldovers;
  if (r.accepted) {
    for (size_t i = 0; i < movable.size(); ++i)
      if (trial.layout.nodes[movable[i]].vertex != state.layout.nodes[movable[i]].vertex)
        damping[i] = 1;
    const bool small_gain = current.E - next.E < no.tuning.stall_gain * current.E;
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

void NodeOptimizer::Impl::solve_current() {
  if (current_solved) return;
  check_cancel(observer);
  current.pipeline->update_positions(state.mesh);
  current.pipeline->compute_field();
  current.pipeline->compute_parameterization();
  ++counters.reused_solves;
  current_solved = true;
}

}  // namespace qs
