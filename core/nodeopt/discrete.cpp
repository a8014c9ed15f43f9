#include "core/nodeopt/discrete.h"

#include <chrono>

#include "core/nodeopt/gradient.h"

namespace qs {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Value {
  double E = 0;
  int foldovers = 0;
};

Value solve(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options) {
  Pipeline p(mesh, layout, options);
  p.compute_field();
  const Parameterization& r = p.compute_parameterization();
  return {unweighted_energy(p.mesh(), p.geometry(), p.field()->theta, r.corner_uv, options.param),
          r.foldovers};
}

}  // namespace

NodeOptResult relocate_nodes_discrete(const TriMesh& mesh, const Layout& layout,
                                      const PipelineOptions& options, const DiscreteOptions& d,
                                      Observer* observer) {
  const auto t_start = std::chrono::steady_clock::now();
  NodeOptResult result;
  result.mesh = mesh;
  result.layout = layout;
  check_cancel(observer);
  Value current = solve(mesh, layout, options);
  result.E_init = current.E;
  result.foldovers_init = current.foldovers;
  const std::vector<int> movable = movable_nodes(mesh, layout);
  int evaluations = 0;
  for (int step = 1; step <= d.max_steps && evaluations < d.max_evaluations; ++step) {
    const auto t_step = std::chrono::steady_clock::now();
    int moved = 0;
    for (int n : movable) {
      const int v = result.layout.nodes[n].vertex;
      const auto forbidden = forbidden_relocation_vertices(mesh, result.layout, n);
      Layout best_layout;
      Value best = current;
      bool found = false;
      for (auto wh : mesh.vv_range(mesh.vertex_handle(v))) {
        if (forbidden[wh.idx()] || evaluations >= d.max_evaluations) continue;
        check_cancel(observer);
        Layout trial = result.layout;
        if (!move_node_and_reroute(mesh, trial, n, wh.idx(), d.relocation)) continue;
        ++evaluations;
        Value val;
        try {
          val = solve(mesh, trial, options);
        } catch (const Cancelled&) {
          throw;
        } catch (const QsError&) {
          continue;
        }
        if (val.E < best.E) {
          best = val;
          best_layout = std::move(trial);
          found = true;
        }
      }
      if (found) {
        result.layout = std::move(best_layout);
        current = best;
        ++moved;
      }
    }
    ++result.steps;
    StepReport r;
    r.step = step;
    r.E = current.E;
    r.accepted = moved > 0;
    r.step_size = 1;
    r.foldovers = current.foldovers;
    r.moved_nodes = moved;
    r.time_s = seconds_since(t_step);
    r.phase = "discrete";
    for (const auto& node : result.layout.nodes) {
      const Vec3 p = mesh.point(mesh.vertex_handle(node.vertex));
      r.node_positions.push_back({p[0], p[1], p[2]});
    }
    result.reports.push_back(r);
    if (observer) observer->on_step(r);
    if (moved == 0) break;
    ++result.accepted;
  }
  result.E_descent = result.E_final = current.E;
  result.foldovers_descent = result.foldovers_final = current.foldovers;
  result.time_s = seconds_since(t_start);
  return result;
}

}  // namespace qs
