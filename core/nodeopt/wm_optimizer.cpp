#include "core/nodeopt/wm_optimizer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/nodeopt/geodesic.h"
#include "core/nodeopt/relocation.h"

namespace qs {

namespace {

using VH = OpenMesh::VertexHandle;

// A solved state.
struct Solved {
  std::shared_ptr<Pipeline> pipeline;
  double E = 0;
  int foldovers = 0;
};

void measure(Solved& s, const PipelineOptions& options) {
  s.pipeline->compute_field();
  const Parameterization& p = s.pipeline->compute_parameterization();
  s.E = unweighted_energy(s.pipeline->mesh(), s.pipeline->geometry(), s.pipeline->field()->theta, p,
                          options.param);
  s.foldovers = p.foldovers;
}

Solved solve_fresh(const MeshLayout& st, const PipelineOptions& options) {
  Solved s;
  s.pipeline = std::make_shared<Pipeline>(st.mesh.mesh(), st.layout, options, false);
  measure(s, options);
  return s;
}

std::vector<std::array<double, 3>> positions(const MeshLayout& st) {
  std::vector<std::array<double, 3>> out;
  for (const auto& n : st.layout.nodes) {
    const Vec3 p = st.mesh.mesh().point(VH(n.vertex));
    out.push_back({p[0], p[1], p[2]});
  }
  return out;
}

}  // namespace

void validate_wm_options(const WmOptions& o) {
  auto fail = [](const std::string& what) {
    throw InvalidInputError("node optimization: " + what);
  };
  if (o.max_steps < 0) fail("max_steps must be >= 0");
  if (!(std::isfinite(o.alpha) && o.alpha > 0 && o.alpha <= 10)) fail("alpha must be in (0, 10]");
  if (o.max_halvings < 0) fail("max_halvings must be >= 0");
}

struct WmOptimizer::Impl {
  PipelineOptions options;
  const WmOptions no;
  const std::chrono::steady_clock::time_point t_start = std::chrono::steady_clock::now();
  Observer* observer = nullptr;
  MeshLayout state;
  Solved current;
  const MeshLayout initial;
  double mean_edge = 1;
  int patches = 0;
  double alpha;
  int phase_halvings = 0;
  std::vector<char> pinned;
  std::vector<Vec3> grad;
  std::vector<int> cell;  // per working vertex of the state: the node whose cell holds it
  bool state_changed = true;
  bool over = false;
  // The most recent accepted fold-free state (E never rises over accepted steps, so it has the
  // lowest E of the fold-free states visited).
  std::unique_ptr<MeshLayout> last_fold_free;
  WmResult result;

  Impl(MeshLayout start, const PipelineOptions& opts, const WmOptions& node_options, Observer* obs)
      : options(opts),
        no(node_options),
        observer(obs),
        state(std::move(start)),
        initial(state),
        alpha(node_options.alpha) {
    validate_wm_options(no);
    const TriMesh& in = state.mesh.input();
    double sum = 0;
    for (auto e : in.edges()) sum += in.calc_edge_length(e);
    mean_edge = in.n_edges() > 0 ? sum / in.n_edges() : 1.0;
    patches = count_patches(state.mesh.mesh(), state.layout);
    pinned.assign(state.layout.nodes.size(), 0);
    for (size_t n = 0; n < state.layout.nodes.size(); ++n) pinned[n] = state.layout.nodes[n].pinned;
    check_cancel(observer);
    current = solve_fresh(state, options);
    result.E_init = current.E;
    result.foldovers_init = current.foldovers;
    note_accepted();
    StepReport r;
    r.E = current.E;
    r.accepted = true;
    r.foldovers = current.foldovers;
    r.phase = "initial";
    r.time_s = seconds_since(t_start);
    emit(r, state);
  }

  void emit(StepReport r, const MeshLayout& st) {
    r.node_positions = positions(st);
    result.reports.push_back(std::move(r));
    if (observer) observer->on_step(result.reports.back());
  }

  void note_accepted() {
    if (current.foldovers > 0) return;
    last_fold_free = std::make_unique<MeshLayout>(state);
  }

  // Nodes that move: not pinned, not an end of a pinned arc, not on the boundary or a feature.
  std::vector<int> movable() const {
    const TriMesh& m = state.mesh.mesh();
    std::vector<char> held = pinned;
    for (const auto& arc : state.layout.arcs) {
      if (!arc.pinned) continue;
      for (int id : {arc.from, arc.to}) {
        const int n = id >= 0 ? state.layout.node_index(id) : -1;
        if (n >= 0) held[n] = 1;
      }
    }
    std::vector<char> feature(m.n_vertices(), 0);
    for (const auto& [a, b] : state.layout.feature_edges) feature[a] = feature[b] = 1;
    std::vector<int> out;
    for (int n = 0; n < static_cast<int>(state.layout.nodes.size()); ++n) {
      const int v = state.layout.nodes[n].vertex;
      if (!held[n] && !m.is_boundary(VH(v)) && !feature[v]) out.push_back(n);
    }
    return out;
  }

  bool step() {
    if (over) return false;
    if (no.stop && no.stop()) {
      result.stopped = true;
      over = true;
      return false;
    }
    const std::vector<int> nodes = movable();
    if (nodes.empty() || result.steps >= no.max_steps || phase_halvings > no.max_halvings) {
      over = true;
      return false;
    }
    check_cancel(observer);
    const auto t_step = std::chrono::steady_clock::now();
    const Pipeline& p = *current.pipeline;
    if (state_changed) {
      std::vector<int> vertices, all;
      for (int n : nodes) vertices.push_back(state.layout.nodes[n].vertex);
      for (const auto& node : state.layout.nodes) all.push_back(node.vertex);
      // Each node's step stays inside its Dijkstra-Voronoi cell among all nodes (paper §7.2):
      // a node never jumps past another node or into a patch it does not touch.
      cell = node_voronoi_cells(state.mesh.mesh(), all);
      grad = no.gradient == GradientKind::kExact
                 ? exact_node_gradients(state.mesh.mesh(), state.layout, options, vertices,
                                        no.exact, observer)
                 : estimate_node_gradients(p.mesh(), p.geometry(), p.field()->theta,
                                           *p.parameterization(), options.param, vertices);
      state_changed = false;
    }
    const double scale = no.gradient == GradientKind::kExact ? 1.0 : 2.0 / 3.0;
    MeshLayout trial = state;
    LayoutOccupancy occ(trial.mesh);
    fill_occupancy(trial, occ);
    const NodeArcs arcs = node_arcs(trial.layout);
    std::vector<int> freed;
    int moved = 0;
    bool relaid = false, broken = false;
    const int faces_before = static_cast<int>(trial.mesh.mesh().n_faces());
    for (size_t i = 0; i < nodes.size(); ++i) {
      const double g = grad[i].norm();
      double len = alpha * scale * g;
      if (!(len >= 1e-4 * mean_edge)) continue;
      const int n = nodes[i];
      // Traced on the state's working mesh (the same surface as the input), inside the cell.
      const TriMesh& sm = state.mesh.mesh();
      const auto outside = [&](int f) {
        for (auto v : sm.fv_range(sm.face_handle(f)))
          if (cell[v.idx()] == n) return false;
        return true;
      };
      const GeodesicTrace tr = trace_straightest_geodesic(
          sm, vertex_surface_point(sm, state.layout.nodes[n].vertex), -grad[i] / g, len, outside);
      // A trace stopped by the cell ends on an edge: the node goes just inside the last face
      // (a node on an input edge could only slide along it afterwards).
      std::array<double, 3> bary = tr.end.bary;
      if (tr.truncated || bary[0] == 0 || bary[1] == 0 || bary[2] == 0)
        for (double& b : bary) b = 0.98 * b + 0.02 / 3;
      const SurfacePoint target = state.mesh.input_point(tr.end.face, bary);
      const NodeMove kind = move_node(trial, occ, arcs, n, target, freed);
      if (kind == NodeMove::kBroken) {
        broken = true;
        break;
      }
      moved += kind != NodeMove::kRefused;
      relaid = relaid || kind == NodeMove::kRelaid;
    }
    relaid = relaid || static_cast<int>(trial.mesh.mesh().n_faces()) != faces_before;
    ++result.steps;
    StepReport r;
    r.step = result.steps;
    r.step_size = alpha;
    r.moved_nodes = moved;
    r.phase = "descent";
    if (moved == 0) {  // converged at the step resolution
      r.E = current.E;
      r.foldovers = current.foldovers;
      r.time_s = seconds_since(t_step);
      emit(r, state);
      over = true;
      return false;
    }
    Solved next;
    bool ok = !broken;
    try {
      if (broken) {
        // a node could not be moved without breaking the layout: the step is refused
      } else if (relaid) {
        // Free refinement vertices around the moved nodes go too (separation puts back the
        // ones the arcs need): the mesh does not keep refining where nodes pass.
        {
          const TriMesh& tm = trial.mesh.mesh();
          for (int n : nodes) {
            const int v = trial.layout.nodes[n].vertex;
            for (auto x : tm.vv_range(tm.vertex_handle(v))) {
              freed.push_back(x.idx());
              for (auto y : tm.vv_range(x)) freed.push_back(y.idx());
            }
          }
        }
        tidy_mesh_layout(trial, freed);
        ok = count_patches(trial.mesh.mesh(), trial.layout) == patches;
        if (ok) next = solve_fresh(trial, options);
      } else {
        next.pipeline = current.pipeline;
        next.pipeline->update_positions(trial.mesh.mesh());
        measure(next, options);
      }
    } catch (const Cancelled&) {
      throw;
    } catch (const InvalidInputError&) {
      ok = false;  // a layout the field cannot realize: like an increase
    } catch (const SolverError&) {
      ok = false;
    }
    r.accepted = ok && next.E <= current.E;
    r.E = ok ? next.E : current.E;
    r.foldovers = ok ? next.foldovers : current.foldovers;
    if (r.accepted) {
      state = std::move(trial);
      current = std::move(next);
      state_changed = true;
      ++result.accepted;
      phase_halvings = 0;
      note_accepted();
    } else {
      alpha *= 0.5;
      ++result.halvings;
      ++phase_halvings;
      if (!relaid && !broken) {  // the current Pipeline holds the trial's positions: solve again
        current.pipeline->update_positions(state.mesh.mesh());
        measure(current, options);
      }
    }
    r.time_s = seconds_since(t_step);
    emit(r, state);
    return true;
  }

  // Solves \p st with the orientation constraints; the pipeline, or null when it throws.
  std::shared_ptr<Pipeline> oriented(const MeshLayout& st, OrientationOptions& used) {
    PipelineOptions o = options;
    o.param.orientation = no.orientation_options;
    o.param.orientation.enabled = true;
    o.param.orientation.observer = observer;
    auto p = std::make_shared<Pipeline>(st.mesh.mesh(), st.layout, o, false);
    p->compute_field();
    p->compute_parameterization();
    used = o.param.orientation;
    used.observer = nullptr;
    return p;
  }

  WmResult finish() {
    over = true;
    result.E_descent = current.E;
    result.foldovers_descent = current.foldovers;
    struct Option {
      WmCandidate c;
      const MeshLayout* state;
      std::shared_ptr<Pipeline> pipeline;
      bool oriented = false;
      OrientationOptions used;
    };
    std::vector<Option> options_seen;
    auto consider = [&](const std::string& name, const MeshLayout& st, const Solved& s,
                        bool is_oriented, const OrientationOptions& used) {
      Option o;
      o.c.name = name;
      o.c.E = s.E;
      o.c.foldovers = s.foldovers;
      o.c.structurally_equivalent = s.pipeline->extract().structurally_equivalent;
      o.state = &st;
      o.pipeline = s.pipeline;
      o.oriented = is_oriented;
      o.used = used;
      result.candidates.push_back(o.c);
      options_seen.push_back(std::move(o));
    };
    auto good = [&] {
      for (const Option& o : options_seen)
        if (o.c.foldovers == 0 && o.c.structurally_equivalent) return true;
      return false;
    };
    // Orients \p st when it folds (a candidate of its own).
    auto orient = [&](const std::string& name, const MeshLayout& st) {
      if (!no.orientation) return;
      const auto t = std::chrono::steady_clock::now();
      check_cancel(observer);
      Solved s;
      OrientationOptions used;
      try {
        s.pipeline = oriented(st, used);
      } catch (const InfeasibleLayoutError& e) {
        result.orientation.message = e.what();
        return;
      } catch (const SolverError& e) {
        result.orientation.message = e.what();
        return;
      }
      const Parameterization& par = *s.pipeline->parameterization();
      result.orientation = par.orientation;
      s.E = unweighted_energy(s.pipeline->mesh(), s.pipeline->geometry(),
                              s.pipeline->field()->theta, par, options.param);
      s.foldovers = par.foldovers;
      consider(name, st, s, true, used);
      StepReport r;
      r.step = result.steps + 1;
      r.E = s.E;
      r.accepted = par.orientation.success;
      r.foldovers = s.foldovers;
      r.phase = "orientation";
      r.time_s = seconds_since(t);
      emit(r, st);
    };
    consider("final", state, current, false, {});
    if (current.foldovers > 0) orient("oriented final", state);
    // The final state folds: the last fold-free state (solved again: a geometry-only step
    // re-solves its Pipeline in place).
    Solved fold_free;
    if (current.foldovers > 0 && last_fold_free) {
      check_cancel(observer);
      fold_free = solve_fresh(*last_fold_free, options);
      consider("last fold-free", *last_fold_free, fold_free, false, {});
    }
    if (!good()) orient("oriented initial", initial);
    // The rule: lowest E among fold-free, structurally equivalent; else fewest fold-overs,
    // then equivalent, then E.
    auto better = [](const WmCandidate& a, const WmCandidate& b) {
      const bool ga = a.foldovers == 0 && a.structurally_equivalent;
      const bool gb = b.foldovers == 0 && b.structurally_equivalent;
      if (ga != gb) return ga;
      if (ga) return a.E < b.E;
      if (a.foldovers != b.foldovers) return a.foldovers < b.foldovers;
      if (a.structurally_equivalent != b.structurally_equivalent) return a.structurally_equivalent;
      return a.E < b.E;
    };
    size_t best = 0;
    for (size_t k = 1; k < options_seen.size(); ++k)
      if (better(options_seen[k].c, options_seen[best].c)) best = k;
    const Option& chosen = options_seen[best];
    result.chosen = chosen.c.name;
    result.state = *chosen.state;
    result.pipeline = chosen.pipeline;
    result.orientation_constraints = chosen.oriented;
    result.orientation_options = chosen.used;
    result.E_final = chosen.c.E;
    result.foldovers_final = chosen.c.foldovers;
    result.time_s = seconds_since(t_start);
    return std::move(result);
  }
};

WmOptimizer::WmOptimizer(MeshLayout start, const PipelineOptions& options,
                         const WmOptions& node_options, Observer* observer)
    : impl_(std::make_unique<Impl>(std::move(start), options, node_options, observer)) {}

WmOptimizer::~WmOptimizer() = default;

bool WmOptimizer::step(Observer* observer) {
  impl_->observer = observer;
  return impl_->step();
}

void WmOptimizer::set_pinned(const std::vector<char>& pinned) {
  for (size_t n = 0; n < impl_->pinned.size() && n < pinned.size(); ++n)
    impl_->pinned[n] = pinned[n];
}

const MeshLayout& WmOptimizer::state() const {
  return impl_->state;
}

const std::vector<StepReport>& WmOptimizer::reports() const {
  return impl_->result.reports;
}

std::shared_ptr<Pipeline> WmOptimizer::pipeline() const {
  return impl_->current.pipeline;
}

WmResult WmOptimizer::finish(Observer* observer) {
  impl_->observer = observer;
  return impl_->finish();
}

WmResult optimize_working_layout(MeshLayout start, const PipelineOptions& options,
                                 const WmOptions& node_options, Observer* observer) {
  WmOptimizer optimizer(std::move(start), options, node_options, observer);
  while (optimizer.step(observer)) {
  }
  return optimizer.finish(observer);
}

}  // namespace qs
