// The job the GUI's Run button starts on the worker. The real stages (field,
// parameterization, node optimization) plug in here once they exist.
#pragma once

#include "core/pipeline/worker.h"

namespace qs::app {

//! Placeholder step: validates the layout, finishes at once and says honestly that the
//! pipeline stages are not available yet.
StepResult placeholder_pipeline_step(WorkerState& state, const WorkerObserver& observer);

}  // namespace qs::app
