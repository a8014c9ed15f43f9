// The job the editor's Run button starts on the worker thread: the first step computes the
// cross field, the parameterization and the traced embedding; every further step is one
// gradient step of node optimization (re-solving field and parameterization), streamed to the
// UI as a snapshot with metrics, timings and node positions. The final step also builds the
// quad mesh. All algorithm state lives in WorkerState::user (worker thread only).
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/engine/optimize.h"
#include "core/extract/quads.h"
#include "core/extract/tracing.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"
#include "core/pipeline/job_exports.h"
#include "core/pipeline/worker.h"

namespace qs::app {

//! Default quad count when WorkerOptions::quad_size is 0 (automatic).
constexpr int kDefaultQuadCount = 400;

//! One step of the editor's job. Throws QsError on failure, Cancelled when cancelled.
StepResult pipeline_step(WorkerState& state, const WorkerObserver& observer);

//! The engine settings of a job with \p options: the same run as `quadsketch-cli optimize`
//! with the corresponding flags (core/engine/optimize.h).
OptimizeSettings optimize_settings(const WorkerOptions& options);

//! Which files write_job_exports writes.
struct ExportSelection {
  bool param = true;   //!< param.obj
  bool layout = true;  //!< layout.json
  bool quads = true;   //!< quads.obj, patches.json, layout_curves.obj (needs a quad mesh)
};

//! Writes the selected exports into folder \p dir (created if missing) and returns the list of
//! written file names. Quick; may run on the UI thread (the data is immutable).
//! \throw std::exception on failure (IoError, filesystem errors, missing quad mesh).
std::vector<std::string> write_job_exports(const JobExports& data, const std::string& dir,
                                           const ExportSelection& what);

}  // namespace qs::app
