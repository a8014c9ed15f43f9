// Continuous vs discrete node relocation (issue #5, paper §6.3): on perturbed layouts, the
// final E and the CPU time of the continuous optimizer (optimize_nodes, defaults; and its
// descent alone, the paper's method without our hop polish) against the discrete baseline
// (relocate_nodes_discrete: every candidate vertex a full solve). Also the CPU time at which the
// continuous run first reaches the discrete run's final E. Not a test.
//
//   qs_relocation_bench [--rings K] [--seeds N] [--max-steps S] [--case NAME] [--hop-all]
//
// --hop-all: the continuous run's hop polish tries every neighbour of every node (no offset,
// direction or work limit), an experiment against the defaults.
//
// Cases are built in process (tests/fixtures.cpp): the bundled ellipsoid sketch
// (assets/example), a cube layout on an ellipsoid (cube_sphere(12), radii 1.3 / 1 / 0.75), the
// 4×2 torus grid, the genus-2 polycube (48 nodes) and, when ../shared is present, spot's quad
// layout. Times are CPU seconds of the process (CLOCK_PROCESS_CPUTIME_ID) with the math
// libraries limited to one thread, so a shared machine does not inflate them.
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/base/solver_threads.h"
#include "core/layout/layout_io.h"
#include "core/layout/perturb.h"
#include "core/layout/quad_import.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/optimizer.h"
#include "tests/fixtures.h"

namespace {

double cpu_now() {
  return qs::bench::cpu_seconds();
}

// Records (CPU time since start, E) of every accepted step.
struct Trace : qs::Observer {
  double start = 0;
  std::vector<std::pair<double, double>> accepted;
  void on_step(const qs::StepReport& r) override {
    if (r.accepted) accepted.push_back({cpu_now() - start, r.E});
  }
  // CPU time at which E first was ≤ target (negative: never).
  double time_to(double target) const {
    for (const auto& [t, E] : accepted)
      if (E <= target * (1 + 1e-12)) return t;
    return -1;
  }
};

struct Case {
  std::string name;
  qs::TriMesh mesh;
  qs::Layout layout;
  int rings = 3;
};

}  // namespace

int main(int argc, char** argv) {
  int rings = -1, seeds = 2, max_steps = 25;
  bool hop_all = false;  // the hop polish tries every neighbour of every node
  std::string only;
  for (int i = 1; i < argc; i += 2) {
    if (!std::strcmp(argv[i], "--hop-all")) {
      hop_all = true;
      --i;
    } else if (i + 1 >= argc) {
      std::fprintf(stderr, "qs_relocation_bench: %s needs a value\n", argv[i]);
      return 2;
    } else if (!std::strcmp(argv[i], "--rings"))
      rings = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--seeds"))
      seeds = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--max-steps"))
      max_steps = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--case"))
      only = argv[i + 1];
    else {
      std::fprintf(stderr,
                   "usage: qs_relocation_bench [--rings K] [--seeds N] [--max-steps S] "
                   "[--case NAME] [--hop-all]\n");
      return 2;
    }
  }
  qs::set_solver_threads(1);
  try {
    std::vector<Case> cases;
    {
      const std::string dir = qs::test::assets_dir() + "/example/";
      Case c{"ellipsoid-example", qs::load_mesh(dir + "ellipsoid.obj"), {}, 0};
      c.layout = qs::load_layout(dir + "ellipsoid.layout.json", c.mesh);  // already displaced
      cases.push_back(std::move(c));
    }
    {
      auto e = qs::test::cube_sphere(12, qs::Vec3(1.3, 1, 0.75));
      cases.push_back({"cube-ellipsoid12", std::move(e.mesh), std::move(e.layout), 3});
    }
    {
      auto t = qs::test::torus_grid(32, 16, 4, 2);
      cases.push_back({"torus-grid", std::move(t.mesh), std::move(t.layout), 3});
    }
    {
      auto g = qs::test::genus2_polycube(4);
      cases.push_back({"genus2-polycube", std::move(g.mesh), std::move(g.layout), 1});
    }
    if (const std::string dir = qs::test::shared_meshes_dir(); !dir.empty()) {
      qs::QuadImportResult imp =
          qs::import_quads(qs::load_poly_mesh(dir + "/spot/spot_quadrangulated.obj"), nullptr, {});
      cases.push_back({"spot", std::move(imp.mesh), std::move(imp.layout), 2});
    }
    std::printf(
        "case | faces | nodes | seed | E_init | continuous E (CPU s) | descent only E (CPU s) "
        "| discrete E (CPU s, sweeps) | continuous reaches discrete E at (CPU s) | time ratio "
        "discrete / continuous-to-reach\n");
    for (const Case& c : cases) {
      if (!only.empty() && c.name != only) continue;
      const int k = rings >= 0 ? rings : c.rings;
      for (int seed = 1; seed <= (k > 0 ? seeds : 1); ++seed) {
        qs::Layout start = c.layout;
        if (k > 0) {
          qs::PerturbLayoutOptions po;
          po.rings = k;
          po.seed = static_cast<unsigned>(seed);
          start = qs::perturb_layout(c.mesh, c.layout, po).layout;
        }
        const qs::PipelineOptions options;
        qs::NodeOptOptions no;
        no.max_steps = max_steps;
        if (hop_all) {
          no.hop_min_offset = 0;
          no.hop_candidates = 0;
          no.hop_min_cos = -1;
          no.hop_max_evaluations = 1 << 20;
        }
        Trace cont;
        cont.start = cpu_now();
        const qs::NodeOptResult rc = qs::optimize_nodes(c.mesh, start, options, no, &cont);
        const double t_cont = cpu_now() - cont.start;

        qs::NodeOptOptions plain = no;
        plain.hop_polish = false;
        Trace desc;
        desc.start = cpu_now();
        const qs::NodeOptResult rd = qs::optimize_nodes(c.mesh, start, options, plain, &desc);
        const double t_desc = cpu_now() - desc.start;

        qs::DiscreteOptions d;
        d.max_steps = max_steps;
        d.max_evaluations = 1 << 30;  // no work cap: run to its own end
        const double t0 = cpu_now();
        const qs::NodeOptResult rx = qs::relocate_nodes_discrete(c.mesh, start, options, d);
        const double t_disc = cpu_now() - t0;
        const double reach = cont.time_to(rx.E_final);
        std::printf("%s | %zu | %zu | %d | %.6g | %.6g (%.2f) | %.6g (%.2f) | %.6g (%.2f, %d) | ",
                    c.name.c_str(), static_cast<size_t>(c.mesh.n_faces()), c.layout.nodes.size(),
                    k > 0 ? seed : 0, rc.E_init, rc.E_final, t_cont, rd.E_final, t_desc, rx.E_final,
                    t_disc, rx.steps);
        if (reach >= 0)
          std::printf("%.2f | %.1f\n", reach, t_disc / std::max(reach, 1e-9));
        else
          std::printf("never | –\n");
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qs_relocation_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
