#include "core/nodeopt/optimizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

#include "core/nodeopt/geodesic.h"

namespace qs {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct Evaluation {
  std::unique_ptr<Pipeline> pipeline;
  double E = 0;
  int foldovers = 0;
};

Evaluation evaluate(const TriMesh& mesh, const Layout& layout, const PipelineOptions& options) {
  Evaluation ev;
  ev.pipeline = std::make_unique<Pipeline>(mesh, layout, options);
  ev.pipeline->compute_field();
  const Parameterization& r = ev.pipeline->compute_parameterization();
  ev.E = unweighted_energy(ev.pipeline->mesh(), ev.pipeline->geometry(),
                           ev.pipeline->field()->theta, r.corner_uv, options.param);
  ev.foldovers = r.foldovers;
  return ev;
}

struct State {
  TriMesh mesh;
  Layout layout;
  std::vector<SurfacePoint> anchor;  // per node, on the original mesh
};

std::vector<std::array<double, 3>> node_positions(const TriMesh& mesh, const Layout& layout) {
  std::vector<std::array<double, 3>> out;
  for (const auto& n : layout.nodes) {
    const Vec3 p = mesh.point(mesh.vertex_handle(n.vertex));
    out.push_back({p[0], p[1], p[2]});
  }
  return out;
}

}  // namespace

std::vector<int> movable_nodes(const TriMesh& mesh, const Layout& layout) {
  std::vector<char> feature(mesh.n_vertices(), 0);
  for (const auto& [a, b] : layout.feature_edges) feature[a] = feature[b] = 1;
  std::vector<int> out;
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n) {
    const LayoutNode& node = layout.nodes[n];
    if (node.pinned || feature[node.vertex] || mesh.is_boundary(mesh.vertex_handle(node.vertex)))
      continue;
    bool pinned_arc = false;
    for (const auto& arc : layout.arcs)
      pinned_arc |= arc.pinned && (arc.from == node.id || arc.to == node.id);
    if (!pinned_arc) out.push_back(n);
  }
  return out;
}

NodeOptResult optimize_nodes(const TriMesh& mesh, const Layout& layout,
                             const PipelineOptions& options, const NodeOptOptions& no,
                             Observer* observer) {
  const auto t_start = std::chrono::steady_clock::now();
  const TriMesh& original = mesh;
  NodeOptResult result;
  State state{mesh, layout, {}};
  for (const auto& n : layout.nodes) state.anchor.push_back(vertex_surface_point(mesh, n.vertex));
  const std::vector<int> movable = movable_nodes(mesh, layout);
  const double mean_edge = build_geometry(mesh).mean_edge_length;

  check_cancel(observer);
  Evaluation current = evaluate(state.mesh, state.layout, options);
  result.E_init = current.E;
  result.foldovers_init = current.foldovers;
  {
    StepReport r;
    r.step = 0;
    r.E = current.E;
    r.accepted = true;
    r.step_size = 0;
    r.foldovers = current.foldovers;
    r.time_s = seconds_since(t_start);
    r.phase = "initial";
    r.node_positions = node_positions(state.mesh, state.layout);
    result.reports.push_back(r);
    if (observer) observer->on_step(r);
  }

  double alpha = no.alpha;
  while (result.steps < no.max_steps && result.halvings <= no.max_halvings && !movable.empty()) {
    check_cancel(observer);
    const auto t_step = std::chrono::steady_clock::now();
    // Gradients at the current solution.
    std::vector<int> vertices;
    for (int n : movable) vertices.push_back(state.layout.nodes[n].vertex);
    std::vector<Vec3> grad;
    double scale;
    if (no.gradient == GradientMethod::Exact) {
      grad = exact_node_gradients(state.mesh, state.layout, options, vertices, no.exact, observer);
      scale = no.exact_scale;
    } else {
      const Pipeline& p = *current.pipeline;
      grad = estimate_node_gradients(p.mesh(), p.geometry(), p.field()->theta,
                                     p.parameterization()->corner_uv, options.param, vertices);
      scale = no.estimator_scale;
    }
    // Node-Voronoi cells on the original mesh, from all node vertices.
    std::vector<int> all_vertices;
    for (const auto& n : state.layout.nodes) all_vertices.push_back(n.vertex);
    const std::vector<int> cell = node_voronoi_cells(original, all_vertices);

    // Builds the trial state; nodes with no_switch[i] set may only move within faces of their
    // current vertex's original 1-ring.
    auto build_trial = [&](const std::vector<char>& no_switch, State& trial,
                           std::vector<char>& switched) {
      trial = state;
      switched.assign(movable.size(), 0);
      int moved = 0;
      for (size_t i = 0; i < movable.size(); ++i) {
        const int n = movable[i];
        const double len = alpha * scale * grad[i].norm();
        if (len < no.min_step_relative * mean_edge) continue;
        auto blocked = [&](int f) {
          if (!no.voronoi_safeguard) return false;
          for (auto vh : original.fv_range(original.face_handle(f)))
            if (cell[vh.idx()] == n || cell[vh.idx()] < 0) return false;
          return true;
        };
        const GeodesicTrace tr = trace_straightest_geodesic(
            original, trial.anchor[n], -grad[i] / grad[i].norm(), len, blocked);
        const int v = trial.layout.nodes[n].vertex;
        std::vector<char> forbidden = forbidden_relocation_vertices(trial.mesh, trial.layout, n);
        if (no_switch[i]) forbidden.assign(forbidden.size(), 1);
        const int w = choose_relocation_vertex(trial.mesh, original, tr.end, tr.end_position, v,
                                               forbidden, no.relocation);
        if (w < 0) continue;
        if (w != v) {
          if (!move_node_and_reroute(trial.mesh, trial.layout, n, w, no.relocation)) continue;
          trial.mesh.set_point(trial.mesh.vertex_handle(v),
                               original.point(original.vertex_handle(v)));
          switched[i] = 1;
        }
        trial.mesh.set_point(trial.mesh.vertex_handle(w), tr.end_position);
        trial.anchor[n] = tr.end;
        ++moved;
      }
      return moved;
    };
    auto try_evaluate = [&](const State& trial, Evaluation& next) {
      check_cancel(observer);
      try {
        next = evaluate(trial.mesh, trial.layout, options);
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
    ++result.steps;
    StepReport r;
    r.step = result.steps;
    r.step_size = alpha;
    r.moved_nodes = moved;
    r.phase = "descent";
    if (moved == 0) {  // converged: every node is at its optimum within the step resolution
      r.E = current.E;
      r.accepted = false;
      r.foldovers = current.foldovers;
      r.time_s = seconds_since(t_step);
      r.node_positions = node_positions(state.mesh, state.layout);
      result.reports.push_back(r);
      if (observer) observer->on_step(r);
      break;
    }
    Evaluation next;
    bool ok = try_evaluate(trial, next);
    // A node that changed its vertex can raise E discontinuously: retry once with those nodes
    // kept on their vertices before halving α.
    if (no.retry_without_switches && !(ok && next.E <= current.E) &&
        std::find(switched.begin(), switched.end(), 1) != switched.end()) {
      State retry;
      std::vector<char> unused;
      if (build_trial(switched, retry, unused) > 0) {
        Evaluation second;
        if (try_evaluate(retry, second) && second.E <= current.E) {
          trial = std::move(retry);
          next = std::move(second);
          ok = true;
        }
      }
    }
    r.accepted = ok && next.E <= current.E;
    r.E = ok ? next.E : current.E;
    r.foldovers = ok ? next.foldovers : current.foldovers;
    if (r.accepted) {
      state = std::move(trial);
      current = std::move(next);
      ++result.accepted;
    } else {
      alpha *= 0.5;
      ++result.halvings;
    }
    r.time_s = seconds_since(t_step);
    r.node_positions = node_positions(state.mesh, state.layout);
    result.reports.push_back(r);
    if (observer) observer->on_step(r);
  }
  result.E_descent = current.E;
  result.foldovers_descent = current.foldovers;
  result.E_final = current.E;
  result.foldovers_final = current.foldovers;

  if (no.stiffen_at_end && current.foldovers > 0) {
    const auto t_st = std::chrono::steady_clock::now();
    const StiffeningResult st = stiffen(state.mesh, state.layout, options, no.stiffening, observer);
    result.stiffening_iterations = st.iterations;
    if (st.foldovers_after < current.foldovers) {
      result.face_weights = st.face_weights;
      result.E_final = st.E_after;
      result.foldovers_final = st.foldovers_after;
    }
    StepReport r;
    r.step = result.steps + 1;
    r.E = result.E_final;
    r.accepted = !result.face_weights.empty();
    r.step_size = 0;
    r.foldovers = result.foldovers_final;
    r.time_s = seconds_since(t_st);
    r.phase = "stiffening";
    r.node_positions = node_positions(state.mesh, state.layout);
    result.reports.push_back(r);
    if (observer) observer->on_step(r);
  }
  result.mesh = std::move(state.mesh);
  result.layout = std::move(state.layout);
  result.time_s = seconds_since(t_start);
  return result;
}

}  // namespace qs
