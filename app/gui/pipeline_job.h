// The job the editor's Run button starts on the worker thread: the first step computes the
// cross field, the parameterization and the traced embedding; every further step is one
// gradient step of node optimization (re-solving field and parameterization), streamed to the
// UI as a snapshot. All algorithm state lives in WorkerState::user (worker thread only).
#pragma once

#include "core/pipeline/worker.h"

namespace qs::app {

//! One step of the editor's job. Throws QsError on failure, Cancelled when cancelled.
StepResult pipeline_step(WorkerState& state, const WorkerObserver& observer);

}  // namespace qs::app
