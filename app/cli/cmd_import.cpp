// quadsketch-cli import-quads and perturb (interfaces.md §2, issue #6).
#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/cli/commands.h"
#include "app/cli/report.h"
#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/import/perturb.h"
#include "core/import/quad_import.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/weld.h"

namespace qs::cli {

namespace {

nlohmann::json layout_counts(const TriMesh& mesh, const Layout& layout) {
  const LayoutTopology topo = build_topology(mesh, layout);
  int irregular = 0;
  for (int v : topo.valence) irregular += (v != 4);
  return {{"nodes", topo.num_nodes},
          {"arcs", topo.num_arcs},
          {"patches", topo.patches.size()},
          {"irregular_nodes", irregular}};
}

std::string ids_text(const std::vector<int>& ids, size_t max_count = 20) {
  std::string s;
  for (size_t i = 0; i < ids.size() && i < max_count; ++i)
    s += (i ? ", " : "") + std::to_string(ids[i]);
  if (ids.size() > max_count) s += ", ...";
  return s;
}

}  // namespace

int run_import_quads(const ImportQuadsOptions& o, const CommonOptions& common) {
  require_writable_folder(o.out);
  const std::string report_path = (std::filesystem::path(o.out) / "report.json").string();
  nlohmann::json report;
  try {
    const auto t_total = std::chrono::steady_clock::now();
    // Coincident vertices are welded first: a quad mesh exported per patch (each patch with
    // its own copies of its border vertices) is one surface again.
    set_activity("loading the quad mesh '" + o.quads + "'");
    const WeldedPolyMesh loaded = load_poly_mesh_welded(o.quads, kWeldTolerance);
    const PolyMesh& quads = loaded.mesh;
    for (const auto& w : loaded.report.warnings)
      std::cerr << "warning: " << o.quads << ": " << w << "\n";
    if (loaded.welded > 0 && !common.quiet) {
      std::cerr << "note: " << o.quads << ": welded " << loaded.welded
                << " coincident vertices (closer than " << kWeldTolerance
                << " x the bounding-box diagonal)";
      if (loaded.parts_before > 1)
        std::cerr << ", joining " << loaded.parts_before << " separate parts";
      std::cerr << "\n";
    }
    TriMesh target;
    MeshReport target_report;
    if (!o.onto.empty()) {
      set_activity("loading the target mesh '" + o.onto + "'");
      target = load_mesh(o.onto, &target_report);
      for (const auto& w : target_report.warnings)
        std::cerr << "warning: " << o.onto << ": " << w << "\n";
    }
    const double load_s = seconds_since(t_total);

    QuadImportOptions options;
    options.all_edges = o.all_edges;
    options.refine = o.refine;
    options.coarsen = o.coarsen;
    const auto t_import = std::chrono::steady_clock::now();
    set_activity("importing the quad mesh '" + o.quads + "'");
    const QuadImportResult result =
        import_quads(quads, o.onto.empty() ? nullptr : &target, options);
    const double import_s = seconds_since(t_import);
    for (const auto& w : result.warnings) std::cerr << "warning: " << o.quads << ": " << w << "\n";

    set_activity("writing " + o.out + "/mesh.obj and layout.json");
    save_mesh_obj(result.mesh, (std::filesystem::path(o.out) / "mesh.obj").string());
    save_layout(result.layout, (std::filesystem::path(o.out) / "layout.json").string(),
                &result.mesh);

    MeshReport out_report;
    count_topology(result.mesh, out_report);
    report["mesh"] = {{"vertices", out_report.vertices},
                      {"faces", out_report.faces},
                      {"genus", out_report.genus},
                      {"boundaries", out_report.boundary_loops}};
    report["layout"] = layout_counts(result.mesh, result.layout);
    report["quads"] = {{"vertices", result.quads.n_vertices()},
                       {"welded_vertices", loaded.welded},
                       {"faces", result.quads.n_faces()},
                       {"irregular_vertices", result.complex.irregular_vertices},
                       {"split", result.split},
                       {"base_complex_patches", result.coarsen.patches_before}};
    if (o.coarsen > 0) {
      report["coarsen"] = {{"width", o.coarsen},
                           {"chords_collapsed", result.coarsen.chords_collapsed},
                           {"before",
                            {{"nodes", result.coarsen.nodes_before},
                             {"arcs", result.coarsen.arcs_before},
                             {"patches", result.coarsen.patches_before}}},
                           {"after",
                            {{"nodes", result.coarsen.nodes_after},
                             {"arcs", result.coarsen.arcs_after},
                             {"patches", result.coarsen.patches_after}}}};
    }
    if (result.working) {
      const TransferStats& t = result.transfer;
      report["transfer"] = {
          {"input", {{"vertices", t.input_vertices}, {"faces", t.input_faces}}},
          {"working_mesh", {{"vertices", t.working_vertices}, {"faces", t.working_faces}}},
          {"growth", t.growth},
          {"min_angle_deg", t.min_angle_deg},
          {"subdivision_levels", t.levels},
          {"dense", {{"vertices", t.dense_vertices}, {"faces", t.dense_faces}}},
          {"max_offset", t.max_offset},
          {"flow_steps", t.flow_steps},
          {"relaxed_vertices", t.relaxed_vertices},
          {"reversed", t.reversed}};
    }
    report["timings_s"] = {
        {"load", load_s}, {"import", import_s}, {"total", seconds_since(t_total)}};
    report["status"] = "ok";
    write_file_atomic(report_path, report.dump(2) + "\n");
    if (!common.quiet && o.coarsen > 0) {
      std::cerr << "import-quads: coarsened the base complex from " << result.coarsen.nodes_before
                << " nodes / " << result.coarsen.arcs_before << " arcs / "
                << result.coarsen.patches_before << " patches to " << result.coarsen.nodes_after
                << " / " << result.coarsen.arcs_after << " / " << result.coarsen.patches_after
                << " (" << result.coarsen.chords_collapsed << " chords collapsed)\n";
    }
    if (!common.quiet) {
      std::cerr << "import-quads: " << report["layout"]["nodes"] << " nodes ("
                << report["layout"]["irregular_nodes"] << " irregular), "
                << report["layout"]["arcs"] << " arcs, " << report["layout"]["patches"]
                << " patches on " << result.mesh.n_vertices() << " vertices / "
                << result.mesh.n_faces() << " faces";
      if (result.working) {
        std::ostringstream growth;
        growth.precision(3);
        growth << result.transfer.growth;
        std::cerr << " (the working mesh of "
                  << (o.onto.empty() ? "the triangulated quad mesh's " : "the target's ")
                  << result.transfer.input_vertices << " vertices / " << result.transfer.input_faces
                  << " faces, growth " << growth.str() << "x)";
      }
      std::cerr << ", " << seconds_since(t_total) << " s; wrote " << o.out
                << "/mesh.obj and layout.json\n";
    }
    return 0;
  } catch (const std::exception& e) {
    report["status"] = "failed";
    report["message"] = failure_message(e);
    try {
      write_file_atomic(report_path, report.dump(2) + "\n");
    } catch (...) {
    }
    throw;
  }
}

int run_perturb(const PerturbOptions& o, const CommonOptions& common) {
  const auto t0 = std::chrono::steady_clock::now();
  require_writable_file(o.out);
  const TriMesh mesh = load_mesh_printing_warnings(o.mesh);
  set_activity("loading the layout '" + o.layout + "'");
  const Layout layout = load_layout(o.layout, mesh);
  PerturbLayoutOptions options;
  options.rings = o.rings;
  options.seed = o.seed;
  // perturb_layout validates its result (the checks load_layout applies) before it is written.
  set_activity("perturbing the layout");
  const PerturbResult result = perturb_layout(mesh, layout, options);
  set_activity("writing " + o.out);
  save_layout(result.layout, o.out, &mesh);
  if (!result.stuck_nodes.empty()) {
    std::cerr << "warning: " << result.stuck_nodes.size()
              << " node(s) could not move without breaking the layout and stayed in place: "
              << ids_text(result.stuck_nodes) << "\n";
  }
  if (!common.quiet) {
    std::cerr << "perturb: moved " << result.moved_nodes.size() << " of " << layout.nodes.size()
              << " nodes by " << o.rings << " ring(s) (seed " << o.seed << "), "
              << result.pinned_nodes.size() << " pinned, " << result.stuck_nodes.size()
              << " stuck, " << seconds_since(t0) << " s; wrote " << o.out << "\n";
  }
  return 0;
}

}  // namespace qs::cli
