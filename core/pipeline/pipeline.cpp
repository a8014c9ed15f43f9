#include "core/pipeline/pipeline.h"

#include <cstdio>
#include <future>
#include <sstream>
#include <utility>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/field/topology.h"

namespace qs {

Pipeline::Pipeline(TriMesh mesh, Layout layout, PipelineOptions options, bool validate)
    : mesh_(std::move(mesh)), layout_(std::move(layout)), options_(std::move(options)) {
  if (validate) validation_ = validate_layout(mesh_, layout_);
  if (validate && !validation_.valid()) {
    std::ostringstream ss;
    ss << "invalid layout: " << validation_.errors() << " error(s)";
    for (const auto& issue : validation_.issues)
      if (issue.severity == IssueSeverity::Error) ss << "\n  " << format_issue(issue);
    throw InvalidInputError(ss.str());
  }
  topology_ = build_topology(mesh_, layout_);
  geometry_ = build_geometry(mesh_);
  if (pipeline_orders_vertices(options_, geometry_.n_faces))
    // The thread gets its own copy of the edges: update_positions rewrites geometry_.
    vertex_order_ = std::async(std::launch::async, [n = geometry_.n_vertices,
                                                    edges = geometry_.edge_vertices]() {
                      std::vector<int> order = vertex_nested_dissection(n, edges);
                      return order.empty()
                                 ? std::shared_ptr<const std::vector<int>>()
                                 : std::make_shared<const std::vector<int>>(std::move(order));
                    }).share();
}

bool pipeline_orders_vertices(const PipelineOptions& options, int n_faces) {
  return options.order_vertices && options.param.second_thread && !options.param.vertex_order &&
         n_faces >= options.second_thread_min_faces;
}

void Pipeline::take_vertex_order() {
  if (!vertex_order_.valid()) return;
  std::shared_ptr<const std::vector<int>> order = vertex_order_.get();
  vertex_order_ = {};
  if (order && !options_.param.vertex_order) options_.param.vertex_order = std::move(order);
}

Pipeline::Pipeline(TriMesh mesh, Layout layout, const Pipeline& previous)
    : mesh_(std::move(mesh)), layout_(std::move(layout)), options_(previous.options_) {
  if (mesh_.n_vertices() != previous.mesh_.n_vertices() ||
      mesh_.n_faces() != previous.mesh_.n_faces())
    throw InvalidInputError("Pipeline: the mesh has " + std::to_string(mesh_.n_vertices()) +
                            " vertices / " + std::to_string(mesh_.n_faces()) +
                            " faces, the previous pipeline's " +
                            std::to_string(previous.mesh_.n_vertices()) + " / " +
                            std::to_string(previous.mesh_.n_faces()));
  vertex_order_ = previous.vertex_order_;  // when previous has not taken it yet
  topology_ = build_topology(mesh_, layout_);
  geometry_ = previous.geometry_;
  update_geometry(mesh_, geometry_);
  if (previous.field_current()) {
    field_solver_ = std::make_unique<CrossFieldSolver>(*previous.field_solver_);
    field_layout_stale_ = true;
  }
}

Pipeline::~Pipeline() = default;

void Pipeline::update_positions(const TriMesh& mesh) {
  if (mesh.n_vertices() != mesh_.n_vertices() || mesh.n_faces() != mesh_.n_faces())
    throw InvalidInputError("update_positions: the mesh has " + std::to_string(mesh.n_vertices()) +
                            " vertices / " + std::to_string(mesh.n_faces()) +
                            " faces, the pipeline's " + std::to_string(mesh_.n_vertices()) + " / " +
                            std::to_string(mesh_.n_faces()));
  for (auto v : mesh_.vertices()) mesh_.set_point(v, mesh.point(v));
  update_geometry(mesh_, geometry_);
  curvature_.reset();
  extraction_.reset();
  prepared_param_.reset();
}

void Pipeline::unshare_solvers() {
  if (field_solver_) field_solver_->unshare_solvers();
}

const CrossField& Pipeline::compute_field() {
  if (!field_solver_) {
    // Split clusters are judged against the layout's own field, whose global rotation is
    // free: it gets the rotation the parameterization would choose for it, as for a field
    // without constraints. Its u/v labels follow the
    // unrotated field: compute_parameterization keeps the solver only when the final field
    // gives the same constraint rows (ParamSolver::adopt_field), else builds one.
    prepared_param_.reset();
    CrossFieldSolver::ReferenceRotation rotation;
    if (options_.field.max_cluster_faces > 0)
      rotation = [this](const std::vector<int>& period_jump, const std::vector<double>& theta) {
        take_vertex_order();
        try {
          auto solver =
              std::make_unique<ParamSolver>(mesh_, geometry_, layout_, topology_, period_jump,
                                            theta, options_.param, nullptr, /*solve_now=*/false);
          const double phi = solver->optimal_field_rotation(mesh_, geometry_, theta);
          prepared_param_ = std::move(solver);
          return phi;
        } catch (const QsError&) {
          return 0.0;  // compute_parameterization() reports it
        }
      };
    field_solver_ = std::make_unique<CrossFieldSolver>(mesh_, geometry_, layout_, topology_,
                                                       options_.field, rotation);
    return field_solver_->field();
  }
  if (field_layout_stale_) {
    // The parameterization's combinatorial setup (cut graph, labels, constraint elimination,
    // the reduced matrix's pattern and its symbolic analysis) needs the period jumps, and θ
    // only for the arc labels' global u/v choice and the feature edges' directions: it is
    // built on the second thread from the last field's θ while the field is solved, and
    // compute_parameterization() keeps it when the solved field gives the same rows
    // (ParamSolver::adopt_field), else builds one as before. That thread computes the period
    // jumps first and hands them to update_layout too. Joined before returning (also when
    // update_layout throws: the future waits in its destructor), so it never outlives this
    // call's use of the members.
    prepared_param_.reset();
    using Jumps = std::pair<std::vector<int>, PeriodJumpReport>;
    std::promise<Jumps> jumps_promise;
    std::shared_future<Jumps> jumps;
    std::future<std::unique_ptr<ParamSolver>> prepared;
    take_vertex_order();  // before the thread reads options_
    if (options_.param.second_thread && geometry_.n_faces >= options_.second_thread_min_faces) {
      jumps = jumps_promise.get_future().share();
      prepared = std::async(std::launch::async, [this, theta = field_solver_->field().theta,
                                                 promise = std::move(jumps_promise)]() mutable {
        std::unique_ptr<ParamSolver> solver;
        std::vector<int> p;
        try {
          PeriodJumpReport report;
          p = compute_period_jumps(mesh_, geometry_, layout_, topology_, &report,
                                   options_.field.free_loops);
          promise.set_value({p, report});
        } catch (...) {
          promise.set_exception(std::current_exception());  // update_layout throws it
          return solver;
        }
        try {
          solver = std::make_unique<ParamSolver>(mesh_, geometry_, layout_, topology_, p, theta,
                                                 options_.param, nullptr,
                                                 /*solve_now=*/false);
        } catch (const QsError&) {
          // compute_parameterization()'s own construction reports it
        }
        return solver;
      });
    }
    CrossFieldSolver::PeriodJumpSource period_jumps;
    if (jumps.valid())
      period_jumps = [&jumps](PeriodJumpReport* report) {
        const Jumps& j = jumps.get();
        if (report) *report = j.second;
        return j.first;
      };
    const CrossField& f =
        field_solver_->update_layout(mesh_, geometry_, layout_, topology_, period_jumps);
    field_layout_stale_ = false;
    if (prepared.valid()) prepared_param_ = prepared.get();
    return f;
  }
  return field_solver_->solve(geometry_);
}

const CrossField* Pipeline::field() const {
  return field_current() ? &field_solver_->field() : nullptr;
}

std::vector<Singularity> Pipeline::singularities() const {
  std::vector<Singularity> out;
  if (!field_current()) return out;
  const auto idx = field_quarter_indices(geometry_, field_solver_->field().theta);
  for (int v = 0; v < static_cast<int>(idx.size()); ++v)
    if (idx[v] != 0) out.push_back({v, idx[v]});
  return out;
}

const Parameterization& Pipeline::compute_parameterization() {
  const CrossField& field = field_current() ? field_solver_->field() : compute_field();
  extraction_.reset();
  if (!param_solver_) {
    // No direction constraints: the field's global rotation is free. Take the one that
    // minimizes the energy, not an arbitrary anchor (that would depend on arc routing); the
    // solver's first solve waits until it is chosen.
    const bool free_rotation = field.gauge_face >= 0;
    take_vertex_order();
    std::unique_ptr<ParamSolver> prepared = std::move(prepared_param_);
    if (prepared && prepared->adopt_field(mesh_, geometry_, layout_, topology_, field.period_jump,
                                          field.theta)) {
      param_solver_ = std::move(prepared);  // not solved yet: the solve below
      param_prepared_ = true;
    } else {
      param_solver_ =
          std::make_unique<ParamSolver>(mesh_, geometry_, layout_, topology_, field.period_jump,
                                        field.theta, options_.param, nullptr, !free_rotation);
      if (!free_rotation) return param_solver_->result();
    }
  }
  if (field.gauge_face >= 0)
    field_solver_->rotate(param_solver_->optimal_field_rotation(mesh_, geometry_, field.theta));
  return param_solver_->solve(mesh_, geometry_, field_solver_->field().theta);
}

const Parameterization* Pipeline::parameterization() const {
  return param_solver_ ? &param_solver_->result() : nullptr;
}

const Extraction& Pipeline::extract() {
  if (!param_solver_) compute_parameterization();
  extraction_ = std::make_unique<Extraction>(
      extract_layout(mesh_, geometry_, layout_, topology_, param_solver_->labeling(),
                     field_solver_->field().period_jump, param_solver_->result().corner_uv));
  return *extraction_;
}

ParamMetrics Pipeline::metrics() {
  if (!param_solver_) compute_parameterization();
  if (!curvature_) {  // the field's own curvature when it is the one E° needs (same positions)
    const Curvature* field_curvature =
        field_solver_ ? field_solver_->curvature_at(mesh_, CurvatureOptions{}) : nullptr;
    curvature_ = std::make_unique<Curvature>(field_curvature ? *field_curvature
                                                             : compute_curvature(mesh_, geometry_));
  }
  const auto& r = param_solver_->result();
  return compute_metrics(mesh_, geometry_, *curvature_, r.corner_uv, r.energy);
}

Layout Pipeline::output_layout() const {
  Layout out = layout_;
  out.mesh_vertices = static_cast<int>(mesh_.n_vertices());
  out.mesh_faces = static_cast<int>(mesh_.n_faces());
  if (extraction_) annotate_layout(mesh_, topology_, *extraction_, out);
  return out;
}

QuadMesh build_quad_mesh(const Pipeline& pipeline, const Extraction& extraction,
                         const QuadMeshOptions& options) {
  if (!pipeline.field() || !pipeline.parameterization())
    throw InvalidInputError("quad mesh: the pipeline has no field or parameterization yet");
  return build_quad_mesh(pipeline.mesh(), pipeline.geometry(), pipeline.layout(),
                         pipeline.topology(), extraction, pipeline.field()->period_jump,
                         pipeline.parameterization()->corner_uv, options);
}

void write_param_obj(const TriMesh& mesh, const std::vector<std::array<double, 2>>& uv,
                     const std::string& path) {
  write_file_atomic(path, [&](std::ostream& out) {
    char line[160];
    out << "# QuadSketch parameterization: one vt per face corner\n";
    for (auto v : mesh.vertices()) {
      const auto& p = mesh.point(v);
      std::snprintf(line, sizeof line, "v %.17g %.17g %.17g\n", p[0], p[1], p[2]);
      out << line;
    }
    for (const auto& t : uv) {
      std::snprintf(line, sizeof line, "vt %.17g %.17g\n", t[0], t[1]);
      out << line;
    }
    int corner = 1;
    for (auto f : mesh.faces()) {
      out << 'f';
      for (auto v : mesh.fv_range(f)) out << ' ' << v.idx() + 1 << '/' << corner++;
      out << '\n';
    }
  });
}

void write_field_txt(const GeometryCache& geometry, const std::vector<double>& theta,
                     const std::string& path) {
  write_file_atomic(path, [&](std::ostream& out) {
    char line[96];
    for (int f = 0; f < geometry.n_faces; ++f) {
      const Vec3 d = geometry.direction_in_face(f, theta[f]);
      std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", d[0], d[1], d[2]);
      out << line;
    }
  });
}

}  // namespace qs
