// quadsketch-cli optimize: field → parameterization → (node optimization) → extraction.
#include <chrono>
#include <filesystem>
#include <iostream>

#include "app/cli/commands.h"
#include "app/cli/report.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"

namespace qs::cli {

int run_optimize(const OptimizeOptions& o, const CommonOptions& common) {
  if (!o.no_node_opt) {
    std::cerr
        << "error: node optimization is not implemented yet (issue #5); run with --no-node-opt to "
           "compute the field, the parameterization and the embedding with the nodes fixed\n";
    return 1;
  }
  if (o.quad_size > 0) {
    std::cerr << "error: --quad-size (quad mesh export) is not implemented yet (issue #8)\n";
    return 1;
  }
  return with_report(o.out, [&](nlohmann::json& report) {
    namespace fs = std::filesystem;
    const auto t_total = std::chrono::steady_clock::now();
    auto t0 = t_total;
    MeshReport mesh_report;
    TriMesh mesh = load_mesh(o.mesh, &mesh_report);
    Layout layout = load_layout(o.layout, mesh);
    report["mesh"] = mesh_json(mesh_report);
    const double load_s = seconds_since(t0);
    PipelineOptions options;
    options.field.constraints.sharp_angle_deg = o.sharp_angle_deg;
    options.field.constraints.curvature = !o.no_align;
    Pipeline pipeline(std::move(mesh), std::move(layout), options);
    report["layout"] = layout_json(pipeline.topology());
    t0 = std::chrono::steady_clock::now();
    const CrossField& field = pipeline.compute_field();
    const double field_s = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const Parameterization& param = pipeline.compute_parameterization();
    const double param_s = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const Extraction& ex = pipeline.extract();
    const double extract_s = seconds_since(t0);
    const ParamMetrics m = pipeline.metrics();
    report["E_init"] = param.energy;
    report["E_final"] = param.energy;
    report["steps"] = nlohmann::json::array();
    report["metrics"] = {{"E_confor", m.E_confor},
                         {"E_planar", m.E_planar},
                         {"E_angle_deg", m.E_angle_deg},
                         {"foldovers", m.foldovers}};
    report["structurally_equivalent"] = ex.structurally_equivalent;
    report["extraction_problems"] = ex.problems;
    report["parameterization"] = {{"wedges", param.wedges},
                                  {"cut_edges", param.cut_edges},
                                  {"constraint_rows", param.constraint_rows},
                                  {"eliminated", param.eliminated},
                                  {"redundant", param.redundant},
                                  {"unknowns", param.unknowns},
                                  {"anisotropic", options.param.anisotropic},
                                  {"aligned", !o.no_align}};
    const fs::path out(o.out);
    write_param_obj(pipeline.mesh(), param.corner_uv, (out / "param.obj").string());
    write_field_txt(pipeline.geometry(), field.theta, (out / "field.txt").string());
    save_layout(pipeline.output_layout(), (out / "layout.json").string(), &pipeline.mesh());
    report["timings_s"] = {{"load", load_s},
                           {"field", field_s},
                           {"parameterization", param_s},
                           {"node_optimization", 0.0},
                           {"extraction", extract_s},
                           {"total", seconds_since(t_total)},
                           {"param_setup", param.timings.setup_s},
                           {"param_assemble", param.timings.assemble_s},
                           {"param_analyze", param.timings.analyze_s},
                           {"param_factorize", param.timings.factorize_s},
                           {"param_solve", param.timings.solve_s}};
    if (!common.quiet) {
      std::cerr << "optimize: E = " << param.energy << ", E_confor = " << m.E_confor
                << ", E° = " << m.E_angle_deg << " deg, fold-overs = " << m.foldovers
                << ", structurally equivalent: " << (ex.structurally_equivalent ? "yes" : "no")
                << "; wrote " << o.out << "/{report.json, param.obj, field.txt, layout.json}\n";
    }
    if (!ex.structurally_equivalent) {
      for (const auto& p : ex.problems) std::cerr << "warning: " << p << "\n";
    }
  });
}

}  // namespace qs::cli
