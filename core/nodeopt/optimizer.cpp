// Construction of a NodeOptimizer (the initial solve), the evaluation of the states the phases
// try, and the public API (docs/design.md, "Node optimization"). The phases are in
// descent.cpp, hop_polish.cpp, mobility.cpp and foldover_removal.cpp (optimizer_impl.h).
#include "core/nodeopt/optimizer.h"

#include <array>
#include <chrono>
#include <future>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "core/base/timing.h"
#include "core/nodeopt/geodesic.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer_impl.h"

namespace qs {

namespace nodeopt_detail {

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

namespace {

std::vector<std::array<double, 3>> node_positions(const TriMesh& mesh, const Layout& layout) {
  std::vector<std::array<double, 3>> out;
  for (const auto& n : layout.nodes) {
    const Vec3 p = mesh.point(mesh.vertex_handle(n.vertex));
    out.push_back({p[0], p[1], p[2]});
  }
  return out;
}

}  // namespace

void emit_step(StepReport r, const TriMesh& mesh, const Layout& layout,
               std::vector<StepReport>& reports, Observer* observer) {
  r.node_positions = node_positions(mesh, layout);
  reports.push_back(std::move(r));
  if (observer) observer->on_step(reports.back());
}

}  // namespace nodeopt_detail

using nodeopt_detail::curve_network;
using nodeopt_detail::emit_step;
using nodeopt_detail::evaluate_fresh;
using nodeopt_detail::Evaluation;
using nodeopt_detail::pipeline_matches;
using nodeopt_detail::solve_and_measure;

NodeOptimizer::Impl::Impl(const TriMesh& mesh, const Layout& layout,
                          const PipelineOptions& options_in, const NodeOptOptions& no_in,
                          Observer* obs, std::shared_ptr<Pipeline> start)
    : options(options_in),
      no(no_in),
      original(mesh),
      observer(obs),
      state{mesh, layout, {}, std::vector<CurvePoint>(layout.nodes.size())},
      original_geometry(build_geometry(mesh)),
      mean_edge(original_geometry.mean_edge_length),
      curves(curve_network(mesh, original_geometry, layout, options_in, no_in)),
      reroute(make_reroute_context(mesh, layout)),
      symmetric(no_in.moves.symmetry ? std::make_unique<const SymmetricStepper>(
                                           original, layout, no_in.moves.symmetry)
                                     : nullptr),
      alpha(no_in.descent.alpha),
      step_budget(no_in.descent.max_steps) {
  for (const auto& n : layout.nodes) state.anchor.push_back(vertex_surface_point(mesh, n.vertex));
  if (no.folds.orientation && no.tuning.initial_fallback)
    initial_state = std::make_unique<State>(state);
  compute_movable();
  for (int n : movable) result.sliding_nodes += on_curve(state.layout.nodes[n].vertex);
  check_cancel(observer);
  // The vertex order depends on the connectivity only. On large meshes the initial Pipeline
  // computes it beside the field (PipelineOptions::order_vertices); otherwise it is computed
  // here beside the initial solve (the future waits in its destructor if that throws).
  std::future<std::vector<int>> vertex_order;
  if (!options.param.vertex_order && !pipeline_orders_vertices(options, original_geometry.n_faces))
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
  } else if (!options.param.vertex_order) {
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

std::shared_ptr<Pipeline> NodeOptimizer::Impl::switched_pipeline(const TriMesh& m, const Layout& l,
                                                                 bool own_solvers) {
  if (no.run.reuse_field && current.pipeline->field()) {
    ++counters.relayouts;
    auto p = std::make_shared<Pipeline>(m, l, *current.pipeline);
    if (own_solvers) p->unshare_solvers();
    return p;
  }
  ++counters.fresh_pipelines;
  return std::make_shared<Pipeline>(m, l, options, false);
}

bool NodeOptimizer::Impl::parallel(int threads) const {
  return no.run.threads >= threads && std::thread::hardware_concurrency() >= 2;
}

Evaluation NodeOptimizer::Impl::evaluate_switched(const TriMesh& m, const Layout& l) {
  Evaluation ev;
  ev.pipeline = switched_pipeline(m, l, false);
  solve_and_measure(ev, options);
  counters.prepared_param_solvers += ev.pipeline->param_solver_prepared();
  return ev;
}

NodeOptimizer::NodeOptimizer(const TriMesh& mesh, const Layout& layout,
                             const PipelineOptions& options, const NodeOptOptions& given_options,
                             Observer* observer, std::shared_ptr<Pipeline> start) {
  // Symmetric optimization: what moves single nodes off (symmetric_step.h).
  const NodeOptOptions node_options = symmetric_node_options(given_options);
  std::optional<SeparateNodesResult> separated;
  if (node_options.moves.separate_crowded_nodes) separated = separate_movable_nodes(mesh, layout);
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
