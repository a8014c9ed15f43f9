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
#include "core/extract/quads.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/gradient.h"
#include "core/nodeopt/optimizer.h"
#include "core/nodeopt/retry.h"
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
    MeshReport mesh_report;
    set_activity("loading the mesh '" + o.mesh + "'");
    SurfaceLayout on_surface = load_command_layout(o.layout, load_mesh(o.mesh, &mesh_report));
    report["mesh"] = mesh_json(mesh_report);
    report["working_mesh"] = working_mesh_json(on_surface);
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
    PipelineOptions options;
    options.field.constraints.sharp_angle_deg = o.sharp_angle_deg;
    options.field.max_cluster_faces = o.max_cluster_faces;
    if (o.wrap_free_holes) options.field.free_loops = FreeLoopTurning::kWrap;
    options.field.constraints.curvature = !o.no_align;
    if (o.sizing) options.param.sizing.enabled = *o.sizing;
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
    const SectorFrame sector_frame = o.orientation_sectors == "field" ? SectorFrame::kField
                                     : o.orientation_sectors == "solution"
                                         ? SectorFrame::kSolution
                                         : SectorFrame::kFieldThenSolution;
    // Node optimization first (it runs its own field + parameterization solves); the final
    // stages below then run on its result.
    double node_s = 0;
    std::optional<NodeOptResult> node_result;
    ProgressPrinter printer(common.quiet);
    bool warned_about_constraints = false;
    // --time-limit: one deadline for every node optimization run (set when the first starts).
    std::optional<std::chrono::steady_clock::time_point> deadline;
    const auto time_limit = [&]() -> std::function<bool()> {
      if (o.time_limit_s <= 0) return {};
      if (!deadline)
        deadline = std::chrono::steady_clock::now() +
                   std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                       std::chrono::duration<double>(o.time_limit_s));
      const auto end = *deadline;
      return [end] { return std::chrono::steady_clock::now() >= end; };
    };
    // NodeOptOptions::keep_nodes_apart of the run that is written (the retry below may set it).
    bool keep_apart = o.keep_nodes_apart.value_or(false);
    const auto optimize = [&](const TriMesh& start_mesh, const Layout& start_layout,
                              const PipelineOptions& run_options, bool apart) {
      if (o.discrete_relocation) {
        DiscreteOptions d;
        d.max_steps = o.steps;
        d.stop = time_limit();
        return relocate_nodes_discrete(start_mesh, start_layout, run_options, d, &printer);
      }
      NodeOptOptions no;
      no.max_steps = o.steps;
      no.stop = time_limit();
      no.gradient = o.gradient == "exact" ? GradientMethod::Exact : GradientMethod::Estimator;
      no.orientation_at_end = !o.no_orientation;
      no.orientation.sector_frame = sector_frame;
      no.orientation.untangle = !o.no_untangle;
      no.slide_on_curves = !o.no_sliding;
      no.sharp_edges_as_curves = o.keep_sharp_edges;
      no.keep_nodes_apart = apart;
      no.separate_crowded_nodes = o.separate_nodes;
      // Integer sizes put nodes exactly on shared iso-lines: fresh trial Pipelines there (see
      // NodeOptOptions::reuse_field).
      if (o.integer) no.reuse_field = false;
      // The optimizer's initial solve (of the layout it starts from, after --separate-nodes)
      // reports a layout that contradicts the curvature before the long run rather than after.
      NodeOptimizer optimizer(start_mesh, start_layout, run_options, no, &printer);
      if (!warned_about_constraints)
        warned_about_constraints = warn_about_released_constraints(
            *optimizer.pipeline(&printer)->field(), "optimize (initial field)");
      while (optimizer.step(&printer)) {
      }
      NodeOptResult result = optimizer.finish(&printer);
      if (!common.quiet && result.crowded_nodes > 0)
        std::cerr << "optimize: " << result.separated_nodes.size() << " of " << result.crowded_nodes
                  << " crowded node(s) moved apart before the node optimization\n";
      return result;
    };
    // After a run: its mesh, layout and the options of its final solve.
    const auto adopt = [&](NodeOptResult result) {
      mesh = result.mesh;
      layout = result.layout;
      options.param.face_weights = result.face_weights;
      if (result.orientation_constraints)  // the final solve is the constrained one
        options.param.orientation = result.orientation_options;
      node_result = std::move(result);
    };
    // --no-node-opt --orientation: the final solve checks for fold-overs and, when there are
    // any, solves the orientation-constrained QP (ParamSolver::solve), cancellable by signal.
    if (o.orientation) {
      options.param.orientation.enabled = true;
      options.param.orientation.sector_frame = sector_frame;
      options.param.orientation.untangle = !o.no_untangle;
      options.param.orientation.observer = &printer;
    }
    // Node optimization, then the retries below when it fails.
    nlohmann::json sizing_retry, apart_retry;
    if (!o.no_node_opt) {
      t0 = std::chrono::steady_clock::now();
      set_activity("optimizing the nodes");
      const bool may_retry_apart =
          !o.keep_nodes_apart && !o.discrete_relocation && !o.no_orientation;
      const bool may_retry =
          !o.sizing && !o.discrete_relocation && !o.no_orientation && !options.param.sizing.enabled;
      std::optional<TriMesh> input_mesh;
      std::optional<Layout> input_layout;
      if (may_retry || may_retry_apart) input_mesh = mesh, input_layout = layout;
      const PipelineOptions input_options = options;
      adopt(optimize(mesh, layout, options, keep_apart));
      // One retry from the input with \p run_options and \p apart (\p with names it, \p flags
      // the options that decide it up front). The retry's run is adopted when \p better(retry,
      // first) says so (`used` in the report entry, to which the caller adds its own fields).
      struct Retry {
        nlohmann::json entry;
        bool used = false;
        NodeOptResult run;
      };
      const auto retry = [&](const std::string& with, const std::string& flags,
                             const PipelineOptions& run_options, bool apart, auto better) {
        const NodeOptResult& first = *node_result;
        if (!common.quiet) {
          std::cerr << "optimize: ";
          if (first.foldovers_final > 0)
            std::cerr << first.foldovers_final << " fold-over(s) remain";
          else if (first.untangled)
            std::cerr << "only the untangling removed the fold-overs";
          else if (first.initial_reverted)
            std::cerr << "the fold-over removal fell back to the initial state";
          else
            std::cerr << "the fold-over removal fell back to an earlier state";
          std::cerr << "; optimizing again from the input with " << with << " (" << flags
                    << " decides this up front)\n";
        }
        const auto t_retry = std::chrono::steady_clock::now();
        NodeOptResult second = optimize(*input_mesh, *input_layout, run_options, apart);
        const bool used = better(second, first);
        nlohmann::json entry = {{"foldovers_without", first.foldovers_final},
                                {"E_final_without", first.E_final},
                                {"foldovers_with", second.foldovers_final},
                                {"E_final_with", second.E_final},
                                {"untangled_without", first.untangled},
                                {"untangled_with", second.untangled},
                                {"used", used}};
        if (!common.quiet)
          std::cerr << "optimize: with " << with << " " << second.foldovers_final
                    << " fold-over(s) remain at E " << second.E_final << " ("
                    << first.foldovers_final << " at E " << first.E_final
                    << " without): " << (used ? "using it" : "keeping the run without it") << "\n";
        entry["time_s"] = seconds_since(t_retry);
        return Retry{std::move(entry), used, std::move(second)};
      };
      // The keep-apart retry comes first: when the user left --keep-nodes-apart to the default
      // (off) and the fold-over removal leaves fold-overs or has to fall back to the accepted
      // state with the fewest fold-overs or to the initial state (the descent went where no
      // orientation-constrained solve embeds the layout), the input is optimized again with
      // NodeOptOptions::keep_nodes_apart, and that run is taken when it ends with fewer fold-overs,
      // or as many at a lower E. Nodes crowding onto one triangle are what made the exact pig's
      // optimized layouts fail (the default fell back to the initial state;
      // kept apart, the optimized layout embedded). Not the default itself:
      // crowded starts (the displaced spot) then keep fold-overs the default removes.
      // The rules: core/nodeopt/retry.h.
      if (may_retry_apart && wants_keep_apart_retry(*node_result)) {
        const bool fell_back_without = fell_back(*node_result);
        Retry r = retry("nodes kept apart", "--keep-nodes-apart or --no-keep-nodes-apart",
                        input_options, true, keep_apart_retry_is_better);
        apart_retry = std::move(r.entry);
        apart_retry["fell_back_without"] = fell_back_without;
        if (r.used) {
          keep_apart = true;
          adopt(std::move(r.run));
        }
      }
      // The sizing retry: when the user left the sizing field to the default (off) and
      // fold-overs remain after the node optimization's fold-over removal, or it embedded only
      // the initial state (the node movement given up), the layout is optimized again from the
      // input with the sizing field (and the keep-apart choice made above), and that run is
      // taken when it ends with fewer fold-overs, or as many without falling back to the initial
      // state (the rocker-arm cage layout with the field frame's sectors and the exact cow
      // embed only with it). E is no
      // criterion here: the sizing field changes the energy. An explicit --sizing or
      // --no-sizing decides up front; --no-orientation (stiffening only, an ablation) and the
      // discrete baseline are run as asked.
      if (may_retry && wants_sizing_retry(*node_result)) {
        PipelineOptions sized = input_options;
        sized.param.sizing.enabled = true;
        const bool initial_without = node_result->initial_reverted;
        Retry r = retry("the sizing field", "--sizing or --no-sizing", sized, keep_apart,
                        sizing_retry_is_better);
        sizing_retry = std::move(r.entry);
        sizing_retry["initial_without"] = initial_without;
        sizing_retry["initial_with"] = r.run.initial_reverted;
        if (r.used) {
          options = sized;
          adopt(std::move(r.run));
        }
      }
      node_s = seconds_since(t0);
    }
    // --integer (paper §8): round every arc's length on the relaxed result to a multiple of Q
    // (one value per poly-chord), then optimize again with those lengths as constraints.
    std::optional<IntegerSizes> integer;
    double E_relaxed = 0;
    std::optional<NodeOptResult> relaxed_result;
    if (o.integer) {
      std::shared_ptr<Pipeline> relaxed;
      if (node_result && node_result->pipeline && node_result->face_weights.empty())
        relaxed = node_result->pipeline;
      else
        relaxed = std::make_shared<Pipeline>(mesh, layout, options);
      if (!relaxed->parameterization()) relaxed->compute_parameterization();
      E_relaxed = unweighted_energy(relaxed->mesh(), relaxed->geometry(), relaxed->field()->theta,
                                    *relaxed->parameterization(), options.param);
      const double q = o.quad_size > 0 ? o.quad_size
                                       : quad_size_for_count(relaxed->topology(),
                                                             relaxed->extract(), o.quad_count);
      integer = round_arc_lengths(relaxed->param_solver()->arc_lengths(), q);
      if (!common.quiet)
        std::cerr << "optimize: integer sizes with quad size " << q << ": "
                  << integer->lengths.size() << " arc lengths rounded (largest change "
                  << integer->max_change << "), relaxed E = " << E_relaxed << "\n";
      PipelineOptions fixed = options;
      fixed.param.arc_lengths = integer->lengths;
      fixed.param.face_weights.clear();
      // The node optimizer's constrained solve is not carried over; --no-node-opt --orientation
      // keeps its own (set above: no node optimization has replaced it).
      if (!o.orientation) fixed.param.orientation = PipelineOptions{}.param.orientation;
      options = fixed;
      if (!o.no_node_opt) {
        t0 = std::chrono::steady_clock::now();
        relaxed_result = std::move(node_result);
        node_result.reset();
        adopt(optimize(mesh, layout, options, keep_apart));
        node_s += seconds_since(t0);
      }
    }
    // The optimizer hands back its final Pipeline (solved with `options`, orientation
    // constraints included when they were used); only stiffening weights need a new solve.
    std::shared_ptr<Pipeline> solved;
    if (node_result && node_result->pipeline && node_result->face_weights.empty())
      solved = node_result->pipeline;
    else
      solved = std::make_shared<Pipeline>(std::move(mesh), std::move(layout), options);
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
      const bool time_limited = node_result->stopped || (relaxed_result && relaxed_result->stopped);
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
          {"keep_nodes_apart", keep_apart},
          {"crowded_nodes", node_result->crowded_nodes},
          {"separated_nodes", node_result->separated_nodes}};
      if (!apart_retry.is_null()) report["node_optimization"]["keep_apart_retry"] = apart_retry;
      if (!sizing_retry.is_null()) report["node_optimization"]["sizing_retry"] = sizing_retry;
      warn_about_infeasible_orientation(node_result->orientation, param.foldovers, pipeline.mesh(),
                                        pipeline.layout());
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
