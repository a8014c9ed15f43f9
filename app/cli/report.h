// Helpers shared by the quadsketch-cli subcommands: timing, report.json writing.
#pragma once

#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>

#include "app/cli/activity.h"
#include "app/cli/signals.h"
#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/base/timing.h"
#include "core/field/cross_field.h"
#include "core/layout/layout.h"
#include "core/layout/layout_input.h"
#include "core/mesh/mesh_io.h"

namespace qs::cli {

//! Loads a mesh for a command that writes no report: its warnings go to stderr, prefixed by
//! the file name. \throw InvalidInputError as load_mesh.
inline TriMesh load_mesh_printing_warnings(const std::string& path) {
  set_activity("loading the mesh '" + path + "'");
  MeshReport report;
  TriMesh mesh = load_mesh(path, &report);
  for (const auto& w : report.warnings) std::cerr << "warning: " << path << ": " << w << "\n";
  return mesh;
}

inline nlohmann::json mesh_json(const MeshReport& r) {
  return {{"vertices", r.vertices},
          {"faces", r.faces},
          {"genus", r.genus},
          {"boundaries", r.boundary_loops}};
}

//! The mesh the pipeline ran on: the input mesh, or a working mesh refined from it to carry
//! the layout (load_layout_on_surface), with its size relative to the input.
inline nlohmann::json working_mesh_json(const SurfaceLayout& s) {
  nlohmann::json j = {
      {"refined", s.on_working_mesh},
      {"vertices", s.mesh.n_vertices()},
      {"faces", s.mesh.n_faces()},
      {"growth", s.input_faces > 0 ? double(s.mesh.n_faces()) / s.input_faces : 1.0}};
  if (s.on_working_mesh) {
    j["inserted_nodes"] = s.embed.inserted_nodes;
    j["snapped_nodes"] = s.embed.snapped_nodes;
    j["route_splits"] = s.embed.route_splits;
    j["separation_splits"] = s.embed.separation_splits;
    j["flips"] = s.embed.flips;
  }
  return j;
}

//! Loads the layout of a command for \p input (load_layout_on_surface), announcing it.
inline SurfaceLayout load_command_layout(const std::string& path, TriMesh input) {
  set_activity("loading the layout '" + path + "'");
  return load_layout_on_surface(path, std::move(input));
}

//! Loads the mesh and the layout of a command (load_mesh, then load_command_layout), announcing
//! each, and records their "mesh" and "working_mesh" blocks in \p report.
inline SurfaceLayout load_command_inputs(const std::string& mesh_path,
                                         const std::string& layout_path, nlohmann::json& report) {
  MeshReport mesh_report;
  set_activity("loading the mesh '" + mesh_path + "'");
  SurfaceLayout on_surface = load_command_layout(layout_path, load_mesh(mesh_path, &mesh_report));
  report["mesh"] = mesh_json(mesh_report);
  report["working_mesh"] = working_mesh_json(on_surface);
  return on_surface;
}

inline nlohmann::json layout_json(const LayoutTopology& topo) {
  int irregular = 0;
  for (int v : topo.valence) irregular += (v != 4);
  return {{"nodes", topo.num_nodes},
          {"arcs", topo.num_arcs},
          {"patches", topo.patches.size()},
          {"irregular_nodes", irregular}};
}

//! The field's direction constraints: faces per kind, clusters, and what is still in force
//! after the clusters that contradict the layout were released.
inline nlohmann::json constraints_json(const CrossField& field) {
  const ConstraintSummary s = summarize_constraints(field);
  return {{"curvature", s.constrained[0]},
          {"feature", s.constrained[1]},
          {"boundary", s.constrained[2]},
          {"clusters", s.clusters},
          {"dropped_clusters", s.dropped_clusters},
          {"in_force",
           {{"curvature", s.in_force[0]},
            {"feature", s.in_force[1]},
            {"boundary", s.in_force[2]},
            {"total", s.total_in_force()}}}};
}

//! Prints released_constraints_warning (when there is one) to stderr, prefixed by \p command.
//! \return whether it printed one.
inline bool warn_about_released_constraints(const CrossField& field, const std::string& command) {
  const std::string w = released_constraints_warning(field);
  if (!w.empty()) std::cerr << "warning: " << command << ": " << w << "\n";
  return !w.empty();
}

//! Runs a command that writes into an output folder: the folder is created and checked for
//! writability first (require_writable_folder, before \p body computes anything), report.json
//! is written also on failure, with "status": "failed" and the message (failure_message),
//! before the error propagates. On SIGINT/SIGTERM (signals.h) the status is "cancelled" and
//! qs::Cancelled propagates (exit code 128 + signal); a stage that does not poll for
//! cancellation is stopped by a CancelWatchdog.
template <typename Body>
int with_report(const std::string& out_dir, Body&& body) {
  require_writable_folder(out_dir);
  // Temporary files of an earlier run that was killed outright (SIGKILL, power loss).
  remove_atomic_write_leftovers(out_dir);
  const std::string report_path = (std::filesystem::path(out_dir) / "report.json").string();
  nlohmann::json report;
  std::optional<CancelWatchdog> watchdog(std::in_place, out_dir);
  try {
    cancellation_point();
    body(report);
    watchdog.reset();
    cancellation_point();
    report["status"] = "ok";
    write_file_atomic(report_path, report.dump(2) + "\n");
    return 0;
  } catch (const Cancelled&) {
    watchdog.reset();  // the report below is the last write
    report["status"] = "cancelled";
    report["signal"] = signal_name(received_signal());
    report["message"] = "interrupted by " + signal_name(received_signal());
    try {
      write_file_atomic(report_path, report.dump(2) + "\n");
    } catch (...) {
    }
    throw;
  } catch (const std::exception& e) {
    watchdog.reset();
    report["status"] = "failed";
    report["message"] = failure_message(e);
    try {
      write_file_atomic(report_path, report.dump(2) + "\n");
    } catch (...) {
    }
    throw;
  }
}

}  // namespace qs::cli
