#include "app/gui/pipeline_job.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>

#include "core/base/errors.h"
#include "core/layout/layout_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"

namespace qs::app {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Forwards cancellation of the worker to core code.
class CancelForwarder : public Observer {
 public:
  explicit CancelForwarder(const WorkerObserver& worker) : worker_(worker) {}
  bool should_cancel() const override { return worker_.should_cancel(); }

 private:
  const WorkerObserver& worker_;
};

struct JobState {
  TriMesh mesh;             // current geometry (node relocation moves vertices on the surface)
  Layout layout;            // current layout (node vertices, re-routed arcs)
  PipelineOptions options;  // fixed when the job starts (WorkerOptions of that moment)
  std::set<int> pinned_in_layout;  // nodes pinned in the editor's layout (stay pinned)
  double alpha = 0.75;
  int halvings = 0;
  double energy = 0;
  bool done = false;
  //! Solved (field + parameterization with `options`) at exactly (mesh, layout), or null: the
  //! display reuses it and the next node-optimization step starts from it (no re-solve).
  std::shared_ptr<Pipeline> pipeline;
  //! Solved with exactly `options` at (mesh, layout) (`pipeline` may hold the optimizer's
  //! orientation-constrained solve instead): the next step's initial solve.
  std::shared_ptr<Pipeline> warm;
};

// Node positions of \p layout on \p mesh: the traced position when known, else the vertex.
std::shared_ptr<const NodeFrame> node_frame(const TriMesh& mesh, const Layout& layout) {
  auto frame = std::make_shared<NodeFrame>();
  for (const auto& node : layout.nodes) {
    std::array<float, 3> p{};
    if (node.position) {
      p = {float((*node.position)[0]), float((*node.position)[1]), float((*node.position)[2])};
    } else if (node.vertex >= 0 && node.vertex < int(mesh.n_vertices())) {
      const auto& q = mesh.point(OpenMesh::VertexHandle(node.vertex));
      p = {float(q[0]), float(q[1]), float(q[2])};
    } else {
      continue;
    }
    frame->ids.push_back(node.id);
    frame->positions.push_back(p);
  }
  return frame;
}

PipelineOptions pipeline_options(const WorkerOptions& o) {
  PipelineOptions options;
  options.field.constraints.curvature = o.align;
  options.field.constraints.sharp_angle_deg = o.sharp_angle_deg;
  options.param.anisotropy = o.anisotropy;
  return options;
}

// The solved field for display: first direction per face and the constraints in force.
std::shared_ptr<const FieldView> field_view(const Pipeline& pipeline) {
  const CrossField* field = pipeline.field();
  if (!field) return nullptr;
  auto view = std::make_shared<FieldView>();
  const std::vector<Vec3> dirs = field_directions(pipeline.geometry(), field->theta);
  view->direction.reserve(dirs.size());
  for (const Vec3& d : dirs) view->direction.push_back({float(d[0]), float(d[1]), float(d[2])});
  const FieldConstraints& c = field->constraints;
  for (std::size_t k = 0; k < c.face.size() && k < c.direction.size() && k < c.kind.size(); ++k) {
    view->constraint_faces.push_back(c.face[k]);
    view->constraint_direction.push_back(
        {float(c.direction[k][0]), float(c.direction[k][1]), float(c.direction[k][2])});
    view->constraint_kind.push_back(static_cast<char>(c.kind[k]));
  }
  return view;
}

std::shared_ptr<const QuadOverlay> overlay_of(const QuadMesh& quads) {
  auto overlay = std::make_shared<QuadOverlay>();
  overlay->quad_size = quads.quad_size;
  overlay->vertices.reserve(quads.vertices.size());
  for (const auto& v : quads.vertices)
    overlay->vertices.push_back({float(v[0]), float(v[1]), float(v[2])});
  overlay->quads = quads.quads;
  overlay->gridded_patches = quads.gridded_patches();
  overlay->patches = int(quads.patches.size());
  overlay->warnings = quads.warnings;
  return overlay;
}

// Solves field + parameterization (unless job.pipeline already holds them, e.g. handed back by
// the node optimizer) + extraction for the job's current state and fills the
// parts of a StepResult the UI draws (metrics, timings, node positions, exports; the quad mesh
// when \p build_quads). Updates state.layout with the traced arcs.
StepResult solve_for_display(JobState& job, WorkerState& state, const WorkerObserver& observer,
                             bool build_quads) {
  StepResult result;
  StepMetrics& m = result.metrics;
  // The node optimizer hands back its solved Pipeline: solve only when there is none.
  if (!job.pipeline || !job.pipeline->parameterization())
    job.pipeline = std::make_shared<Pipeline>(job.mesh, job.layout, job.options);
  Pipeline& pipeline = *job.pipeline;
  observer.check_cancel();
  auto t = Clock::now();
  if (!pipeline.field()) pipeline.compute_field();
  m.field_ms = ms_since(t);
  result.field = field_view(pipeline);
  observer.check_cancel();
  t = Clock::now();
  const Parameterization& param = pipeline.parameterization() ? *pipeline.parameterization()
                                                              : pipeline.compute_parameterization();
  m.param_ms = ms_since(t);
  observer.check_cancel();
  t = Clock::now();
  const Extraction& ex = pipeline.extract();
  m.extract_ms = ms_since(t);
  observer.check_cancel();
  t = Clock::now();
  const ParamMetrics pm = pipeline.metrics();
  m.metrics_ms = ms_since(t);
  m.valid = true;
  m.E = pm.E;
  m.E_confor = pm.E_confor;
  m.E_angle_deg = pm.E_angle_deg;
  m.E_planar = pm.E_planar;
  m.foldovers = pm.foldovers;

  result.energy = param.energy;
  job.energy = param.energy;
  result.corner_uv.resize(param.corner_uv.size());
  for (size_t i = 0; i < param.corner_uv.size(); ++i)
    result.corner_uv[i] = {static_cast<float>(param.corner_uv[i][0]),
                           static_cast<float>(param.corner_uv[i][1])};
  result.face_foldover.assign(param.corner_uv.size() / 3, 0);
  for (size_t f = 0; f < result.face_foldover.size(); ++f)
    result.face_foldover[f] = param_signed_area2(param.corner_uv, static_cast<int>(f)) <= 0;
  state.layout = pipeline.output_layout();
  result.nodes = node_frame(job.mesh, state.layout);

  auto exports = std::make_shared<JobExports>();
  exports->mesh = job.mesh;
  exports->corner_uv = param.corner_uv;
  exports->layout = state.layout;
  exports->extraction = ex;
  std::string quad_note;
  if (build_quads) {
    observer.check_cancel();
    t = Clock::now();
    QuadMeshOptions qopt;
    qopt.quad_size = state.options.quad_size;
    if (qopt.quad_size <= 0) qopt.quad_count = kDefaultQuadCount;
    try {
      auto quads = std::make_shared<const QuadMesh>(build_quad_mesh(pipeline, ex, qopt));
      result.quads = overlay_of(*quads);
      exports->quads = std::move(quads);
    } catch (const QsError& e) {
      quad_note = std::string(", no quad mesh: ") + e.what();
    }
    m.quads_ms = ms_since(t);
  }
  result.exports = std::move(exports);

  std::ostringstream ss;
  ss << "E = " << param.energy << ", fold-overs " << param.foldovers << ", "
     << (ex.structurally_equivalent ? "structurally equivalent" : "NOT structurally equivalent");
  if (!ex.structurally_equivalent && !ex.problems.empty()) ss << " (" << ex.problems.front() << ")";
  ss << quad_note;
  result.message = ss.str();
  return result;
}

// Applies the UI's pins (node id -> vertex) to the job's layout: pinned nodes stay where they
// are (the UI pins a node at its current vertex); a cleared pin releases the node unless the
// editor's layout pinned it.
void apply_pins(const WorkerState& state, const JobState& job, Layout& layout) {
  for (auto& node : layout.nodes)
    node.pinned = job.pinned_in_layout.count(node.id) > 0 || state.pins.count(node.id) > 0;
}

}  // namespace

StepResult pipeline_step(WorkerState& state, const WorkerObserver& observer) {
  const auto start = Clock::now();
  auto job = std::static_pointer_cast<JobState>(state.user);
  if (!job) {
    job = std::make_shared<JobState>();
    job->mesh = *state.mesh;
    job->layout = state.layout;
    job->options = pipeline_options(state.options);
    job->alpha = state.options.alpha;
    for (const auto& node : job->layout.nodes)
      if (node.pinned) job->pinned_in_layout.insert(node.id);
    state.user = job;
    const bool last = !state.options.node_optimization || state.options.max_steps <= 1;
    StepResult result = solve_for_display(*job, state, observer, last);
    result.finished = !state.options.node_optimization;
    result.message = "initial solve: " + result.message;
    result.metrics.total_ms = ms_since(start);
    return result;
  }
  // One descent step of node optimization from the current state.
  apply_pins(state, *job, job->layout);
  CancelForwarder cancel(observer);
  NodeOptOptions options;
  options.max_steps = 1;
  options.hop_polish = false;  // one step per call (a hop sweep would add more steps)
  options.alpha = job->alpha;
  options.stiffen_at_end = false;
  auto t = Clock::now();
  // Warm start from the Pipeline of the previous display (optimize_nodes ignores it when the
  // pins changed the layout), and display the Pipeline it returns: one solve per trial only.
  // The optimizer may re-solve the start in place, so the job drops it until the step is done.
  std::shared_ptr<Pipeline> warm_start = job->warm ? job->warm : job->pipeline;
  job->pipeline.reset();
  job->warm.reset();
  const NodeOptResult step =
      optimize_nodes(job->mesh, job->layout, job->options, options, &cancel, std::move(warm_start));
  const double nodeopt_ms = ms_since(t);
  const bool accepted = step.accepted > 0;
  job->pipeline = step.pipeline;
  job->warm = step.descent_pipeline;
  if (accepted) {
    job->mesh = step.mesh;
    job->layout = step.layout;
  } else {
    job->alpha *= 0.5;
    ++job->halvings;
  }
  const bool finished = job->halvings > options.max_halvings;
  const bool last = finished || state.iteration + 1 >= state.options.max_steps;
  StepResult result = solve_for_display(*job, state, observer, last);
  result.metrics.nodeopt_ms = nodeopt_ms;
  result.metrics.total_ms = ms_since(start);
  std::ostringstream ss;
  ss << "step " << state.iteration << (accepted ? " accepted" : " rejected (step size halved)")
     << ": " << result.message;
  result.message = ss.str();
  result.finished = finished;
  return result;
}

std::vector<std::string> write_job_exports(const JobExports& data, const std::string& dir,
                                           const ExportSelection& what) {
  namespace fs = std::filesystem;
  if (dir.empty()) throw std::runtime_error("choose an export folder first");
  fs::create_directories(dir);
  std::vector<std::string> written;
  if (what.param) {
    write_param_obj(data.mesh, data.corner_uv, (fs::path(dir) / "param.obj").string());
    written.push_back("param.obj");
  }
  if (what.layout) {
    save_layout(data.layout, (fs::path(dir) / "layout.json").string(), &data.mesh);
    written.push_back("layout.json");
  }
  if (what.quads) {
    if (!data.quads)
      throw std::runtime_error("no quad mesh yet: run the pipeline to the end first");
    write_quad_exports(*data.quads, data.layout, data.extraction, dir);
    written.insert(written.end(), {"quads.obj", "patches.json", "layout_curves.obj"});
  }
  return written;
}

}  // namespace qs::app
