// What the exporters of a worker job need (param.obj, layout.json, quads.obj, patches.json,
// layout_curves.obj), frozen at one step and carried by the worker's snapshots
// (docs/design.md, "Editor and worker").
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "core/extract/quads.h"
#include "core/extract/tracing.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! What the exporters need, frozen at one step (immutable once published). A job's step
//! function fills it (StepResult::exports); the worker only passes the pointer along
//! (Snapshot::exports).
struct JobExports {
  TriMesh mesh;                                  //!< the job's surface (nodes may have moved it)
  std::vector<std::array<double, 2>> corner_uv;  //!< parameterization, one (u, v) per corner
  Layout layout;                                 //!< traced output layout
  Extraction extraction;                         //!< traced arcs
  std::shared_ptr<const QuadMesh> quads;         //!< null when no quad mesh was built
};

}  // namespace qs
