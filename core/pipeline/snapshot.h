// Immutable state of the pipeline worker at one step, published to the UI (docs/design.md,
// "Editor and worker"). A Snapshot is built by the worker outside any lock, then shared as
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

//! Quality metrics and stage timings of one step (computed on the worker). NaN: not measured.
struct StepMetrics {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  bool valid = false;  //!< false: no metrics for this step (keep the previous ones)
  double E = kNaN;     //!< energy (1) residual
  double E_confor = kNaN;
  double E_angle_deg = kNaN;  //!< E°
  double E_planar = kNaN;
  int foldovers = 0;
  // Wall-clock milliseconds per stage of the step.
  double nodeopt_ms = kNaN;  //!< node-optimization descent step (NaN on the initial solve)
  double field_ms = kNaN;
  double param_ms = kNaN;
  double extract_ms = kNaN;
  double metrics_ms = kNaN;
  double quads_ms = kNaN;  //!< quad-mesh build (NaN when not built in this step)
  double total_ms = kNaN;
};

//! Node positions (3D, on the job's surface) after one step; ids and positions are parallel.
struct NodeFrame {
  std::vector<int> ids;
  std::vector<std::array<float, 3>> positions;
};

//! A quad mesh built on the worker, for drawing as a line overlay.
struct QuadOverlay {
  double quad_size = 0;  //!< q used
  std::vector<std::array<float, 3>> vertices;
  std::vector<std::array<int, 4>> quads;
  int gridded_patches = 0;
  int patches = 0;
  std::vector<std::string> warnings;
};

//! The cross field of one step, for display (glyphs and constraint faces).
struct FieldView {
  //! Per face (size #F): the field's first direction (unit, in the face plane of the job's
  //! surface); the second is its 90° rotation about the face normal.
  std::vector<std::array<float, 3>> direction;
  //! Faces with a direction constraint (reliable curvature, feature or boundary), parallel
  //! arrays: face index, constrained direction (unit), kind (ConstraintKind value: 0 curvature,
  //! 1 feature, 2 boundary), whether it is in force.
  std::vector<int> constraint_faces;
  std::vector<std::array<float, 3>> constraint_direction;
  std::vector<char> constraint_kind;
  //! Parallel to constraint_faces: 1 when the constraint is in force, 0 when its cluster was
  //! released as contradicting the layout's topology (the field ignores it).
  std::vector<char> constraint_in_force;
  int in_force = 0;          //!< number of 1s in constraint_in_force
  int clusters = 0;          //!< constraint clusters
  int dropped_clusters = 0;  //!< clusters released (none of their constraints in force)
  //! released_constraints_warning of the field (empty when most constraints are in force).
  std::string warning;
};

//! Immutable job data the exporters need (core/pipeline/job_exports.h, filled by the job's step
//! function); the worker only passes the pointer along.
struct JobExports;

struct Snapshot {
  std::uint64_t version = 0;      //!< publication counter (strictly increasing)
  std::uint64_t generation = 0;   //!< job generation this state belongs to
  std::uint64_t applied_seq = 0;  //!< every command with seq <= applied_seq is reflected here
  WorkerStatus status = WorkerStatus::Idle;
  std::string message;  //!< status line or failure message
  int iteration = 0;    //!< steps done in the current job
  double energy = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> energy_history;  //!< energy per step of the current job
  double energy_init = std::numeric_limits<double>::quiet_NaN();  //!< E of the first step

  //! Metrics and timings of the latest step that measured them.
  StepMetrics metrics;
  //! Node positions per step of the current job (index = step - 1); entries are shared.
  std::vector<std::shared_ptr<const NodeFrame>> node_history;
  //! Quad mesh of the current job (null until a step built one).
  std::shared_ptr<const QuadOverlay> quads;
  //! Data for the exporters (null until a step provided it).
  std::shared_ptr<const JobExports> exports;
  //! Cross field of the latest step that solved one (null until then).
  std::shared_ptr<const FieldView> field;

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
