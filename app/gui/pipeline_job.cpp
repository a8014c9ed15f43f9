#include "app/gui/pipeline_job.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/errors.h"
#include "core/engine/optimize.h"
#include "core/layout/layout.h"
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
  TriMesh mesh;                    // the displayed state's geometry (nodes move on the surface)
  Layout layout;                   // the displayed state's layout (node vertices, re-routed arcs)
  std::set<int> pinned_in_layout;  // nodes pinned in the editor's layout
  std::set<int> arcs_pinned_in_layout;  // arcs pinned in the editor's layout
  double energy = 0;
  StepMetrics metrics;  // of the last displayed state (repeated for rejected steps)
  //! Solved (field + parameterization) at exactly (mesh, layout): the display reuses it.
  std::shared_ptr<Pipeline> pipeline;
  //! The whole `quadsketch-cli optimize` policy (core/engine/optimize.h): its initial solve at
  //! the first step, then one unit (descent step, hop sweep, a retry's start) per step.
  std::unique_ptr<OptimizeRun> run;
  int runs = 0;  // OptimizeRun::runs() at the last step
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

}  // namespace

OptimizeSettings optimize_settings(const WorkerOptions& o) {
  OptimizeSettings s;
  s.field.align = o.align;
  s.field.sharp_angle_deg = o.sharp_angle_deg;
  s.field.max_cluster_faces = o.max_cluster_faces;
  s.field.wrap_free_holes = o.wrap_free_holes;
  s.param.anisotropy = o.anisotropy;
  s.param.sizing = o.sizing;
  s.nodes.enabled = o.node_optimization;
  s.nodes.steps = o.descent_steps;
  s.nodes.alpha = o.alpha;
  s.nodes.keep_sharp_edges = o.keep_sharp_edges;
  s.nodes.keep_apart = o.keep_nodes_apart;
  s.nodes.separate_crowded = o.node_optimization && o.separate_nodes;
  if (!o.node_optimization) s.folds.remove = o.remove_foldovers;
  s.folds.untangle = o.untangle;
  if (o.node_optimization) {  // a fixed-node run has nothing to keep symmetric
    s.nodes.symmetry = o.symmetry;
    s.nodes.symmetry_plane = o.symmetry_plane;
  }
  return s;
}

namespace {

// The solved field for display: first direction per face and the constraints (in force or
// released).
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
    view->constraint_in_force.push_back(
        k < field->constraint_active.size() ? field->constraint_active[k] : char(1));
    view->in_force += view->constraint_in_force.back() != 0;
  }
  view->clusters = field->clusters;
  view->dropped_clusters = field->dropped_clusters;
  view->warning = released_constraints_warning(*field);
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

// Solves what job.pipeline lacks of field + parameterization (the run hands it over solved) +
// extraction for the job's current state and fills the
// parts of a StepResult the UI draws (metrics, timings, node positions, exports; the quad mesh
// when \p build_quads). Updates state.layout with the traced arcs.
StepResult solve_for_display(JobState& job, WorkerState& state, const WorkerObserver& observer,
                             bool build_quads) {
  StepResult result;
  StepMetrics& m = result.metrics;
  // The run hands over its solved Pipeline (the fixed-node one may still need its solve).
  if (!job.pipeline) throw std::logic_error("solve_for_display: no Pipeline");
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

// The pins in force per node of \p layout: the editor layout's pins, minus the nodes released
// during the run (ClearPin), plus those pinned during the run (SetPin; a pinned node stays where
// it is: the UI pins a node at its current vertex).
std::vector<char> pin_flags(const WorkerState& state, const JobState& job, const Layout& layout) {
  std::vector<char> flags;
  for (const auto& node : layout.nodes)
    flags.push_back(
        (job.pinned_in_layout.count(node.id) > 0 && state.released.count(node.id) == 0) ||
        state.pins.count(node.id) > 0);
  return flags;
}

// The pins in force per arc of \p layout: the editor layout's, overridden by those set during the
// run (SetArcPin). A pinned arc keeps its route and its end nodes.
std::vector<char> arc_pin_flags(const WorkerState& state, const JobState& job,
                                const Layout& layout) {
  std::vector<char> flags;
  for (const auto& arc : layout.arcs) {
    const auto it = state.arc_pins.find(arc.id);
    flags.push_back(it != state.arc_pins.end() ? it->second
                                               : job.arcs_pinned_in_layout.count(arc.id) > 0);
  }
  return flags;
}

}  // namespace

StepResult pipeline_step(WorkerState& state, const WorkerObserver& observer) {
  const auto start = Clock::now();
  auto job = std::static_pointer_cast<JobState>(state.user);
  CancelForwarder cancel(observer);
  std::string prefix;  // what this step did, before the metrics
  const auto add = [&prefix](const std::string& text) {
    if (text.empty()) return;
    prefix += (prefix.empty() ? "" : "; ") + text;
  };
  if (!job) {
    job = std::make_shared<JobState>();
    for (const auto& node : state.layout.nodes)
      if (node.pinned) job->pinned_in_layout.insert(node.id);
    for (const auto& arc : state.layout.arcs)
      if (arc.pinned) job->arcs_pinned_in_layout.insert(arc.id);
    job->run = std::make_unique<OptimizeRun>(*state.mesh, state.layout,
                                             optimize_settings(state.options), &cancel);
    job->runs = job->run->runs();
    job->mesh = job->run->mesh();
    job->layout = job->run->layout();
    job->pipeline = job->run->pipeline(&cancel);
    state.user = job;
    const bool fixed = !state.options.node_optimization;
    const bool last = fixed || state.options.max_steps <= 1;
    StepResult result = solve_for_display(*job, state, observer, last);
    job->metrics = result.metrics;
    result.finished = fixed;
    result.message = "initial solve: " + result.message;
    const Parameterization* param = job->pipeline->parameterization();
    if (fixed && param && param->orientation.ran) {
      const OrientationReport& r = param->orientation;
      result.message += "; fold-overs " + std::to_string(r.foldovers_before) + " -> " +
                        std::to_string(param->foldovers) + " by orientation constraints" +
                        (r.success ? "" : " (not used: " + r.message + ")");
    }
    result.metrics.total_ms = ms_since(start);
    return result;
  }
  // The next unit of the run from the current state; the end of the run (fold-over removal,
  // the choice among the runs, the final solve) when it is over or the job's last step came.
  OptimizeRun& run = *job->run;
  auto t = Clock::now();
  run.set_pinned(pin_flags(state, *job, run.layout()), arc_pin_flags(state, *job, run.layout()));
  const size_t reports_before = run.runs() == job->runs ? run.reports().size() : 0;
  const bool more = run.step(&cancel);
  const bool restarted = run.runs() != job->runs;  // a retry started from the input
  job->runs = run.runs();
  const bool last = !more || state.iteration + 1 >= state.options.max_steps;
  bool changed = restarted;  // a unit of this call kept a new state
  std::ostringstream what;
  for (size_t k = restarted ? 0 : reports_before; k < run.reports().size(); ++k) {
    const StepReport& r = run.reports()[k];
    if (r.phase == "initial") continue;
    changed |= r.accepted;
    what << (what.tellp() > 0 ? "; " : "") << r.phase << " step " << r.step
         << (r.accepted             ? " accepted"
             : r.phase != "descent" ? " kept nothing"
             : r.moved_nodes == 0   ? " converged"
                                    : " rejected (step size halved)");
  }
  add(what.str());
  for (const std::string& note : run.take_notes()) add(note);
  StepResult result;
  if (last) {
    OptimizeResult end = run.finish(&cancel);
    for (const std::string& note : run.take_notes()) add(note);
    job->run.reset();
    job->pipeline = end.pipeline;
    job->mesh = end.pipeline->mesh();
    job->layout = end.pipeline->layout();
    if (end.nodes && end.nodes->orientation.ran) {
      const NodeOptResult& n = *end.nodes;
      add("fold-overs " + std::to_string(n.foldovers_descent) + " -> " +
          std::to_string(n.foldovers_final) + " by orientation constraints");
      // Infeasible constraints: the nodes next to the faces they could not unfold.
      if (n.foldovers_final > 0 && !n.orientation.success) {
        const std::vector<int> near =
            nodes_near_faces(job->mesh, job->layout, n.orientation.infeasible_faces);
        if (!near.empty()) prefix += " (infeasible near " + describe_nodes(job->layout, near) + ")";
      }
    }
    if (end.nodes && end.nodes->initial_reverted)
      add("the moved layouts could not be unfolded: back at the initial state");
    else if (end.nodes && end.nodes->fewest_foldovers_reverted)
      add("unfolded at an earlier step (the one with the fewest fold-overs)");
    const double nodeopt_ms = ms_since(t);
    result = solve_for_display(*job, state, observer, true);
    result.metrics.nodeopt_ms = nodeopt_ms;
    result.finished = true;
  } else if (changed) {
    job->mesh = run.mesh();
    job->layout = run.layout();
    job->pipeline = run.pipeline(&cancel);
    const double nodeopt_ms = ms_since(t);
    result = solve_for_display(*job, state, observer, false);
    result.metrics.nodeopt_ms = nodeopt_ms;
  } else {  // nothing kept: the display stays (no solve), the energy and metrics repeat
    result.energy = job->energy;
    result.metrics = job->metrics;
    result.metrics.nodeopt_ms = ms_since(t);
    result.nodes = node_frame(job->mesh, state.layout);
    result.validate = false;
  }
  job->metrics = result.metrics;
  result.metrics.total_ms = ms_since(start);
  // Pins shown on the traced layout: the ones in force.
  const std::vector<char> pins = pin_flags(state, *job, state.layout);
  for (size_t n = 0; n < state.layout.nodes.size(); ++n) state.layout.nodes[n].pinned = pins[n];
  const std::vector<char> arc_pins = arc_pin_flags(state, *job, state.layout);
  for (size_t a = 0; a < state.layout.arcs.size(); ++a) state.layout.arcs[a].pinned = arc_pins[a];
  std::ostringstream ss;
  ss << prefix;
  if (!result.message.empty()) ss << ": " << result.message;
  result.message = ss.str();
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
