// Immutable state of the pipeline worker at one step, published to the UI (architecture.md,
// "Threading model"). A Snapshot is built by the worker outside any lock, then shared as
// shared_ptr<const Snapshot>; nobody modifies it after publication.
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/layout/validate.h"

namespace qs {

//! What the worker is doing. Failed keeps the worker alive; the message says why.
enum class WorkerStatus { Idle, Running, Paused, Finished, Failed, Cancelled };

//! Human-readable name ("idle", "running", ...).
const char* to_string(WorkerStatus status);

struct Snapshot {
  std::uint64_t version = 0;      //!< publication counter (strictly increasing)
  std::uint64_t generation = 0;   //!< job generation this state belongs to
  std::uint64_t applied_seq = 0;  //!< every command with seq <= applied_seq is reflected here
  WorkerStatus status = WorkerStatus::Idle;
  std::string message;  //!< status line or failure message
  int iteration = 0;    //!< steps done in the current job
  double energy = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> energy_history;  //!< energy per step of the current job

  //! The mesh the job works on (shared, immutable); null before LoadMesh.
  std::shared_ptr<const TriMesh> mesh;
  //! Layout at this step (node positions / arcs may move during node optimization).
  std::shared_ptr<const Layout> layout;
  //! Parameterization, uv per corner (size 3·#F, corner k of face f at 3f+k), empty if none.
  std::vector<std::array<float, 2>> corner_uv;
  //! Per face (size #F or empty): 1 where the parameterization folds over (det <= 0).
  std::vector<char> face_foldover;
  //! Validation of `layout` at this step.
  std::vector<LayoutIssue> issues;
  //! Pinned node targets the job used at this step: (node id, vertex).
  std::vector<std::array<int, 2>> pins;
};

using SnapshotPtr = std::shared_ptr<const Snapshot>;

}  // namespace qs
