// quadsketch-cli optimize: field → parameterization → (node optimization) → extraction.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>

#include "app/cli/commands.h"
#include "app/cli/report.h"
#include "core/extract/quads.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"

namespace qs::cli {

namespace {

// Progress lines on stderr, one per node optimization step.
class ProgressPrinter : public Observer {
 public:
  explicit ProgressPrinter(bool quiet) : quiet_(quiet) {}
  void on_step(const StepReport& r) override {
    if (quiet_) return;
    std::cerr << "node optimization [" << r.phase << "] step " << r.step << ": E = " << r.E
              << (r.accepted ? " (accepted)" : " (rejected)") << ", alpha = " << r.step_size
              << ", moved nodes = " << r.moved_nodes << ", fold-overs = " << r.foldovers << ", "
              << r.time_s << " s\n";
  }

 private:
  bool quiet_;
};

}  // namespace

int run_optimize(const OptimizeOptions& o, const CommonOptions& common) {
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
    // Node optimization first (it runs its own field + parameterization solves); the final
    // stages below then run on its result.
    double node_s = 0;
    std::optional<NodeOptResult> node_result;
    if (!o.no_node_opt) {
      t0 = std::chrono::steady_clock::now();
      ProgressPrinter printer(common.quiet);
      if (o.discrete_relocation) {
        DiscreteOptions d;
        d.max_steps = o.steps;
        node_result = relocate_nodes_discrete(mesh, layout, options, d, &printer);
      } else {
        NodeOptOptions no;
        no.max_steps = o.steps;
        no.gradient = o.gradient == "exact" ? GradientMethod::Exact : GradientMethod::Estimator;
        node_result = optimize_nodes(mesh, layout, options, no, &printer);
      }
      mesh = node_result->mesh;
      layout = node_result->layout;
      options.param.face_weights = node_result->face_weights;
      node_s = seconds_since(t0);
    }
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
    const double E_final = unweighted_energy(pipeline.mesh(), pipeline.geometry(), field.theta,
                                             param.corner_uv, options.param);
    report["E_init"] = node_result ? node_result->E_init : E_final;
    report["E_final"] = E_final;
    report["steps"] = nlohmann::json::array();
    if (node_result) {
      for (const StepReport& r : node_result->reports) {
        if (r.phase == "initial") continue;
        report["steps"].push_back({{"step", r.step},
                                   {"E", r.E},
                                   {"accepted", r.accepted},
                                   {"step_size", r.step_size},
                                   {"time_s", r.time_s},
                                   {"foldovers", r.foldovers},
                                   {"phase", r.phase},
                                   {"moved_nodes", r.moved_nodes}});
      }
      report["node_optimization"] = {{"method", o.discrete_relocation ? "discrete" : o.gradient},
                                     {"steps", node_result->steps},
                                     {"accepted", node_result->accepted},
                                     {"halvings", node_result->halvings},
                                     {"foldovers_init", node_result->foldovers_init},
                                     {"foldovers_descent", node_result->foldovers_descent},
                                     {"E_descent", node_result->E_descent},
                                     {"stiffening_iterations", node_result->stiffening_iterations},
                                     {"stiffened", !node_result->face_weights.empty()}};
    }
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
    if (o.quad_size > 0 || o.quad_count > 0) {  // quad mesh export (issue #8)
      QuadMeshOptions qo;
      qo.quad_size = o.quad_size;
      qo.quad_count = o.quad_count;
      const QuadMesh quads = build_quad_mesh(pipeline, ex, qo);
      write_quad_exports(quads, pipeline.output_layout(), ex, out.string());
      report["quads"] = {{"quad_size", quads.quad_size},
                         {"vertices", quads.vertices.size()},
                         {"quads", quads.quads.size()},
                         {"patches", quads.gridded_patches()},
                         {"warnings", quads.warnings}};
      for (const auto& w : quads.warnings) std::cerr << "warning: quads: " << w << "\n";
      if (!common.quiet)
        std::cerr << "optimize: quad mesh " << quads.quads.size() << " quads (quad size "
                  << quads.quad_size << "); wrote quads.obj, patches.json, layout_curves.obj\n";
    }
    report["timings_s"] = {{"load", load_s},
                           {"field", field_s},
                           {"parameterization", param_s},
                           {"node_optimization", node_s},
                           {"extraction", extract_s},
                           {"total", seconds_since(t_total)},
                           {"param_setup", param.timings.setup_s},
                           {"param_assemble", param.timings.assemble_s},
                           {"param_analyze", param.timings.analyze_s},
                           {"param_factorize", param.timings.factorize_s},
                           {"param_solve", param.timings.solve_s}};
    if (!common.quiet) {
      std::cerr << "optimize: E = " << E_final << ", E_confor = " << m.E_confor
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
