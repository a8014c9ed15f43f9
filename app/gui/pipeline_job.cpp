#include "app/gui/pipeline_job.h"

#include <cmath>
#include <sstream>

#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"

namespace qs::app {

namespace {

// Forwards cancellation of the worker to core code.
class CancelForwarder : public Observer {
 public:
  explicit CancelForwarder(const WorkerObserver& worker) : worker_(worker) {}
  bool should_cancel() const override { return worker_.should_cancel(); }

 private:
  const WorkerObserver& worker_;
};

struct JobState {
  TriMesh mesh;   // current geometry (node relocation moves vertices on the surface)
  Layout layout;  // current layout (node vertices, re-routed arcs)
  double alpha = 0.75;
  int halvings = 0;
  double energy = 0;
  bool done = false;
};

// Solves field + parameterization + extraction for the job's current state and fills the
// parts of a StepResult the UI draws. Updates state.layout with the traced arcs.
StepResult solve_for_display(JobState& job, WorkerState& state, const WorkerObserver& observer) {
  PipelineOptions options;
  Pipeline pipeline(job.mesh, job.layout, options);
  observer.check_cancel();
  pipeline.compute_field();
  observer.check_cancel();
  const Parameterization& param = pipeline.compute_parameterization();
  observer.check_cancel();
  const Extraction& ex = pipeline.extract();
  StepResult result;
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
  std::ostringstream ss;
  ss << "E = " << param.energy << ", fold-overs " << param.foldovers << ", "
     << (ex.structurally_equivalent ? "structurally equivalent" : "NOT structurally equivalent");
  if (!ex.structurally_equivalent && !ex.problems.empty()) ss << " (" << ex.problems.front() << ")";
  result.message = ss.str();
  return result;
}

// Applies the UI's pins (node id → pinned) to the job's layout.
void apply_pins(const WorkerState& state, Layout& layout) {
  for (auto& node : layout.nodes)
    if (state.pins.count(node.id)) node.pinned = true;
}

}  // namespace

StepResult pipeline_step(WorkerState& state, const WorkerObserver& observer) {
  auto job = std::static_pointer_cast<JobState>(state.user);
  if (!job) {
    job = std::make_shared<JobState>();
    job->mesh = *state.mesh;
    job->layout = state.layout;
    state.user = job;
    StepResult result = solve_for_display(*job, state, observer);
    result.finished = !state.options.node_optimization;
    result.message = "initial solve: " + result.message;
    return result;
  }
  // One descent step of node optimization from the current state.
  apply_pins(state, job->layout);
  CancelForwarder cancel(observer);
  NodeOptOptions options;
  options.max_steps = 1;
  options.alpha = job->alpha;
  options.stiffen_at_end = false;
  const NodeOptResult step =
      optimize_nodes(job->mesh, job->layout, PipelineOptions{}, options, &cancel);
  const bool accepted = step.accepted > 0;
  if (accepted) {
    job->mesh = step.mesh;
    job->layout = step.layout;
  } else {
    job->alpha *= 0.5;
    ++job->halvings;
  }
  StepResult result = solve_for_display(*job, state, observer);
  std::ostringstream ss;
  ss << "step " << state.iteration << (accepted ? " accepted" : " rejected (step size halved)")
     << ": " << result.message;
  result.message = ss.str();
  result.finished = job->halvings > options.max_halvings;
  return result;
}

}  // namespace qs::app
