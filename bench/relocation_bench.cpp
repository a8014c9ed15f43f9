// Continuous vs discrete node relocation (issue #5, paper §6.3): on perturbed layouts, the
// final E and the CPU time of the continuous optimizer (optimize_nodes, defaults; and its
// descent alone, the paper's method without our hop polish) against the discrete baseline
// (relocate_nodes_discrete: every candidate vertex a full solve). Also the CPU time at which the
// continuous run first reaches the discrete run's final E. Not a test.
//
//   qs_relocation_bench [--rings K] [--seeds N] [--max-steps S] [--case NAME] [--hop-all]
//                       [--no-discrete] [--verbose] [--gradient exact] [--hop-OPTION VALUE ...]
//                       [--mesh FILE --layout FILE] [--discrete-cap S]
//
// --mesh, --layout: one case, this mesh and layout (e.g. the paper's models with cage layouts),
// instead of the built-in cases; unperturbed unless --rings is given.
// --discrete-cap S: the discrete run ends after S CPU seconds with the moves made so far (the
// paper's comparison capped it at 1 h). The ratio is then a lower bound (printed with ≥): the
// whole discrete run would take longer. Also printed: the CPU time at which the discrete run
// first reaches the continuous run's final E (its trajectory move by move), or "not within".
// The continuous column also gives its fold-overs at the end and E / fold-overs before the
// fold-over removal (orientation constraints, which can raise E); the discrete run removes none.
// --hop-all: the continuous run's hop polish tries every neighbour of every relocated node (no
// offset, direction or work limit), an experiment against the defaults.
// --no-discrete: only the continuous run (E, CPU time, hop sweeps, hops, steps, fold-overs).
// --verbose: the continuous run's steps, and per movable node at its end the valence, the angle
// deficit at its vertex, its relocation offset and the best-fitting vertex within 2 rings.
// --hop-min-offset X, --hop-candidates N, --hop-max-evaluations N, --hop-max-failures N,
// --hop-collective 0|1, --hop-cones 0|1, --hop-cone-rings N, --hop-cone-targets N,
// --hop-cone-max-failures N, --hop-rounds N, --stall-gain X, --hop-alpha-growth X:
// NodeOptTuning::hop_* / max_hop_rounds / stall_gain / hop_alpha_growth. A polish without
// the cone and collective passes, for comparison: --hop-cones 0 --hop-collective 0
// --hop-min-offset 0.25 --hop-max-evaluations 16 --hop-max-failures 0.
//
// Cases are built in process (tests/fixtures.cpp): the bundled ellipsoid sketch
// (assets/example), a cube layout on an ellipsoid (cube_sphere(12), radii 1.3 / 1 / 0.75), the
// 4×2 torus grid, the genus-2 polycube (48 nodes) and, when ../shared is present, spot's quad
// layout. Times are CPU seconds of the process (CLOCK_PROCESS_CPUTIME_ID) with the math
// libraries limited to one thread, so a shared machine does not inflate them.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "bench/bench_util.h"
#include "core/base/allocator.h"
#include "core/base/solver_threads.h"
#include "core/import/perturb.h"
#include "core/import/quad_import.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/discrete.h"
#include "core/nodeopt/optimizer.h"
#include "tests/fixtures.h"

namespace {

double cpu_now() {
  return qs::bench::cpu_seconds();
}

// E reaches \p target: equal up to round-off, or below \p floor (values under it are round-off;
// the polycube's exact layouts end at 1e-22 with E_init 30).
bool reaches(double E, double target, double floor) {
  return E <= std::max(target * (1 + 1e-12), floor);
}

// Records (CPU time since start, E) of every accepted step.
struct Trace : qs::Observer {
  double start = 0;
  bool verbose = false;  // print every step
  std::vector<std::pair<double, double>> accepted;
  void on_step(const qs::StepReport& r) override {
    if (verbose)
      std::printf("  step %d %s E %.6g %s moved %d α %.3g (%.2f s)\n", r.step, r.phase.c_str(), r.E,
                  r.accepted ? "accepted" : "rejected", r.moved_nodes, r.step_size,
                  cpu_now() - start);
    if (r.accepted) accepted.push_back({cpu_now() - start, r.E});
  }
  // CPU time at which E first reached \p target (see reaches; negative: never).
  double time_to(double target, double floor) const {
    for (const auto& [t, E] : accepted)
      if (reaches(E, target, floor)) return t;
    return -1;
  }
};

struct Case {
  std::string name;
  qs::TriMesh mesh;
  qs::Layout layout;
  int rings = 3;
};

// Angle deficit (2π − angle sum) at vertex v of \p mesh, in degrees.
double deficit_deg(const qs::TriMesh& mesh, int v) {
  const auto vh = mesh.vertex_handle(v);
  double sum = 0;
  for (auto h : mesh.voh_range(vh)) {
    if (mesh.is_boundary(h)) continue;
    const qs::Vec3 a = mesh.point(mesh.to_vertex_handle(h)) - mesh.point(vh);
    const qs::Vec3 b =
        mesh.point(mesh.to_vertex_handle(mesh.next_halfedge_handle(h))) - mesh.point(vh);
    sum += std::acos(std::clamp((a | b) / (a.norm() * b.norm()), -1.0, 1.0));
  }
  return (2 * M_PI - sum) * 180 / M_PI;
}

// Per movable node of the result: valence, deficit at its vertex, relocation offset (mean
// edges), and the vertex within 2 rings whose deficit best matches the node's index.
void print_nodes(const qs::TriMesh& original, const qs::NodeOptResult& r) {
  const double mean_edge = qs::build_geometry(original).mean_edge_length;
  for (int n : qs::movable_nodes(original, r.layout)) {
    const auto& node = r.layout.nodes[n];
    int valence = 0;
    for (const auto& a : r.layout.arcs) valence += (a.from == node.id) + (a.to == node.id);
    const double want = (4 - valence) * 90.0;
    const int v = node.vertex;
    const auto vh = original.vertex_handle(v);
    const double d = (r.mesh.point(vh) - original.point(vh)).norm() / mean_edge;
    int best = v, best_ring = 0;
    double best_err = std::abs(deficit_deg(original, v) - want);
    for (auto w1 : original.vv_range(vh)) {
      for (int ring : {1, 2}) {
        std::vector<int> ws;
        if (ring == 1)
          ws.push_back(w1.idx());
        else
          for (auto w2 : original.vv_range(w1)) ws.push_back(w2.idx());
        for (int w : ws) {
          const double err = std::abs(deficit_deg(original, w) - want);
          if (err < best_err - 1e-9) best = w, best_err = err, best_ring = ring;
        }
      }
    }
    std::printf(
        "  node %d val %d deficit %.1f want %.0f offset %.3f | best %d (ring %d) deficit %.1f\n", n,
        valence, deficit_deg(original, v), want, d, best, best_ring, deficit_deg(original, best));
  }
}

}  // namespace

int main(int argc, char** argv) {
  qs::keep_freed_memory();  // as quadsketch-cli and the GUI (core/base/allocator.h)
  int rings = -1, seeds = 2, max_steps = 25;
  bool hop_all = false;      // the hop polish tries every neighbour of every node
  bool no_discrete = false;  // skip the descent-only and discrete runs
  bool verbose = false;      // print the continuous run's steps
  std::string only, mesh_file, layout_file;
  double discrete_cap = 0;  // CPU seconds (≤ 0: none)
  qs::NodeOptOptions hop;   // hop polish settings (--hop-* flags)
  for (int i = 1; i < argc; i += 2) {
    if (!std::strcmp(argv[i], "--hop-all")) {
      hop_all = true;
      --i;
    } else if (!std::strcmp(argv[i], "--verbose")) {
      verbose = true;
      --i;
    } else if (!std::strcmp(argv[i], "--no-discrete")) {
      no_discrete = true;
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
    else if (!std::strcmp(argv[i], "--mesh"))
      mesh_file = argv[i + 1];
    else if (!std::strcmp(argv[i], "--layout"))
      layout_file = argv[i + 1];
    else if (!std::strcmp(argv[i], "--discrete-cap"))
      discrete_cap = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-cones"))
      hop.tuning.hop_cones = std::atoi(argv[i + 1]) != 0;
    else if (!std::strcmp(argv[i], "--hop-max-evaluations"))
      hop.tuning.hop_max_evaluations = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-min-offset"))
      hop.tuning.hop_min_offset = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-candidates"))
      hop.tuning.hop_candidates = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-max-failures"))
      hop.tuning.hop_max_failures = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-collective"))
      hop.tuning.hop_collective = std::atoi(argv[i + 1]) != 0;
    else if (!std::strcmp(argv[i], "--hop-cone-rings"))
      hop.tuning.hop_cone_rings = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-cone-targets"))
      hop.tuning.hop_cone_targets = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-cone-max-failures"))
      hop.tuning.hop_cone_max_failures = std::atoi(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--stall-gain"))
      hop.tuning.stall_gain = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--hop-alpha-growth"))
      hop.tuning.hop_alpha_growth = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--gradient"))
      hop.descent.gradient = !std::strcmp(argv[i + 1], "exact") ? qs::GradientMethod::Exact
                                                                : qs::GradientMethod::Estimator;
    else if (!std::strcmp(argv[i], "--hop-rounds"))
      hop.tuning.max_hop_rounds = std::atoi(argv[i + 1]);
    else {
      std::fprintf(stderr,
                   "usage: qs_relocation_bench [--rings K] [--seeds N] [--max-steps S] "
                   "[--case NAME] [--hop-all] [--no-discrete] [--verbose] [--gradient exact] "
                   "[--hop-OPTION VALUE ...] [--mesh FILE --layout FILE] [--discrete-cap S]\n");
      return 2;
    }
  }
  if (mesh_file.empty() != layout_file.empty()) {
    std::fprintf(stderr, "qs_relocation_bench: --mesh and --layout go together\n");
    return 2;
  }
  qs::set_solver_threads(1);
  try {
    std::vector<Case> cases;
    if (!mesh_file.empty()) {
      Case c{mesh_file.substr(mesh_file.find_last_of('/') + 1), qs::load_mesh(mesh_file), {}, 0};
      c.layout = qs::load_layout(layout_file, c.mesh);
      cases.push_back(std::move(c));
    } else {
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
        qs::QuadImportResult imp = qs::import_quads(
            qs::load_poly_mesh(dir + "/spot/spot_quadrangulated.obj"), nullptr, {});
        cases.push_back({"spot", std::move(imp.mesh), std::move(imp.layout), 2});
      }
    }
    std::printf(
        "case | faces | nodes | seed | E_init | continuous E (CPU s) | descent only E (CPU s) "
        "| discrete E (CPU s, sweeps) | continuous reaches discrete E at (CPU s) | time ratio "
        "discrete / continuous-to-reach | discrete reaches continuous E at (CPU s)\n");
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
        qs::NodeOptOptions no = hop;
        no.descent.max_steps = max_steps;
        // CPU time compares the methods: both solve one candidate at a time (the second threads
        // of run.threads ≥ 2 and DiscreteOptions::parallel shorten the wall time but add CPU,
        // most on small meshes: the discrete ellipsoid run 1.4 s → 1.8 s).
        no.run.threads = 1;
        if (hop_all) {
          no.tuning.hop_min_offset = 0;
          no.tuning.hop_candidates = 0;
          no.tuning.hop_min_cos = -1;
          no.tuning.hop_max_evaluations = 1 << 20;
          no.tuning.hop_max_failures = 0;
        }
        Trace cont;
        cont.verbose = verbose;
        cont.start = cpu_now();
        const qs::NodeOptResult rc = qs::optimize_nodes(c.mesh, start, options, no, &cont);
        const double t_cont = cpu_now() - cont.start;
        if (verbose) print_nodes(c.mesh, rc);
        if (no_discrete) {
          std::printf(
              "%s | %zu | %zu | %d | %.6g | %.6g (%.2f) | hop sweeps %d, hops %d, steps %d, "
              "fold-overs %d\n",
              c.name.c_str(), static_cast<size_t>(c.mesh.n_faces()), c.layout.nodes.size(),
              k > 0 ? seed : 0, rc.E_init, rc.E_final, t_cont, rc.hop_rounds, rc.hops, rc.steps,
              rc.foldovers_final);
          std::fflush(stdout);
          continue;
        }

        qs::NodeOptOptions plain = no;
        plain.polish.enabled = false;
        Trace desc;
        desc.start = cpu_now();
        const qs::NodeOptResult rd = qs::optimize_nodes(c.mesh, start, options, plain, &desc);
        const double t_desc = cpu_now() - desc.start;

        qs::DiscreteOptions d;
        d.max_steps = max_steps;
        d.max_evaluations = 1 << 30;  // no work cap: run to its own end
        d.parallel = false;
        const double t0 = cpu_now();
        bool capped = false;
        if (discrete_cap > 0) {
          d.stop = [&]() { return capped = capped || cpu_now() - t0 > discrete_cap; };
        }
        // The discrete trajectory, move by move: when it first reaches the continuous final E.
        double disc_reach = -1;
        d.on_move = [&](double E) {
          if (disc_reach < 0 && reaches(E, rc.E_final, 1e-12 * rc.E_init))
            disc_reach = cpu_now() - t0;
        };
        const qs::NodeOptResult rx = qs::relocate_nodes_discrete(c.mesh, start, options, d);
        const double t_disc = cpu_now() - t0;
        const double reach = cont.time_to(rx.E_final, 1e-12 * rc.E_init);
        std::printf(
            "%s | %zu | %zu | %d | %.6g | %.6g (%.2f; %d folds, before removal %.6g / %d) | %.6g "
            "(%.2f) | %.6g (%.2f, %d%s; %d folds) | ",
            c.name.c_str(), static_cast<size_t>(c.mesh.n_faces()), c.layout.nodes.size(),
            k > 0 ? seed : 0, rc.E_init, rc.E_final, t_cont, rc.foldovers_final, rc.E_descent,
            rc.foldovers_descent, rd.E_final, t_desc, rx.E_final, t_disc, rx.steps,
            capped ? ", capped" : "", rx.foldovers_final);
        if (reach >= 0)
          std::printf("%.2f | %s%.1f", reach, capped ? "≥ " : "", t_disc / std::max(reach, 1e-9));
        else
          std::printf("never | –");
        if (disc_reach >= 0)
          std::printf(" | %.2f\n", disc_reach);
        else
          std::printf(" | not within %.0f s\n", t_disc);
        std::fflush(stdout);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "qs_relocation_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
