#include "app/gui/pipeline_job.h"

namespace qs::app {

StepResult placeholder_pipeline_step(WorkerState& state, const WorkerObserver& observer) {
  observer.check_cancel();
  (void)state;
  StepResult result;
  result.finished = true;
  result.validate = true;  // the worker validates state.layout into the snapshot
  result.message =
      "Layout validated. The optimization stages (cross field, parameterization, node "
      "optimization) are not available in this build yet.";
  return result;
}

}  // namespace qs::app
