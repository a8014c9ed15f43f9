// quadsketch-cli cage-layout: a quad layout for a closed triangle mesh from its voxel cage.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include "app/cli/commands.h"
#include "app/cli/report.h"
#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/import/cage.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "core/mesh/write_checks.h"

namespace qs::cli {

namespace {

void write_cage_obj(const PolyMesh& cage, const std::string& path) {
  write_file_atomic(path, [&](std::ostream& os) {
    os << std::setprecision(17);
    for (const auto v : cage.vertices()) {
      const Vec3& p = cage.point(v);
      os << "v " << p[0] << " " << p[1] << " " << p[2] << "\n";
    }
    for (const auto f : cage.faces()) {
      os << "f";
      for (const auto v : cage.fv_range(f)) os << " " << v.idx() + 1;
      os << "\n";
    }
  });
}

std::string format_shift(double shift) {
  std::ostringstream os;
  os << std::setprecision(3) << shift;
  return os.str();
}

}  // namespace

int run_cage_layout(const CageLayoutOptions& o, const CommonOptions& common) {
  const auto t0 = std::chrono::steady_clock::now();
  require_writable_file(o.out);
  if (!o.cage.empty()) require_writable_file(o.cage);
  const TriMesh mesh = load_mesh_printing_warnings(o.mesh);
  CageOptions options;
  options.resolution = o.resolution;
  options.attempts = o.attempts;
  options.all_edges = o.all_edges;
  options.coarsen = o.coarsen;
  options.fit.iterations = o.smoothing;
  options.subsamples = o.subsamples;
  options.simplify = o.simplify;
  set_activity("making the cage layout");
  const CageResult result = cage_layout(mesh, options);
  for (const auto& w : result.warnings) std::cerr << "warning: " << w << "\n";
  // The layout was validated by the transfer (the checks load_layout applies); the cage gets
  // the checks of the mesh reader before anything is written.
  if (!o.cage.empty()) {
    const MeshReport cage_report = check_as_read(result.cage);
    if (!cage_report.ok())
      throw InvalidInputError(rejection_message(cage_report, "the fitted cage for " + o.cage));
  }
  set_activity("writing " + o.out);
  save_layout(result.layout, o.out, &mesh);
  if (!o.cage.empty()) write_cage_obj(result.cage, o.cage);
  if (!common.quiet) {
    const nlohmann::json counts = layout_json(build_topology(mesh, result.layout));
    std::cerr << "cage-layout: resolution " << result.resolution
              << (result.shift != 0 ? " (shifted " + format_shift(result.shift) + " cell)" : "")
              << (result.refined ? ", split " + std::to_string(result.refined) + "x" : "")
              << (result.simplified
                      ? ", simplified (irregular nodes " +
                            std::to_string(result.simplify.irregular_before) + " -> " +
                            std::to_string(result.simplify.irregular_after) + ")"
                      : "")
              << ", cage " << result.cage.n_faces() << " quads (genus " << result.voxels.genus
              << ", " << result.voxels.flipped_cells << " cells flipped for manifoldness, "
              << result.folded_quads << " folded after fitting, " << result.coarsen.patches_before
              << " patches before coarsening); layout " << counts["nodes"] << " nodes ("
              << counts["irregular_nodes"] << " irregular), " << counts["arcs"] << " arcs, "
              << counts["patches"] << " patches, " << seconds_since(t0) << " s; wrote " << o.out
              << "\n";
  }
  return 0;
}

}  // namespace qs::cli
