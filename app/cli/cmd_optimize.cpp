// quadsketch-cli optimize: field → parameterization → (node optimization) → extraction.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli/commands.h"
#include "app/cli/report.h"
#include "app/cli/signals.h"
#include "core/base/solver_threads.h"
#include "core/engine/optimize.h"
#include "core/extract/quads.h"
#include "core/layout/layout_io.h"
#include "core/layout/symmetry.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/symmetric_step.h"
#include "core/pipeline/integer_sizes.h"
#include "core/pipeline/pipeline.h"

namespace qs::cli {

namespace {

// Progress lines on stderr, one per node optimization step. Forwards SIGINT/SIGTERM: the
// optimizer stops at its next poll (between solves) instead of waiting for the watchdog.
class ProgressPrinter : public Observer {
 public:
  explicit ProgressPrinter(bool quiet) : quiet_(quiet) {}
  bool should_cancel() const override { return cancel_requested(); }
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

// The report's account of one orientation-constrained solve.
nlohmann::json orientation_json(const OrientationReport& r) {
  return {{"ran", r.ran},
          {"success", r.success},
          {"constrained_faces", r.constrained_faces},
          {"all_faces", r.all_faces},
          {"rounds", r.rounds},
          {"iterations", r.iterations},
          {"time_s", r.time_s},
          {"sector_frame", r.sector_frame == SectorFrame::kSolution ? "solution" : "field"},
          {"message", r.message},
          {"infeasible_faces", r.infeasible_faces},
          {"untangle",
           {{"ran", r.untangle.ran},
            {"foldovers_before", r.untangle.foldovers_before},
            {"foldovers_after", r.untangle.foldovers_after},
            {"newton_steps", r.untangle.newton_steps},
            {"rounds", r.untangle.rounds},
            {"time_s", r.untangle.time_s}}}};
}

// When fold-overs remain (\p foldovers_left) after orientation constraints that were
// infeasible, a warning that names the nodes of the written layout next to the faces the
// constraints could not unfold: where to look at (or edit) the layout.
void warn_about_infeasible_orientation(const OrientationReport& r, int foldovers_left,
                                       const TriMesh& mesh, const Layout& layout) {
  if (foldovers_left <= 0 || !r.ran || r.infeasible_faces.empty()) return;
  const std::vector<int> near = nodes_near_faces(mesh, layout, r.infeasible_faces);
  std::cerr << "warning: " << foldovers_left << " fold-over(s) remain";
  if (!near.empty())
    std::cerr << "; the layout cannot be unfolded near " << describe_nodes(layout, near);
  std::cerr << ": " << r.message << "\n";
}

// Refuses a quad size that would give more than kMaxQuads quads. \p quads: the count, found as
// \p basis says.
void require_quad_count_within_limit(double quads, double quad_size, const std::string& basis) {
  if (quads <= static_cast<double>(kMaxQuads)) return;
  std::ostringstream os;
  os << std::setprecision(3) << "--quad-size " << quad_size << " would make " << quads << " quads ("
     << basis << "), more than the limit of " << kMaxQuads << "; use a --quad-size of at least "
     << quad_size * std::sqrt(quads / static_cast<double>(kMaxQuads)) << " (or --quad-count)";
  throw InvalidInputError(os.str());
}

// Total area of the mesh's faces (length²).
// The report's account of one retry of the node optimization.
nlohmann::json retry_json(const RetryRecord& r) {
  return {{"foldovers_without", r.foldovers_without},
          {"E_final_without", r.E_without},
          {"foldovers_with", r.foldovers_with},
          {"E_final_with", r.E_with},
          {"untangled_without", r.untangled_without},
          {"untangled_with", r.untangled_with},
          {"used", r.used},
          {"time_s", r.time_s}};
}

// The engine settings that the flags of `optimize` mean.
OptimizeSettings optimize_settings(const OptimizeOptions& o) {
  OptimizeSettings s;
  s.field.align = !o.no_align;
  s.field.sharp_angle_deg = o.sharp_angle_deg;
  s.field.max_cluster_faces = o.max_cluster_faces;
  s.field.wrap_free_holes = o.wrap_free_holes;
  s.param.sizing = o.sizing;
  s.nodes.enabled = !o.no_node_opt;
  s.nodes.steps = o.steps;
  s.nodes.method = o.discrete_relocation   ? NodeMethod::kDiscrete
                   : o.gradient == "exact" ? NodeMethod::kExact
                                           : NodeMethod::kEstimator;
  s.nodes.slide_on_curves = !o.no_sliding;
  s.nodes.keep_sharp_edges = o.keep_sharp_edges;
  s.nodes.keep_apart = o.keep_nodes_apart;
  s.nodes.separate_crowded = o.separate_nodes;
  s.nodes.time_limit_s = o.time_limit_s;
  if (!o.symmetry.empty()) s.nodes.symmetry = parse_symmetry_axis(o.symmetry);
  if (o.no_orientation) s.folds.remove = false;
  if (o.orientation) s.folds.remove = true;
  s.folds.sectors = o.orientation_sectors == "field"      ? SectorFrame::kField
                    : o.orientation_sectors == "solution" ? SectorFrame::kSolution
                                                          : SectorFrame::kFieldThenSolution;
  s.folds.untangle = !o.no_untangle;
  s.sizes.integer = o.integer;
  s.sizes.quad_size = o.quad_size;
  s.sizes.quad_count = o.quad_count;
  return s;
}

double surface_area(const TriMesh& mesh) {
  double area = 0;
  for (const auto f : mesh.faces()) area += mesh.calc_face_area(f);
  return area;
}

}  // namespace

int run_optimize(const OptimizeOptions& o, const CommonOptions& common) {
  set_solver_threads(o.threads);
  return with_report(o.out, [&](nlohmann::json& report) {
    namespace fs = std::filesystem;
    const auto t_total = std::chrono::steady_clock::now();
    auto t0 = t_total;
    SurfaceLayout on_surface = load_command_inputs(o.mesh, o.layout, report);
    TriMesh mesh = std::move(on_surface.mesh);
    Layout layout = std::move(on_surface.layout);
    // A parameterization close to isometric has about the surface's area: refuse an absurd
    // quad size now rather than after the whole optimization.
    if (o.quad_size > 0) {
      const double area = surface_area(mesh);
      std::ostringstream basis;
      basis << std::setprecision(3) << "estimated: surface area " << area << " / quad size²";
      require_quad_count_within_limit(area / (o.quad_size * o.quad_size), o.quad_size, basis.str());
    }
    const double load_s = seconds_since(t0);
    if (o.integer && !(o.quad_size > 0 || o.quad_count > 0))
      throw InvalidInputError("--integer needs --quad-size Q or --quad-count N");
    if (o.atlas != "per-patch" && !(o.quad_size > 0 || o.quad_count > 0))
      throw InvalidInputError("--atlas needs --quad-size Q or --quad-count N");
    if (o.orientation && !o.no_node_opt)
      throw InvalidInputError(
          "--orientation applies to --no-node-opt runs (the node optimization removes "
          "fold-overs with orientation constraints by default; --no-orientation turns that off)");
    if (o.time_limit_s > 0 && o.no_node_opt)
      throw InvalidInputError("--time-limit applies to the node optimization (not --no-node-opt)");
    if (o.separate_nodes && (o.no_node_opt || o.discrete_relocation))
      throw InvalidInputError(
          "--separate-nodes applies to the continuous node optimization (not --no-node-opt or "
          "--discrete-relocation)");
    if (o.orientation && o.no_orientation)
      throw InvalidInputError("--orientation and --no-orientation contradict each other");
    if (!o.symmetry.empty() && (o.no_node_opt || o.discrete_relocation || o.separate_nodes))
      throw InvalidInputError(
          "--symmetry applies to the continuous node optimization (not --no-node-opt, "
          "--discrete-relocation or --separate-nodes)");
    // The whole policy (node optimization, retries, integer sizes) is the engine's
    // (core/engine/optimize.h), the same that the editor's Run drives step by step.
    const OptimizeSettings settings = optimize_settings(o);
    ProgressPrinter printer(common.quiet);
    const auto print_notes = [&](OptimizeRun& run) {
      for (const std::string& note : run.take_notes())
        if (!common.quiet) std::cerr << "optimize: " << note << "\n";
    };
    if (!o.no_node_opt) set_activity("optimizing the nodes");
    OptimizeRun run(std::move(mesh), std::move(layout), settings, &printer);
    // The initial solve reports a layout that contradicts the curvature before the long run.
    bool warned_about_constraints = false;
    if (!o.no_node_opt && !o.discrete_relocation)
      warned_about_constraints = warn_about_released_constraints(*run.pipeline(&printer)->field(),
                                                                 "optimize (initial field)");
    while (run.step(&printer)) print_notes(run);
    OptimizeResult result = run.finish(&printer);
    print_notes(run);
    const PipelineOptions& options = result.options;
    const std::optional<NodeOptResult>& node_result = result.nodes;
    const std::optional<NodeOptResult>& relaxed_result = result.relaxed;
    const std::optional<IntegerSizes>& integer = result.integer;
    const double E_relaxed = result.E_relaxed;
    const double node_s = result.node_time_s;
    std::shared_ptr<Pipeline> solved = result.pipeline;
    Pipeline& pipeline = *solved;
    set_activity("computing the final field, parameterization and extraction");
    report["layout"] = layout_json(pipeline.topology());
    t0 = std::chrono::steady_clock::now();
    const CrossField& field = pipeline.field() ? *pipeline.field() : pipeline.compute_field();
    const double field_s = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const Parameterization& param = pipeline.parameterization()
                                        ? *pipeline.parameterization()
                                        : pipeline.compute_parameterization();
    const double param_s = seconds_since(t0);
    t0 = std::chrono::steady_clock::now();
    const Extraction& ex = pipeline.extract();
    const double extract_s = seconds_since(t0);
    const ParamMetrics m = pipeline.metrics();
    const double E_final =
        unweighted_energy(pipeline.mesh(), pipeline.geometry(), field.theta, param, options.param);
    report["E_init"] = relaxed_result            ? relaxed_result->E_init
                       : integer && !node_result ? E_relaxed
                       : node_result             ? node_result->E_init
                                                 : E_final;
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
      const bool time_limited = result.time_limited;
      if (time_limited && !common.quiet)
        std::cerr << "optimize: the time limit (" << o.time_limit_s
                  << " s) ended the node movement after " << node_result->steps
                  << " step(s); the run finishes from the state reached\n";
      report["node_optimization"] = {
          {"method", o.discrete_relocation ? "discrete" : o.gradient},
          {"steps", node_result->steps},
          {"accepted", node_result->accepted},
          {"halvings", node_result->halvings},
          {"sliding_nodes", node_result->sliding_nodes},
          {"foldovers_init", node_result->foldovers_init},
          {"foldovers_descent", node_result->foldovers_descent},
          {"E_descent", node_result->E_descent},
          {"stiffening_iterations", node_result->stiffening_iterations},
          {"stiffened", !node_result->face_weights.empty()},
          {"foldovers_before_orientation", node_result->foldovers_descent},
          {"foldovers_final", node_result->foldovers_final},
          {"fold_removal", node_result->orientation_constraints ? "orientation"
                           : !node_result->face_weights.empty() ? "stiffening"
                                                                : "none"},
          {"orientation", orientation_json(node_result->orientation)},
          {"time_limited", time_limited},
          {"polish_reverted", node_result->polish_reverted},
          {"fewest_foldovers_reverted", node_result->fewest_foldovers_reverted},
          {"initial_reverted", node_result->initial_reverted},
          {"untangled", node_result->untangled},
          {"fold_free_reverted", node_result->fold_free_reverted},
          {"keep_nodes_apart", result.keep_nodes_apart},
          {"crowded_nodes", node_result->crowded_nodes},
          {"separated_nodes", node_result->separated_nodes}};
      if (result.keep_apart_retry) {
        nlohmann::json& j = report["node_optimization"]["keep_apart_retry"];
        j = retry_json(*result.keep_apart_retry);
        j["fell_back_without"] = result.keep_apart_retry->fell_back_without;
      }
      if (result.sizing_retry) {
        nlohmann::json& j = report["node_optimization"]["sizing_retry"];
        j = retry_json(*result.sizing_retry);
        j["initial_without"] = result.sizing_retry->initial_without;
        j["initial_with"] = result.sizing_retry->initial_with;
      }
      warn_about_infeasible_orientation(node_result->orientation, param.foldovers, pipeline.mesh(),
                                        pipeline.layout());
    }
    if (result.symmetry) {  // measured on the written state
      const NodeSymmetry& sym = *result.symmetry;
      const NodeSymmetryMeasure sm = measure_node_symmetry(pipeline.mesh(), pipeline.layout(), sym);
      const MirrorPlane& p = sym.plane;
      report["symmetry"] = {{"plane",
                             {{"axis", o.symmetry},
                              {"normal", {p.normal[0], p.normal[1], p.normal[2]}},
                              {"offset", p.offset}}},
                            {"pairs", sm.pairs},
                            {"plane_nodes", sm.plane_nodes},
                            {"max_pair_error", sm.max_pair_error},
                            {"max_plane_error", sm.max_plane_error}};
      if (!common.quiet)
        std::cerr << "optimize: symmetric about the plane " << describe_plane(p) << ": " << sm.pairs
                  << " mirror pair(s), " << sm.plane_nodes
                  << " node(s) on the plane, largest error "
                  << std::max(sm.max_pair_error, sm.max_plane_error) << " of the diagonal\n";
    }
    if (o.orientation) {  // --no-node-opt --orientation
      const OrientationReport& r = param.orientation;
      report["fold_removal"] = {{"method", r.success ? "orientation" : "none"},
                                {"foldovers_before", r.ran ? r.foldovers_before : param.foldovers},
                                {"foldovers_after", param.foldovers},
                                {"orientation", orientation_json(r)}};
      if (!common.quiet && r.ran)
        std::cerr << "optimize: orientation constraints: " << r.foldovers_before << " -> "
                  << param.foldovers << " fold-overs"
                  << (r.success ? "" : " (not used: " + r.message + ")") << "\n";
      warn_about_infeasible_orientation(r, param.foldovers, pipeline.mesh(), pipeline.layout());
    }
    if (integer) {
      double worst = 0;  // largest deviation of a patch side from a multiple of Q (relative)
      for (const auto& l : pipeline.param_solver()->arc_lengths()) {
        const double k = l.length / integer->quad_size;
        worst = std::max(worst, std::abs(k - std::round(k)));
      }
      report["integer"] = {{"quad_size", integer->quad_size},
                           {"arcs", integer->lengths.size()},
                           {"max_rounding_change", integer->max_change},
                           {"min_multiple", integer->min_multiple},
                           {"E_relaxed", E_relaxed},
                           {"E_integer", E_final},
                           {"max_deviation_from_integer", worst}};
      if (relaxed_result)
        report["integer"]["relaxed_node_optimization"] = {{"steps", relaxed_result->steps},
                                                          {"E_final", relaxed_result->E_final}};
    }
    report["metrics"] = {{"E_confor", m.E_confor},
                         {"E_planar", m.E_planar},
                         {"E_angle_deg", m.E_angle_deg},
                         {"foldovers", m.foldovers},
                         {"degenerate_faces", m.degenerate}};
    report["field"] = {{"constraints", constraints_json(field)},
                       {"singularities", pipeline.singularities().size()}};
    if (!warned_about_constraints) warn_about_released_constraints(field, "optimize");
    report["structurally_equivalent"] = ex.structurally_equivalent;
    report["extraction_problems"] = ex.problems;
    report["bad_cones"] = ex.bad_cones;
    report["parameterization"] = {{"wedges", param.wedges},
                                  {"cut_edges", param.cut_edges},
                                  {"constraint_rows", param.constraint_rows},
                                  {"eliminated", param.eliminated},
                                  {"redundant", param.redundant},
                                  {"unknowns", param.unknowns},
                                  {"anisotropic", options.param.anisotropic},
                                  {"sizing", options.param.sizing.enabled},
                                  {"aligned", !o.no_align}};
    const fs::path out(o.out);
    set_activity("writing the results into " + o.out);
    write_param_obj(pipeline.mesh(), param.corner_uv, (out / "param.obj").string());
    write_field_txt(pipeline.geometry(), field.theta, (out / "field.txt").string());
    save_layout(pipeline.output_layout(), (out / "layout.json").string(), &pipeline.mesh());
    if (o.quad_size > 0 || o.quad_count > 0) {  // quad mesh export (issue #8)
      QuadMeshOptions qo;
      qo.quad_size = integer ? integer->quad_size : o.quad_size;
      qo.quad_count = integer ? 0 : o.quad_count;
      if (qo.quad_size > 0) {
        require_quad_count_within_limit(
            static_cast<double>(count_quads(pipeline.topology(), ex, qo.quad_size)), qo.quad_size,
            "counted on the parameterization");
      }
      set_activity("building the quad mesh");
      const QuadMesh quads = build_quad_mesh(pipeline, ex, qo);
      UvAtlasOptions atlas;
      if (o.atlas == "packed") atlas.layout = UvAtlasLayout::kPacked;
      set_activity("writing the quad mesh into " + o.out);
      write_quad_exports(quads, pipeline.output_layout(), ex, out.string(), atlas);
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
