#include "app/cli/commands.h"

#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/cli/report.h"
#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"

namespace qs::cli {

int run_validate(const ValidateOptions& o, const CommonOptions& common) {
  if (!o.out.empty()) require_writable_folder(o.out);
  set_activity("loading the mesh '" + o.mesh + "'");
  MeshReport report;
  TriMesh input = load_mesh(o.mesh, &report);
  for (const auto& w : report.warnings) std::cerr << "warning: " << o.mesh << ": " << w << "\n";
  const SurfaceLayout on_surface = load_command_layout(o.layout, std::move(input));
  const TriMesh& mesh = on_surface.mesh;
  const Layout& layout = on_surface.layout;
  set_activity("validating the layout '" + o.layout + "'");
  const ValidationResult result = validate_layout(mesh, layout);
  set_activity("reporting the issues of the layout '" + o.layout + "'");
  for (const auto& issue : result.issues)
    std::cerr << o.layout << ": " << format_issue(issue) << "\n";

  nlohmann::json out = {{"status", result.valid() ? "ok" : "invalid"},
                        {"mesh", mesh_json(report)},
                        {"working_mesh", working_mesh_json(on_surface)},
                        {"errors", result.errors()},
                        {"warnings", result.warnings()}};
  nlohmann::json issues = nlohmann::json::array();
  for (const auto& i : result.issues) {
    issues.push_back({{"severity", i.severity == IssueSeverity::Error ? "error" : "warning"},
                      {"code", i.code},
                      {"message", i.message},
                      {"nodes", i.node_ids},
                      {"arcs", i.arc_ids},
                      {"vertices", i.vertices}});
    if (i.omitted > 0) issues.back()["omitted"] = i.omitted;
  }
  out["issues"] = issues;
  if (result.valid()) {
    const LayoutTopology topo = build_topology(mesh, layout);
    int irregular = 0;
    for (int v : topo.valence) irregular += (v != 4);
    out["layout"] = {{"nodes", topo.num_nodes},
                     {"arcs", topo.num_arcs},
                     {"patches", topo.patches.size()},
                     {"irregular_nodes", irregular}};
    if (!common.quiet) {
      std::cout << "valid: " << o.layout << " on " << o.mesh << " (" << report.vertices
                << " vertices, " << report.faces << " faces, genus " << report.genus << ", "
                << report.boundary_loops << " boundary loops): " << topo.num_nodes << " nodes ("
                << irregular << " irregular), " << topo.num_arcs << " arcs, " << topo.patches.size()
                << " patches";
      if (result.warnings()) std::cout << ", " << result.warnings() << " warning(s)";
      std::cout << "\n";
    }
  } else {
    std::cerr << o.layout << ": invalid layout: " << result.errors() << " error(s)\n";
  }
  if (!o.out.empty()) {
    set_activity("writing " + o.out + "/report.json");
    write_file_atomic((std::filesystem::path(o.out) / "report.json").string(), out.dump(2) + "\n");
  }
  return result.valid() ? 0 : 2;
}

int run_field(const FieldOptions& o, const CommonOptions& common) {
  return with_report(o.out, [&](nlohmann::json& report) {
    const auto t_total = std::chrono::steady_clock::now();
    auto t0 = t_total;
    SurfaceLayout on_surface = load_command_inputs(o.mesh, o.layout, report);
    TriMesh mesh = std::move(on_surface.mesh);
    Layout layout = std::move(on_surface.layout);
    const double load_s = seconds_since(t0);
    PipelineOptions options;
    options.field.constraints.sharp_angle_deg = o.sharp_angle_deg;
    options.field.max_cluster_faces = o.max_cluster_faces;
    if (o.wrap_free_holes) options.field.free_loops = FreeLoopTurning::kWrap;
    set_activity("computing the cross field");
    Pipeline pipeline(std::move(mesh), std::move(layout), options);
    report["layout"] = layout_json(pipeline.topology());
    t0 = std::chrono::steady_clock::now();
    const CrossField& field = pipeline.compute_field();
    const double field_s = seconds_since(t0);
    nlohmann::json singularities = nlohmann::json::array();
    for (const auto& s : pipeline.singularities())
      singularities.push_back({{"vertex", s.vertex}, {"index", s.quarter_index / 4.0}});
    report["singularities"] = singularities;
    report["constraints"] = constraints_json(field);
    warn_about_released_constraints(field, "field");
    report["period_jumps"] = {{"free_unknowns", field.topology.free_unknowns},
                              {"layout_cycles", field.topology.cycles},
                              {"max_abs", field.topology.max_abs_jump}};
    set_activity("writing " + o.out + "/field.txt");
    write_field_txt(pipeline.geometry(), field.theta,
                    (std::filesystem::path(o.out) / "field.txt").string());
    report["timings_s"] = {{"load", load_s},
                           {"field", field_s},
                           {"curvature", field.timings.curvature_s},
                           {"period_jumps", field.timings.period_jumps_s},
                           {"assemble", field.timings.assemble_s},
                           {"factorize", field.timings.factorize_s},
                           {"solve", field.timings.solve_s},
                           {"total", seconds_since(t_total)}};
    if (!common.quiet) {
      std::cerr << "field: " << pipeline.singularities().size() << " singular vertices, "
                << field.constraints.face.size() << " constrained faces ("
                << field.active_constraints << " in force), " << field_s << " s; wrote " << o.out
                << "/field.txt and report.json\n";
    }
  });
}

}  // namespace qs::cli
