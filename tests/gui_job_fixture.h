// Shared setup of the GUI job tests (gui_job_test, gui_field_test): the bundled example and a
// worker run to its end. Needs app/gui/pipeline_job.cpp linked (tests/cmake/gui_smoke.cmake).
#pragma once

#include <chrono>
#include <filesystem>
#include <memory>

#include "app/gui/pipeline_job.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"

namespace qs::test {

//! The bundled example (assets/example): the ellipsoid mesh and its layout.
struct Example {
  std::shared_ptr<const TriMesh> mesh;
  Layout layout;
};

//! Loads the bundled example.
inline Example example() {
  const std::filesystem::path dir = std::filesystem::path(QS_ASSETS_DIR) / "example";
  auto mesh = std::make_shared<TriMesh>(load_mesh((dir / "ellipsoid.obj").string()));
  Layout layout = load_layout((dir / "ellipsoid.layout.json").string(), *mesh);
  return {mesh, std::move(layout)};
}

//! Runs a worker on \p ex with \p options (set as given) and returns its first snapshot that is
//! Finished or Failed (null after two minutes without one).
inline SnapshotPtr run_job(const Example& ex, const WorkerOptions& options) {
  using namespace std::chrono_literals;
  Worker worker(app::pipeline_step);
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{ex.mesh, ex.layout});
  worker.send(cmd::Run{});
  return worker.wait_for(
      [](const Snapshot& x) {
        return x.status == WorkerStatus::Finished || x.status == WorkerStatus::Failed;
      },
      120s);
}

}  // namespace qs::test
