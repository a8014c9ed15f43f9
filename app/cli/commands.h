// The subcommands of quadsketch-cli. Each returns the process exit code and may throw
// qs::QsError (mapped to exit codes by qs::exit_code_for). Each checks that its outputs can be
// written (require_writable_folder / require_writable_file) before it computes anything, and
// records what it is doing (set_activity) for the message of an allocation failure.
#pragma once

#include <optional>
#include <string>

#include "core/field/cross_field.h"

namespace qs::cli {

//! optimize refuses to build a quad mesh with more quads (about 1.7 GB of quads.obj), estimated
//! from the surface area / quad size² before the computation and counted before the quad mesh
//! is built.
inline constexpr long kMaxQuads = 10'000'000;

struct CommonOptions {
  bool quiet = false;
};

struct ValidateOptions {
  std::string mesh, layout, out;
};

struct FieldOptions {
  std::string mesh, layout, out;
  double sharp_angle_deg = 35.0;
  int max_cluster_faces = CrossFieldOptions{}.max_cluster_faces;
  bool wrap_free_holes = false;  //!< CrossFieldOptions::free_loops = kWrap
};

struct OptimizeOptions {
  std::string mesh, layout, out;
  int steps = 25;
  bool no_node_opt = false;
  double quad_size = 0.0;
  int quad_count = 0;    //!< alternative to quad_size: about this many quads
  bool integer = false;  //!< patch sizes integer multiples of the quad size (paper §8)
  std::string gradient = "estimator";
  //! quads.obj texture coordinates: "per-patch" or "packed" (UvAtlasLayout)
  std::string atlas = "per-patch";
  bool no_align = false;
  bool discrete_relocation = false;
  bool no_orientation = false;  //!< no orientation constraints after the node optimization
  //! With no_node_opt: the parameterization with strict orientation constraints when it folds
  //! (ParamOptions::orientation, paper §7.2), as the node optimization's last solve does.
  bool orientation = false;
  //! Sectors of the orientation constraints: "auto" (field frame, then the solution's where
  //! fold-overs remain), "field" or "solution" (OrientationOptions::sector_frame).
  std::string orientation_sectors = "auto";
  bool no_untangle = false;  //!< OrientationOptions::untangle off
  bool no_sliding = false;   //!< nodes on curves stay (NodeOptOptions::Moves::slide_on_curves off)
  bool keep_sharp_edges = false;  //!< NodeOptOptions::Moves::sharp_edges_as_curves
  //! NodeOptOptions::Moves::keep_nodes_apart; unset: off, with a retry with it when the fold-over
  //! removal leaves fold-overs or falls back to an earlier state.
  std::optional<bool> keep_nodes_apart;
  bool separate_nodes = false;  //!< NodeOptOptions::Moves::separate_crowded_nodes
  //! Curl-reducing sizing field (ParamOptions::sizing); unset: the library default.
  std::optional<bool> sizing;
  double sharp_angle_deg = 35.0;
  int max_cluster_faces = CrossFieldOptions{}.max_cluster_faces;
  bool wrap_free_holes = false;  //!< CrossFieldOptions::free_loops = kWrap
  int threads = 1;               //!< math-library threads (core/base/solver_threads.h)
  //! Wall-clock seconds for moving nodes (all node optimization runs together); 0: no limit.
  double time_limit_s = 0;
  //! Symmetric optimization about the plane of this axis ("x", "y", "z" or "auto",
  //! OptimizeSettings::Nodes::symmetry); "": off.
  std::string symmetry;
};

//! import-quads welds the quad mesh's vertices closer than this × its bounding-box diagonal.
inline constexpr double kWeldTolerance = 1e-9;

struct ImportQuadsOptions {
  std::string quads, onto, out;
  bool all_edges = false;  //!< every quad edge is an arc (coarse cages)
  int refine = 1;          //!< split each quad refine x refine before triangulating
  double coarsen = 0;      //!< collapse chords thinner than this many mean edge lengths (0: off)
};

struct CageLayoutOptions {
  std::string mesh, out, cage;
  int resolution = 12;     //!< voxel cells along the longest bounding-box axis
  int attempts = 8;        //!< grids tried (resolution, shifted, resolution + 1, ...)
  int smoothing = 30;      //!< spring relaxation rounds of the fitted cage (CageFitOptions)
  bool all_edges = false;  //!< every cage edge is an arc (one patch per cage quad)
  double coarsen = 1.5;    //!< collapse cage chords at most this many voxel cells wide (0: off)
  int subsamples = 1;      //!< inside-test points per cell and axis (CageOptions::subsamples)
  bool simplify = false;   //!< cancel nearby irregular layout nodes (CageOptions::simplify)
};

struct PerturbOptions {
  std::string mesh, layout, out;
  int rings = 1;
  unsigned seed = 0;
};

int run_validate(const ValidateOptions& options, const CommonOptions& common);
int run_field(const FieldOptions& options, const CommonOptions& common);
int run_optimize(const OptimizeOptions& options, const CommonOptions& common);
int run_import_quads(const ImportQuadsOptions& options, const CommonOptions& common);
int run_perturb(const PerturbOptions& options, const CommonOptions& common);
int run_cage_layout(const CageLayoutOptions& options, const CommonOptions& common);

}  // namespace qs::cli
