// The end of the node optimization, NodeOptimizer::finish (docs/design.md, "Fold-over removal",
// "Orientation constraints", "Stiffening", "Untangling", "Result rule"): the
// orientation-constrained solve of the final state and of the earlier candidate states (the
// state before the polish, the one with the fewest fold-overs, the initial state), stiffening
// as their fallback, untangling as the last resort, then the result rule among the fold-free
// states kept during the descent. Also the bookkeeping of those candidate states at each
// accepted step. Part of NodeOptimizer::Impl (optimizer_impl.h).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <future>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/optimizer_impl.h"
#include "core/nodeopt/stiffening.h"

namespace qs {

using nodeopt_detail::emit_step;
using nodeopt_detail::evaluate_fresh;
using nodeopt_detail::State;

namespace {

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

}  // namespace

void NodeOptimizer::Impl::note_fold_free(bool initial) {
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

void NodeOptimizer::Impl::note_fold_count(const State& before, int after_folds) {
  if (after_folds <= fewest_folds_count) {  // the new state is the best (equal: lower E)
    fewest_folds.reset();
    fewest_folds_count = after_folds;
  } else if (!fewest_folds) {  // leaving the best state
    fewest_folds = std::make_unique<State>(before);
  }
}

NodeOptResult NodeOptimizer::Impl::finish(NodeOptStats* stats) {
  descent_over = true;
  finished = true;
  solve_current();
  // Stiffening (§7.1) of state \p st (its descent solve: \p descent) into \p out when it leaves
  // fewer fold-overs than out's result.
  auto stiffen_into = [&](const State& st, const std::shared_ptr<Pipeline>& descent,
                          NodeOptResult& out) {
    const auto t_st = std::chrono::steady_clock::now();
    const StiffeningResult sr =
        stiffen(st.mesh, st.layout, options, no.tuning.stiffening, observer);
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
  // The message of a failed untangling, appended to the fold-over removal's.
  auto untangling_message = [&](const std::exception& e) {
    return std::string(result.orientation.message.empty() ? "" : "; ") + "untangling: " + e.what();
  };
  const bool try_fewest = fewest_folds && fewest_folds_count < current.foldovers;
  const bool has_earlier = no.folds.orientation && (pre_polish || try_fewest);
  // One orientation-constrained solve of \p st (\p untangle: OrientationOptions::untangle;
  // \p fallback: as remove_foldovers'), polled by \p obs; its options, without the observer,
  // into \p used.
  auto oriented_solve = [&](const State& st, bool untangle, bool fallback, Observer* obs,
                            OrientationOptions& used) {
    PipelineOptions oriented = options;  // the caller's orientation options, enabled
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
    const bool at_this_state = no.tuning.orientation_at_moved_states ||
                               (initial_state && same_state(*initial_state, st_in));
    if (no.folds.orientation && ev.foldovers > 0 && at_this_state) {
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
      } catch (const InfeasibleLayoutError& e) {
        out.orientation.message = e.what();
      } catch (const SolverError& e) {
        out.orientation.message = e.what();
      }
      emit_orientation(st_in, out, out.orientation_constraints, t_or, out.reports, obs);
    }
    if (stiffen && no.folds.stiffen && out.foldovers_final > 0)
      stiffen_into(st_in, ev.pipeline, out);
  };
  // The fold-over removal at the state before the polish, solved speculatively
  // (run.threads ≥ 2). Declared after the lambda and the states it reads: its destructor
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
  // run.threads ≥ 2: the state before the polish is solved and oriented on a second thread
  // while this one orients the final state; its result (and its reports) are used exactly when
  // the sequential order would have tried it.
  if (no.folds.orientation && pre_polish && current.foldovers > 0 && parallel(2)) {
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
  if (!no.folds.orientation && !no.folds.stiffen) pre_polish.reset(), fewest_folds.reset();
  // The initial state last (NodeOptTuning::initial_fallback), unless it is one of the states
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
  if (try_fewest) try_earlier(fewest_folds, result.fewest_foldovers_reverted, false, !has_earlier);
  bool initial_taken = false;
  if (try_initial) try_earlier(initial_state, initial_taken, false, false);
  // The state returned is the initial one: taken as such, or as the earlier state that won
  // (the fewest-fold-over state when both earlier states were taken in turn).
  if (initial_taken) result.polish_reverted = result.fewest_foldovers_reverted = false;
  result.initial_reverted =
      initial_taken ||
      (result.fewest_foldovers_reverted ? fewest_is_initial
                                        : result.polish_reverted && pre_polish_is_initial);
  if (has_earlier && no.folds.stiffen && result.foldovers_final > 0)
    stiffen_into(state, result.descent_pipeline, result);
  // The last resort: the untangling (untangle.h) at the state returned, when the tri-sector
  // constraints left fold-overs at every state tried and stiffening did too. Not inside those
  // attempts: an untangled map has no fold-over but keeps the parametric cones of its state,
  // and the constraints' failure at a state often marks wrong cones that an earlier state does
  // not have (the rocker-arm cage layout: untangled at its final state, 0 fold-overs and 7 bad
  // cones; its fewest-fold-over state embeds structurally equivalent).
  if (no.folds.orientation && options.param.orientation.untangle && result.foldovers_final > 0) {
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
    } catch (const InfeasibleLayoutError& e) {
      result.orientation.message += untangling_message(e);
    } catch (const SolverError& e) {
      result.orientation.message += untangling_message(e);
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

}  // namespace qs
