// The hop polish of the node optimization (docs/design.md, "Hop polish"): hop sweeps that move
// nodes between vertices where the continuous descent cannot (all relocations undone at once,
// cone restores and hops, relocated nodes onto the neighbour they lean to, sliding nodes to the
// curve neighbour they lean to), each kept only when it lowers E, and the new descent phase
// after a sweep that moved nodes. Part of NodeOptimizer::Impl (optimizer_impl.h).
#include <algorithm>
#include <chrono>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/geodesic.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/optimizer_impl.h"
#include "core/nodeopt/relocation.h"

namespace qs {

using nodeopt_detail::emit_step;
using nodeopt_detail::Evaluation;
using nodeopt_detail::kHopConeMaxEvaluations;
using nodeopt_detail::kHopConeTolerance;
using nodeopt_detail::pipeline_matches;
using nodeopt_detail::solve_and_measure;

namespace {

// Runs \p solve (which returns an Evaluation) and gives its E and fold-overs; false when it
// throws InfeasibleLayoutError (a layout the field cannot realize, …) or SolverError. Other
// errors (Cancelled among them) pass through.
template <typename Solve>
bool measured(Solve&& solve, double& E, int& foldovers) {
  try {
    const Evaluation ev = solve();
    E = ev.E;
    foldovers = ev.foldovers;
    return true;
  } catch (const InfeasibleLayoutError&) {
    return false;
  } catch (const SolverError&) {
    return false;
  }
}

}  // namespace

bool NodeOptimizer::Impl::hop_round(bool cones_only) {
  const auto t_hop = std::chrono::steady_clock::now();
  check_cancel(observer);
  // The solved candidate with the lowest E so far (a job may run on the second thread): the
  // sweep's final state is usually one of them, and then needs no second solve at the end.
  std::mutex best_mutex;
  Evaluation best;
  auto keep_if_best = [&](Evaluation ev) {
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
  // Two at a time (run.threads ≥ 2): each job's Pipeline is built here and owns its
  // factorizations before any thread solves it.
  const HopJobMaker make_job = [&](const TriMesh& m, const Layout& l) -> HopJob {
    ++counters.parallel_hop_jobs;
    std::shared_ptr<Pipeline> p;
    try {
      p = switched_pipeline(m, l, true);
    } catch (const InfeasibleLayoutError&) {
      return [](double&, int&) { return false; };
    } catch (const SolverError&) {
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
  const HopJobMaker* jobs = parallel(2) ? &make_job : nullptr;
  State hopped = state;
  HopSweepResult h;
  h.E = current.E;
  h.foldovers = current.foldovers;
  // One hop_sweep of hopped, its result accumulated into h (evaluations too when the sweep
  // draws on the neighbour hops' budget).
  auto run_sweep = [&](const std::vector<int>& nodes, const std::vector<Vec3>& directions,
                       HopSweepOptions sweep, bool counts_evaluations) {
    sweep.relocation = relocation;
    sweep.keep_nodes_apart = no.moves.keep_nodes_apart;
    sweep.stop = no.run.stop;
    if (nodes.empty() || sweep.max_evaluations <= 0) return;
    const HopSweepResult s = hop_sweep(original, hopped.mesh, hopped.layout, nodes, directions, h.E,
                                       h.foldovers, sweep, evaluate, observer, &reroute, jobs);
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
    sweep.max_evaluations = no.tuning.hop_max_evaluations - h.evaluations;
    run_sweep(nodes, directions, sweep, true);
  };
  // Sharp cone vertices (discrete.h cone_candidates; none on smooth meshes).
  ConeCandidates cones;
  auto find_cones = [&]() {
    if (!no.tuning.hop_cones) return;
    if (deficits.empty()) deficits = vertex_angle_deficits(original_geometry);
    std::vector<int> cone_nodes;  // all but the nodes on the boundary
    for (int n : movable)
      if (!original.is_boundary(original.vertex_handle(hopped.layout.nodes[n].vertex)))
        cone_nodes.push_back(n);
    cones = cone_candidates(original, hopped.mesh, hopped.layout, cone_nodes,
                            current.pipeline->topology().valence, deficits, kHopConeTolerance,
                            no.tuning.hop_cone_rings, no.tuning.hop_cone_targets);
  };
  find_cones();
  if (cones_only && cones.hop_nodes.empty() && cones.snap_nodes.empty()) return false;
  ++result.hop_rounds;
  // All at once first, one solve (single moves miss collective optima: one node on its cone
  // or vertex while its neighbours are not can raise E): every relocation undone and every
  // node off its cone onto its nearest fitting vertex.
  if (no.tuning.hop_collective && !stop_requested()) {
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
          forbidden_relocation_vertices(original, all.layout, n, no.moves.keep_nodes_apart);
      for (int w : cones.hop_targets[i])
        if (!forbidden[w] &&
            move_node_and_reroute(all.mesh, all.layout, n, w, relocation, &reroute)) {
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
    sweep.max_evaluations = kHopConeMaxEvaluations;
    sweep.max_failures = no.tuning.hop_cone_max_failures;
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
    sweep.max_candidates = no.tuning.hop_candidates;
    sweep.min_direction_cos = no.tuning.hop_min_cos;
    sweep.max_failures = no.tuning.hop_max_failures;
    sweep_nodes(no.tuning.hop_min_offset, sweep);
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
    along.max_failures = no.tuning.hop_max_failures;
    std::vector<int> nodes;
    for (const auto& [t, n] : leaning) {
      nodes.push_back(n);
      along.targets.push_back({hopped.curve[n].toward});
    }
    along.max_evaluations = no.tuning.hop_max_evaluations - h.evaluations;
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
    if (best.pipeline && best.E == h.E &&
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

bool NodeOptimizer::Impl::polish() {
  if (!no.polish.enabled || polish_rounds >= no.tuning.max_hop_rounds) return false;
  ++polish_rounds;
  if (!hop_round(false)) return false;
  const double growth = no.tuning.hop_alpha_growth;
  alpha = growth > 0 && accepted_alpha > 0 ? std::min(no.descent.alpha, growth * accepted_alpha)
                                           : no.descent.alpha;
  accepted_alpha = 0;
  phase_halvings = 0;
  stalled_steps = 0;
  std::fill(rejected_target.begin(), rejected_target.end(), -1);
  std::fill(damping.begin(), damping.end(), 1.0);
  step_budget = std::max(step_budget, result.steps + no.tuning.hop_descent_steps);
  return true;
}

}  // namespace qs
