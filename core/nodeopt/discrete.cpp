#include "core/nodeopt/discrete.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <thread>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/nodeopt/gradient.h"

namespace qs {

namespace {

// Free neighbours of node n's vertex, in the order they are tried.
std::vector<int> hop_candidates(const TriMesh& original, const Layout& layout, int n,
                                const Vec3* direction, const HopSweepOptions& o) {
  const int v = layout.nodes[n].vertex;
  const std::vector<char> forbidden =
      forbidden_relocation_vertices(original, layout, n, o.keep_nodes_apart);
  const auto vh = original.vertex_handle(v);
  std::vector<std::pair<double, int>> ranked;  // (−cos, vertex), or (0, vertex) in ring order
  for (auto wh : original.vv_range(vh)) {
    if (forbidden[wh.idx()]) continue;
    double key = 0;
    if (direction) {
      const Vec3 e = original.point(wh) - original.point(vh);
      const double cos = (e | *direction) / (e.norm() * direction->norm());
      if (cos < o.min_direction_cos) continue;
      key = -cos;
    }
    ranked.push_back({key, wh.idx()});
  }
  std::stable_sort(ranked.begin(), ranked.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<int> out;
  for (const auto& [key, w] : ranked) {
    if (o.max_candidates > 0 && static_cast<int>(out.size()) >= o.max_candidates) break;
    out.push_back(w);
  }
  return out;
}

}  // namespace

std::vector<double> vertex_angle_deficits(const GeometryCache& geometry) {
  std::vector<double> out = geometry.angle_defect;
  for (int v = 0; v < geometry.n_vertices; ++v)
    if (geometry.vertex_on_boundary[v]) out[v] = 0.0;
  return out;
}

ConeCandidates cone_candidates(const TriMesh& original, const TriMesh& mesh, const Layout& layout,
                               const std::vector<int>& nodes, const std::vector<int>& valence,
                               const std::vector<double>& deficits, double tolerance, int rings,
                               int max_targets) {
  ConeCandidates out;
  const double tol = tolerance * M_PI / 2;
  std::vector<int> seen(original.n_vertices(), -1);
  for (int n : nodes) {
    const double index = (4 - valence[n]) / 4.0;
    if (index == 0) continue;
    const double want = 2 * M_PI * index;
    auto fits = [&](int w) { return std::abs(deficits[w] - want) <= tol; };
    const int v = layout.nodes[n].vertex;
    const auto vh = mesh.vertex_handle(v);
    if (fits(v)) {
      if (mesh.point(vh) != original.point(vh)) out.snap_nodes.push_back(n);
      continue;
    }
    // Breadth-first rings around v (original connectivity); fitting vertices by ring, then by
    // how well they fit.
    std::vector<std::pair<std::pair<int, double>, int>> found;  // ((ring, misfit), vertex)
    std::vector<int> frontier{v};
    seen[v] = n;
    for (int ring = 1; ring <= rings && !frontier.empty(); ++ring) {
      std::vector<int> next;
      for (int u : frontier)
        for (auto wh : original.vv_range(original.vertex_handle(u))) {
          const int w = wh.idx();
          if (seen[w] == n) continue;
          seen[w] = n;
          next.push_back(w);
          if (fits(w)) found.push_back({{ring, std::abs(deficits[w] - want)}, w});
        }
      frontier = std::move(next);
    }
    if (found.empty()) continue;
    std::sort(found.begin(), found.end());
    std::vector<int> targets;
    for (const auto& f : found) {
      if (static_cast<int>(targets.size()) >= max_targets) break;
      targets.push_back(f.second);
    }
    out.hop_nodes.push_back(n);
    out.hop_targets.push_back(std::move(targets));
  }
  return out;
}

HopSweepResult hop_sweep(const TriMesh& original, TriMesh& mesh, Layout& layout,
                         const std::vector<int>& nodes, const std::vector<Vec3>& directions,
                         double E, int foldovers, const HopSweepOptions& o,
                         const HopEvaluator& evaluate, Observer* observer,
                         const RerouteContext* context, const HopJobMaker* jobs) {
  HopSweepResult result;
  result.E = E;
  result.foldovers = foldovers;
  const bool parallel = jobs && *jobs;
  int failures = 0;  // candidate solves since the last lower E
  struct Candidate {
    Layout layout;         // node n on its candidate vertex (the trial's routing)
    bool restore = false;  // n stays on v with v at its original position
    bool solved = false, ok = false;
    double E = 0;
    int foldovers = 0;
  };
  // Solves node n's candidates (its vertex v back at \p restored in each) in their order and
  // keeps the best one below the current E.
  auto solve_candidates = [&](std::vector<Candidate>& list, int v, const Vec3& restored) {
    TriMesh moved = mesh;
    moved.set_point(moved.vertex_handle(v), restored);
    // Solves candidate k (and k + 1 on a second thread, in parallel mode).
    auto solve = [&](size_t k) {
      check_cancel(observer);
      Candidate& a = list[k];
      if (parallel && k + 1 < list.size()) {
        const HopJob first = (*jobs)(moved, a.layout);
        const HopJob second = (*jobs)(moved, list[k + 1].layout);
        Candidate& b = list[k + 1];
        auto other =
            std::async(std::launch::async, [&second, &b]() { b.ok = second(b.E, b.foldovers); });
        a.ok = first(a.E, a.foldovers);  // on throw, the future's destructor waits for b
        other.get();
        b.solved = true;
      } else {
        a.ok = evaluate(moved, a.layout, a.E, a.foldovers);
      }
      a.solved = true;
    };
    int best = -1;
    double best_E = result.E;
    for (size_t k = 0; k < list.size(); ++k) {
      if (!list[k].solved) {
        if (o.stop && o.stop()) {
          result.stopped = true;
          break;
        }
        solve(k);
      }
      ++result.evaluations;
      if (list[k].ok && list[k].E < best_E) {
        best_E = list[k].E;
        best = static_cast<int>(k);
        failures = 0;
      } else {
        ++failures;  // a failed solve counts as one without a lower E
      }
      if (!list[k].restore && o.max_failures > 0 && failures >= o.max_failures) break;
    }
    if (best >= 0) {
      layout = std::move(list[best].layout);
      mesh.set_point(mesh.vertex_handle(v), restored);
      result.E = best_E;
      result.foldovers = list[best].foldovers;
      ++result.moved;
      if (o.on_move) o.on_move(best_E);
    }
  };
  for (size_t i = 0; i < nodes.size(); ++i) {
    const int n = nodes[i];
    const Vec3* direction = directions.empty() ? nullptr : &directions[i];
    if (direction && direction->norm() <= 0) direction = nullptr;
    const int v = layout.nodes[n].vertex;
    const Vec3 restored = original.point(original.vertex_handle(v));
    // The node's candidates in the order they are tried, at most the evaluations left. The
    // moved mesh is the same for all of them: v back at its original position.
    std::vector<Candidate> list;
    const int budget = o.max_evaluations - result.evaluations;
    if (o.try_restore && mesh.point(mesh.vertex_handle(v)) != restored && budget > 0 &&
        relocation_keeps_orientation(mesh, original, -1, v, restored, o.relocation)) {
      Candidate c;
      c.layout = layout;
      c.restore = true;
      list.push_back(std::move(c));
    }
    std::vector<int> vertices;
    // Curve neighbours of v (o.curves): steps along the curve.
    const std::vector<int> no_curve;
    const std::vector<int>& along = o.curves ? o.curves->neighbours[v] : no_curve;
    auto on_curve_step = [&](int w) {
      return std::find(along.begin(), along.end(), w) != along.end();
    };
    if (!o.targets.empty()) {
      // A step along the curve may take a forbidden (curve) vertex, never one next to a node.
      const std::vector<char> forbidden = forbidden_relocation_vertices(original, layout, n);
      const std::vector<char> near =
          o.keep_nodes_apart ? next_to_other_nodes(original, layout, n) : std::vector<char>{};
      for (int w : o.targets[i]) {
        if (w != v && (!forbidden[w] || on_curve_step(w)) && (near.empty() || !near[w]))
          vertices.push_back(w);
      }
    } else if (o.try_neighbours) {
      vertices = hop_candidates(original, layout, n, direction, o);
    }
    for (int w : vertices) {
      if (static_cast<int>(list.size()) >= budget) break;
      const Vec3 at = mesh.point(mesh.vertex_handle(w));
      if (!relocation_keeps_orientation(mesh, original, v, w, at, o.relocation)) continue;
      Candidate c;
      c.layout = layout;
      CurveWalk walk;
      if (on_curve_step(w)) walk = make_curve_walk(*o.curves, {v, w});
      if (!move_node_and_reroute(mesh, c.layout, n, w, o.relocation, context, nullptr,
                                 walk.vertices.empty() ? nullptr : &walk))
        continue;
      list.push_back(std::move(c));
    }
    if (!list.empty()) solve_candidates(list, v, restored);
    if (result.stopped || result.evaluations >= o.max_evaluations) break;
    if (o.max_failures > 0 && failures >= o.max_failures) break;
  }
  return result;
}

NodeOptResult relocate_nodes_discrete(const TriMesh& mesh, const Layout& layout,
                                      const PipelineOptions& options, const DiscreteOptions& d,
                                      Observer* observer) {
  const auto t_start = std::chrono::steady_clock::now();
  NodeOptResult result;
  result.mesh = mesh;
  result.layout = layout;
  const HopEvaluator evaluate = [&](const TriMesh& m, const Layout& l, double& E, int& folds) {
    try {
      Pipeline p(m, l, options);
      p.compute_field();
      const Parameterization& r = p.compute_parameterization();
      E = unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, r, options.param);
      folds = r.foldovers;
      return true;
    } catch (const InfeasibleLayoutError&) {  // a candidate that cannot be realized
      return false;
    } catch (const SolverError&) {
      return false;
    }
  };
  check_cancel(observer);
  double E = 0;
  int foldovers = 0;
  {  // The initial solve must succeed: its errors are the caller's.
    Pipeline p(mesh, layout, options);
    p.compute_field();
    const Parameterization& r = p.compute_parameterization();
    E = unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, r, options.param);
    foldovers = r.foldovers;
  }
  result.E_init = E;
  result.foldovers_init = foldovers;
  const std::vector<int> movable = movable_nodes(mesh, layout);
  // Every candidate gets a fresh Pipeline: a job only needs its own copies of the input.
  const HopJobMaker make_job = [&](const TriMesh& m, const Layout& l) -> HopJob {
    return [&, m, l](double& E, int& folds) { return evaluate(m, l, E, folds); };
  };
  const HopJobMaker* jobs =
      d.parallel && std::thread::hardware_concurrency() >= 2 ? &make_job : nullptr;
  HopSweepOptions sweep;
  sweep.relocation = d.relocation;
  sweep.stop = d.stop;
  sweep.on_move = d.on_move;
  int evaluations = 0;
  for (int step = 1; step <= d.max_steps && evaluations < d.max_evaluations; ++step) {
    const auto t_step = std::chrono::steady_clock::now();
    sweep.max_evaluations = d.max_evaluations - evaluations;
    const HopSweepResult s = hop_sweep(mesh, result.mesh, result.layout, movable, {}, E, foldovers,
                                       sweep, evaluate, observer, nullptr, jobs);
    evaluations += s.evaluations;
    E = s.E;
    foldovers = s.foldovers;
    ++result.steps;
    StepReport r;
    r.step = step;
    r.E = E;
    r.accepted = s.moved > 0;
    r.step_size = 1;
    r.foldovers = foldovers;
    r.moved_nodes = s.moved;
    r.time_s = seconds_since(t_step);
    r.phase = "discrete";
    for (const auto& node : result.layout.nodes) {
      const Vec3 p = mesh.point(mesh.vertex_handle(node.vertex));
      r.node_positions.push_back({p[0], p[1], p[2]});
    }
    result.reports.push_back(r);
    if (observer) observer->on_step(r);
    if (s.moved > 0) ++result.accepted;
    result.stopped = s.stopped;
    if (s.moved == 0 || s.stopped) break;
  }
  result.E_descent = result.E_final = E;
  result.foldovers_descent = result.foldovers_final = foldovers;
  result.time_s = seconds_since(t_start);
  return result;
}

}  // namespace qs
