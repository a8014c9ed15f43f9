// Gradient estimator statistics (issue #9): compares the 1-ring estimator of the node gradient
// (estimate_node_gradients) with central finite differences that re-solve field and
// parameterization (exact_node_gradients) over all nodes of three displaced layouts, and prints
// the mean/max angle between them and the magnitude ratio |estimator| / |exact|.
//
//   qs_bench_gradient [--json OUT.json]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/base/allocator.h"
#include "core/import/perturb.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/gradient.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace {

struct Stats {
  std::string name;
  int nodes = 0, compared = 0;
  double mean_angle_deg = 0, max_angle_deg = 0;
  double mean_ratio = 0, min_ratio = 0, max_ratio = 0;
  double time_s = 0;
};

Stats compare(const std::string& name, const qs::TriMesh& mesh, const qs::Layout& layout) {
  const auto t0 = std::chrono::steady_clock::now();
  qs::PipelineOptions options;
  qs::Pipeline pipeline(mesh, layout, options);
  const qs::Parameterization& param = pipeline.compute_parameterization();
  std::vector<int> vertices;
  for (const qs::LayoutNode& n : layout.nodes) vertices.push_back(n.vertex);
  const std::vector<qs::Vec3> est =
      qs::estimate_node_gradients(pipeline.mesh(), pipeline.geometry(), pipeline.field()->theta,
                                  param, options.param, vertices);
  const std::vector<qs::Vec3> exact = qs::exact_node_gradients(mesh, layout, options, vertices);

  Stats s;
  s.name = name;
  s.nodes = static_cast<int>(vertices.size());
  s.min_ratio = INFINITY;
  double max_exact = 0;
  for (const qs::Vec3& g : exact) max_exact = std::max(max_exact, static_cast<double>(g.norm()));
  for (size_t i = 0; i < vertices.size(); ++i) {
    const double ne = est[i].norm(), nx = exact[i].norm();
    // Nodes at a stationary point (|exact| tiny relative to the largest) have no direction.
    if (nx <= 1e-6 * max_exact || ne == 0) continue;
    const double c = std::clamp(static_cast<double>(est[i].dot(exact[i])) / (ne * nx), -1.0, 1.0);
    const double angle = std::acos(c) * 180.0 / M_PI;
    const double ratio = ne / nx;
    ++s.compared;
    s.mean_angle_deg += angle;
    s.max_angle_deg = std::max(s.max_angle_deg, angle);
    s.mean_ratio += ratio;
    s.min_ratio = std::min(s.min_ratio, ratio);
    s.max_ratio = std::max(s.max_ratio, ratio);
  }
  if (s.compared > 0) {
    s.mean_angle_deg /= s.compared;
    s.mean_ratio /= s.compared;
  } else {
    s.min_ratio = 0;
  }
  s.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  qs::keep_freed_memory();  // as quadsketch-cli and the GUI (core/base/allocator.h)
  std::string json_path;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0 && i + 1 < argc) {
      json_path = argv[++i];
    } else {
      std::cerr << "usage: qs_bench_gradient [--json OUT.json]\n";
      return 1;
    }
  }
  try {
    std::vector<Stats> all;
    // 1. The bundled example: the displaced sketch on the ellipsoid (8 nodes).
    const std::string assets = qs::test::assets_dir() + "/example/";
    const qs::TriMesh ellipsoid = qs::load_mesh(assets + "ellipsoid.obj");
    const qs::Layout sketch = qs::load_layout(assets + "ellipsoid.layout.json", ellipsoid);
    all.push_back(compare("ellipsoid sketch", ellipsoid, sketch));
    // 2. A synthetic ellipsoid cube layout (radii 1, 0.8, 0.6; 12×12 per cube face) whose
    //    nodes moved by 2 edge rings (seed 1).
    qs::test::MeshAndLayout ml = qs::test::cube_sphere(12, qs::Vec3(1.0, 0.8, 0.6));
    qs::PerturbLayoutOptions po;
    po.rings = 2;
    po.seed = 1;
    const qs::Layout perturbed = qs::perturb_layout(ml.mesh, ml.layout, po).layout;
    all.push_back(compare("cube_sphere(12) ellipsoid, perturb 2 rings", ml.mesh, perturbed));
    // 3. The genus-2 polycube (valence 3, 4 and 5 nodes, sharp edges), nodes moved by 1 ring.
    qs::test::MeshAndLayout poly = qs::test::genus2_polycube(4);
    po.rings = 1;
    const qs::Layout poly_perturbed = qs::perturb_layout(poly.mesh, poly.layout, po).layout;
    all.push_back(compare("genus2_polycube(4), perturb 1 ring", poly.mesh, poly_perturbed));

    nlohmann::json out = nlohmann::json::array();
    std::cout << "layout | nodes | compared | mean angle (deg) | max angle (deg) | mean ratio | "
                 "min ratio | max ratio | time (s)\n";
    for (const Stats& s : all) {
      std::cout << s.name << " | " << s.nodes << " | " << s.compared << " | " << s.mean_angle_deg
                << " | " << s.max_angle_deg << " | " << s.mean_ratio << " | " << s.min_ratio
                << " | " << s.max_ratio << " | " << s.time_s << "\n";
      out.push_back({{"name", s.name},
                     {"nodes", s.nodes},
                     {"compared", s.compared},
                     {"mean_angle_deg", s.mean_angle_deg},
                     {"max_angle_deg", s.max_angle_deg},
                     {"mean_ratio", s.mean_ratio},
                     {"min_ratio", s.min_ratio},
                     {"max_ratio", s.max_ratio},
                     {"time_s", s.time_s}});
    }
    if (!json_path.empty()) std::ofstream(json_path) << out.dump(2) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "qs_bench_gradient: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
