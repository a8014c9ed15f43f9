// quadsketch-cli: the headless interface (interfaces.md §2).
// Exit codes: 0 success; 2 invalid input; 3 solver failure; 1 anything else (a malformed or
// out-of-range option, out of memory, a write error).
#include <CLI/CLI.hpp>
#include <csignal>
#include <iostream>
#include <new>
#include <string>

#include "app/cli/activity.h"
#include "app/cli/commands.h"
#include "app/cli/signals.h"
#include "app/cli/validators.h"
#include "core/base/allocator.h"
#include "core/base/errors.h"
#include "core/base/solver_threads.h"

namespace {

// The command line: sets up and parses the options, runs the subcommand.
int run_cli(int argc, char** argv) {
  qs::limit_solver_threads_here();  // CHOLMOD's OpenMP regions: at most the idle cores
  qs::keep_freed_memory();          // solves reuse freed memory (core/base/allocator.h)
  using namespace qs::cli;
  CLI::App app{"QuadSketch: quad layout embedding via aligned parameterization (headless)",
               "quadsketch-cli"};
  app.set_version_flag("--version", std::string("quadsketch-cli ") + QS_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global flags such as --quiet also work after the subcommand
  CommonOptions common;
  app.add_flag("-q,--quiet", common.quiet, "Silence progress output");

  ValidateOptions validate;
  auto* cmd_validate =
      app.add_subcommand("validate", "Check a mesh and a layout; list every problem");
  cmd_validate->add_option("--mesh", validate.mesh, "Triangle mesh (OBJ, OFF, PLY, STL)")
      ->required();
  cmd_validate->add_option("--layout", validate.layout, "Layout JSON")->required();
  cmd_validate->add_option("--out", validate.out, "Also write report.json into this folder");

  // field and optimize: the dihedral angle above which an edge is sharp.
  auto add_sharp_angle_option = [](CLI::App* cmd, double& value) {
    cmd->add_option("--sharp-angle", value, "Sharp feature dihedral angle (deg)")
        ->check(finite_in(0, 180))
        ->capture_default_str();
  };

  // field and optimize: CrossFieldOptions::max_cluster_faces.
  auto add_cluster_option = [](CLI::App* cmd, int& value) {
    cmd->add_option("--max-cluster-faces", value,
                    "Curvature constraints form clusters of at most N faces, each with its own "
                    "quarter-turn rotation, released one by one where they contradict the "
                    "layout (0: whole connected regions)")
        ->check(finite_in(0, 1e9))
        ->capture_default_str();
  };

  // field and optimize: CrossFieldOptions::free_loops.
  auto add_free_holes_option = [](CLI::App* cmd, bool& value) {
    cmd->add_flag("--wrap-free-holes", value,
                  "Along boundary loops the layout leaves free (holes that only dangling arcs "
                  "run into) the field follows the loop, so the iso-lines wrap around the hole "
                  "(an O-grid, for many arcs radiating into it); by default it turns as around "
                  "a regular point and the iso-lines run on across the hole");
  };

  FieldOptions field;
  auto* cmd_field = app.add_subcommand("field", "Compute the guiding cross field of a layout");
  cmd_field->add_option("--mesh", field.mesh, "Triangle mesh")->required();
  cmd_field->add_option("--layout", field.layout, "Layout JSON")->required();
  cmd_field->add_option("--out", field.out, "Output folder")->required();
  add_sharp_angle_option(cmd_field, field.sharp_angle_deg);
  add_cluster_option(cmd_field, field.max_cluster_faces);
  add_free_holes_option(cmd_field, field.wrap_free_holes);

  OptimizeOptions opt;
  auto* cmd_opt = app.add_subcommand("optimize", "Run the whole pipeline and write the results");
  cmd_opt->add_option("--mesh", opt.mesh, "Triangle mesh")->required();
  cmd_opt->add_option("--layout", opt.layout, "Layout JSON")->required();
  cmd_opt->add_option("--out", opt.out, "Output folder")->required();
  cmd_opt
      ->add_option("--steps", opt.steps,
                   "Node optimization descent steps (accepted and rejected) before the first hop "
                   "sweep; a sweep that moves nodes allows at least 10 more (3 sweeps at most)")
      ->check(finite_in(0, 10000))
      ->capture_default_str();
  cmd_opt->add_flag("--no-node-opt", opt.no_node_opt, "Only field and parameterization");
  auto* quad_size_opt =
      cmd_opt
          ->add_option("--quad-size", opt.quad_size,
                       "Write quads.obj, patches.json, layout_curves.obj with this quad size "
                       "(refused when the quad mesh would have more than " +
                           std::to_string(kMaxQuads) + " quads)")
          ->check(positive_finite());
  cmd_opt
      ->add_option("--quad-count", opt.quad_count,
                   "Like --quad-size, choosing the size for about N quads")
      ->check(finite_in(1, kMaxQuads))
      ->excludes(quad_size_opt);
  cmd_opt->add_flag("--integer", opt.integer,
                    "Make every patch size an integer multiple of the quad size: optimize relaxed, "
                    "round the arc lengths, optimize again with them fixed (needs --quad-size or "
                    "--quad-count)");
  cmd_opt
      ->add_option("--atlas", opt.atlas,
                   "Texture coordinates of quads.obj: per-patch (every patch on [0,1]^2) or packed "
                   "(non-overlapping patches, one scale, for baking)")
      ->check(CLI::IsMember({"per-patch", "packed"}))
      ->capture_default_str();
  cmd_opt->add_option("--gradient", opt.gradient, "Node gradient: estimator or exact")
      ->check(CLI::IsMember({"estimator", "exact"}))
      ->capture_default_str();
  cmd_opt->add_flag("--no-align", opt.no_align, "Ignore curvature directions (baseline)");
  cmd_opt->add_flag("--discrete-relocation", opt.discrete_relocation,
                    "Move nodes vertex by vertex (baseline)");
  cmd_opt
      ->add_option("--time-limit", opt.time_limit_s,
                   "Stop moving nodes after this many seconds (wall clock, from the start of the "
                   "node optimization; with --integer both runs together) and finish from the "
                   "state reached (the continuous run still removes fold-overs)")
      ->check(positive_finite(1e7, "a positive number of seconds"));
  cmd_opt->add_flag("--no-sliding", opt.no_sliding,
                    "Nodes on the boundary and on feature curves stay instead of sliding along "
                    "them; nodes on sharp edges move freely and vertices on sharp edges may be "
                    "relocated (sharp edges not kept)");
  cmd_opt->add_flag("--keep-sharp-edges", opt.keep_sharp_edges,
                    "Treat the sharp edges (--sharp-angle) as feature curves in the node "
                    "optimization: nodes on them slide along them and their vertices keep their "
                    "place (sharp edges keep their shape; higher E)");
  auto* apart_on = cmd_opt->add_flag_callback(
      "--keep-nodes-apart", [&opt] { opt.keep_nodes_apart = true; },
      "Never carry a moving node onto a vertex next to another node (no two nodes on one "
      "triangle), for dense layouts with a few edges per patch side. Off by default, but "
      "without --keep-nodes-apart or --no-keep-nodes-apart a node optimization whose fold-over "
      "removal leaves fold-overs or falls back to an earlier state is run again with it and "
      "kept when it ends better");
  cmd_opt
      ->add_flag_callback(
          "--no-keep-nodes-apart", [&opt] { opt.keep_nodes_apart = false; },
          "Nodes may move next to each other, and no retry with "
          "--keep-nodes-apart")
      ->excludes(apart_on);
  cmd_opt->add_flag("--separate-nodes", opt.separate_nodes,
                    "Before the node optimization, move nodes that sit next to another node "
                    "(on its vertex's 1-ring) apart, at most 2 edge rings; for displaced "
                    "sketches with crowded nodes, best with --keep-nodes-apart");
  cmd_opt
      ->add_option("--symmetry", opt.symmetry,
                   "Keep the layout mirror symmetric about the plane x, y or z = const through "
                   "the mesh's bounding-box centre, or the fitted mirror plane (auto): mirror "
                   "pairs of nodes move as mirror images and nodes on the plane stay in it. The "
                   "pairs are found from the layout, which must be symmetric (an error names the "
                   "first node without a mirror); no hop polish, nodes on curves stay")
      ->check(CLI::IsMember({"x", "y", "z", "auto"}));
  cmd_opt->add_flag("--orientation", opt.orientation,
                    "With --no-node-opt: when the parameterization has fold-overs, solve it "
                    "again with strict orientation constraints (the fixed nodes' fold-over "
                    "removal; the node optimization does this by default)");
  cmd_opt
      ->add_option("--orientation-sectors", opt.orientation_sectors,
                   "Frame of the orientation constraints' tri-sectors: auto (the field's; "
                   "where fold-overs remain, also turned by the solution's rotation, at most "
                   "45 deg, keeping the result with fewer fold-overs), field or solution")
      ->check(CLI::IsMember({"auto", "field", "solution"}))
      ->capture_default_str();
  cmd_opt->add_flag("--no-untangle", opt.no_untangle,
                    "Where the orientation constraints leave fold-overs (they are only "
                    "sufficient), do not untangle the parameterization (a barrier on the "
                    "faces' Jacobian determinants, Newton steps with the same exact "
                    "constraints)");
  cmd_opt->add_flag("--no-orientation", opt.no_orientation,
                    "No orientation constraints against fold-overs after the node optimization "
                    "(stiffening only)");
  auto* sizing_on = cmd_opt->add_flag_callback(
      "--sizing", [&opt] { opt.sizing = true; },
      "Scale the parameterization's targets by the curl-reducing sizing field (paper §5.3; "
      "off by default, but without --sizing or --no-sizing a node optimization that ends "
      "with fold-overs, or back at its initial state, is run again with it and kept when it "
      "ends better)");
  cmd_opt
      ->add_flag_callback(
          "--no-sizing", [&opt] { opt.sizing = false; },
          "Unit targets, no sizing field, and no retry with it when fold-overs remain")
      ->excludes(sizing_on);
  add_sharp_angle_option(cmd_opt, opt.sharp_angle_deg);
  add_cluster_option(cmd_opt, opt.max_cluster_faces);
  add_free_holes_option(cmd_opt, opt.wrap_free_holes);
  cmd_opt
      ->add_option("--threads", opt.threads,
                   "Threads of the math libraries (OpenBLAS, CHOLMOD's OpenMP regions); more "
                   "than 1 uses at most the idle cores")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();

  ImportQuadsOptions imp;
  auto* cmd_import = app.add_subcommand("import-quads", "Make a layout from a quad mesh");
  cmd_import->add_option("--quads", imp.quads, "Quad mesh")->required();
  cmd_import->add_option("--onto", imp.onto, "Triangle mesh to transfer the layout onto");
  cmd_import->add_option("--out", imp.out, "Output folder")->required();
  cmd_import->add_flag("--all-edges", imp.all_edges,
                       "Use every edge as an arc (coarse cages) instead of the base complex");
  cmd_import
      ->add_option("--refine", imp.refine, "Split each quad K x K before triangulating (no --onto)")
      ->check(finite_in(1, 1000))
      ->capture_default_str();
  cmd_import
      ->add_option("--coarsen", imp.coarsen,
                   "Collapse the base complex's patch strips thinner than W mean edge lengths")
      ->check(finite_in(0, 1e6))
      ->capture_default_str();

  PerturbOptions perturb;
  auto* cmd_perturb = app.add_subcommand("perturb", "Move the nodes of a layout randomly");
  cmd_perturb->add_option("--mesh", perturb.mesh, "Triangle mesh")->required();
  cmd_perturb->add_option("--layout", perturb.layout, "Layout JSON")->required();
  cmd_perturb->add_option("--rings", perturb.rings, "Edge rings to move each node")
      ->check(finite_in(1, 1000))
      ->required();
  cmd_perturb->add_option("--seed", perturb.seed, "Random seed")->required();
  cmd_perturb->add_option("--out", perturb.out, "Output layout JSON")->required();

  CageLayoutOptions cage;
  auto* cmd_cage = app.add_subcommand(
      "cage-layout", "Make a layout for a closed triangle mesh from its voxel cage");
  cmd_cage->add_option("--mesh", cage.mesh, "Closed triangle mesh")->required();
  cmd_cage->add_option("--out", cage.out, "Output layout JSON")->required();
  cmd_cage->add_option("--resolution", cage.resolution, "Voxel cells along the longest axis")
      ->check(CLI::Range(2, 200))
      ->capture_default_str();
  cmd_cage->add_flag("--all-edges", cage.all_edges,
                     "Every cage edge is an arc (one patch per cage quad) instead of the base "
                     "complex");
  cmd_cage->add_option("--smoothing", cage.smoothing, "Spring relaxation rounds of the fitted cage")
      ->check(finite_in(0, 10000))
      ->capture_default_str();
  cmd_cage
      ->add_option("--attempts", cage.attempts,
                   "Grids to try (resolution, shifted, resolution + 1, ...) until one works")
      ->check(finite_in(1, 400))
      ->capture_default_str();
  cmd_cage
      ->add_option("--coarsen", cage.coarsen,
                   "Collapse cage chords at most this many voxel cells wide (0: off)")
      ->check(finite_in(0, 1000))
      ->capture_default_str();
  cmd_cage
      ->add_option("--subsamples", cage.subsamples,
                   "Inside-test points per cell and axis (1: the cell centre; more: the cell's "
                   "inside fraction)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  cmd_cage->add_flag("--simplify", cage.simplify,
                     "Cancel nearby irregular nodes of the coarsened cage layout (diagonal "
                     "collapses, edge rotations) and re-embed it; falls back to the plain layout");
  cmd_cage->add_option("--cage", cage.cage, "Also write the fitted quad cage (OBJ)");

  set_activity("parsing the command line");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 1;
  }

  // field and optimize stop cooperatively (report.json "cancelled", see report.h); the other
  // commands are short and write atomically: a signal simply ends them.
  if (!*cmd_field && !*cmd_opt) restore_default_signal_handling();
  try {
    set_activity("running " + app.get_subcommands().front()->get_name());
    if (*cmd_validate) return run_validate(validate, common);
    if (*cmd_field) return run_field(field, common);
    if (*cmd_opt) return run_optimize(opt, common);
    if (*cmd_import) return run_import_quads(imp, common);
    if (*cmd_perturb) return run_perturb(perturb, common);
    if (*cmd_cage) return run_cage_layout(cage, common);
  } catch (const qs::Cancelled&) {
    std::cerr << "error: cancelled (" << signal_name(received_signal()) << ")\n";
    return cancelled_exit_code();
  } catch (const std::bad_alloc&) {
    throw;  // main() ends the process
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return qs::exit_code_for(e);
  }
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  // First of all, so that a signal during start-up is never handled by the default action.
  qs::cli::install_signal_handlers();  // SIGINT/SIGTERM: cancel, report.json "cancelled", 130/143
  // A file-size limit (ulimit -f) fails the write (EFBIG, reported) instead of killing.
  std::signal(SIGXFSZ, SIG_IGN);
  // Out of memory anywhere: "error: out of memory while <activity>", exit code 1.
  qs::cli::handle_out_of_memory_in_terminate();
  try {
    return run_cli(argc, argv);
  } catch (const std::bad_alloc&) {
    qs::cli::exit_out_of_memory();
  }
}
