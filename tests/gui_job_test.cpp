// The editor's worker job (app/gui/pipeline_job.cpp) on the bundled example, GL-free: metrics,
// timings and node positions per step, the quad mesh at the final step, and the exports.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/gui/history.h"
#include "app/gui/pipeline_job.h"
#include "core/import/perturb.h"
#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "core/nodeopt/optimizer.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"
#include "tests/gui_job_fixture.h"

namespace qs::app {
namespace {

namespace fs = std::filesystem;

using test::Example;
using test::example;

//! Options of a run of \p max_steps steps that publishes every step.
WorkerOptions steps(int max_steps) {
  WorkerOptions options;
  options.max_steps = max_steps;
  options.publish_interval_ms = 0;
  return options;
}

TEST(GuiJob, StreamsMetricsHistoryQuadsAndExports) {
  const Example ex = example();
  const WorkerOptions options = steps(2);  // initial solve + one node-optimization step
  const auto s = test::run_job(ex, options);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  ASSERT_EQ(s->iteration, 2);

  // Metrics and timings of the last step.
  EXPECT_TRUE(std::isfinite(s->energy_init));
  ASSERT_TRUE(s->metrics.valid);
  EXPECT_TRUE(std::isfinite(s->metrics.E));
  EXPECT_GE(s->metrics.E_confor, 2.0 - 1e-9);
  EXPECT_GE(s->metrics.E_angle_deg, 0.0);
  EXPECT_LE(s->metrics.E_angle_deg, 45.0 + 1e-9);
  EXPECT_TRUE(std::isfinite(s->metrics.E_planar));
  EXPECT_GE(s->metrics.foldovers, 0);
  EXPECT_GE(s->metrics.field_ms, 0.0);
  EXPECT_GE(s->metrics.param_ms, 0.0);
  EXPECT_GE(s->metrics.nodeopt_ms, 0.0);  // a node-optimization step
  EXPECT_GE(s->metrics.total_ms, s->metrics.param_ms);

  // One node frame per step, one position per layout node.
  ASSERT_EQ(s->node_history.size(), 2u);
  for (const auto& frame : s->node_history) {
    ASSERT_TRUE(frame);
    EXPECT_EQ(frame->ids.size(), ex.layout.nodes.size());
    EXPECT_EQ(frame->positions.size(), frame->ids.size());
  }
  EXPECT_EQ(scrub_index(5, int(s->node_history.size()), false), 1);

  // Quad mesh built at the final step, on the worker.
  ASSERT_TRUE(s->quads) << s->message;
  EXPECT_GT(s->quads->quads.size(), 0u);
  EXPECT_GT(s->quads->quad_size, 0.0);
  for (const auto& q : s->quads->quads)
    for (int v : q) ASSERT_TRUE(v >= 0 && v < int(s->quads->vertices.size()));

  // Exports from the immutable snapshot data.
  ASSERT_TRUE(s->exports);
  const fs::path dir = fs::temp_directory_path() / "qs_gui_job_test_exports";
  fs::remove_all(dir);
  const auto written = write_job_exports(*s->exports, dir.string(), ExportSelection{});
  EXPECT_EQ(written.size(), 5u);
  for (const char* name :
       {"param.obj", "layout.json", "quads.obj", "patches.json", "layout_curves.obj"}) {
    EXPECT_TRUE(fs::exists(dir / name)) << name;
    EXPECT_GT(fs::file_size(dir / name), 0u) << name;
  }
  // The written layout loads back on the job's mesh.
  EXPECT_NO_THROW(load_layout((dir / "layout.json").string(), s->exports->mesh));
  EXPECT_THROW(write_job_exports(*s->exports, "", ExportSelection{}), std::exception);
  fs::remove_all(dir);
}

TEST(GuiJob, ExportWithoutQuadMeshFailsClearly) {
  JobExports data;
  EXPECT_THROW(write_job_exports(data, (fs::temp_directory_path() / "qs_gui_job_noquads").string(),
                                 ExportSelection{false, false, true}),
               std::exception);
}

}  // namespace

// Each node-optimization step displays the Pipeline the optimizer hands back (no second solve):
// its energy is the one of a Pipeline built from scratch on the step's mesh and layout.
TEST(GuiJob, DisplayedStepMatchesFreshSolve) {
  const Example ex = example();
  const WorkerOptions options = steps(3);  // initial solve + two node-optimization steps
  const auto s = test::run_job(ex, options);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  ASSERT_TRUE(s->exports);
  Layout layout = s->exports->layout;
  for (auto& arc : layout.arcs) arc.polyline.clear(), arc.samples.clear(), arc.label.clear();
  layout.patches.clear();
  qs::PipelineOptions po;  // as the job sets them from WorkerOptions
  po.field.constraints.curvature = options.align;
  po.field.constraints.sharp_angle_deg = options.sharp_angle_deg;
  po.param.anisotropy = options.anisotropy;
  qs::Pipeline fresh(s->exports->mesh, layout, po);
  const double E = fresh.compute_parameterization().energy;
  // The optimizer's last solve may add the orientation constraints (when the plain one folds).
  qs::PipelineOptions oriented = po;
  oriented.param.orientation = qs::OrientationOptions{};
  oriented.param.orientation.enabled = true;
  qs::Pipeline fresh_oriented(s->exports->mesh, layout, oriented);
  const double E_oriented = fresh_oriented.compute_parameterization().energy;
  EXPECT_TRUE(std::abs(s->energy - E) <= 1e-9 * E || std::abs(s->energy - E_oriented) <= 1e-9 * E)
      << "displayed " << s->energy << ", fresh " << E << ", fresh oriented " << E_oriented;
  ASSERT_EQ(s->exports->corner_uv.size(), fresh.parameterization()->corner_uv.size());
}

// Without node optimization the sketch's fixed nodes fold; with "Remove fold-overs" the job's
// one solve adds the orientation constraints (as `optimize --no-node-opt --orientation`): no
// fold-over, an equivalent layout, the same node vertices, and the message says what happened.
TEST(GuiJob, FixedNodesRemoveFoldoversWhenAsked) {
  const Example ex = example();
  WorkerOptions options = steps(1);
  options.node_optimization = false;
  const auto plain = test::run_job(ex, options);
  ASSERT_EQ(plain->status, WorkerStatus::Finished) << plain->message;
  ASSERT_GT(plain->metrics.foldovers, 0) << plain->message;
  EXPECT_EQ(plain->message.find("orientation"), std::string::npos) << plain->message;
  options.remove_foldovers = true;
  const auto oriented = test::run_job(ex, options);
  ASSERT_EQ(oriented->status, WorkerStatus::Finished) << oriented->message;
  EXPECT_EQ(oriented->metrics.foldovers, 0) << oriented->message;
  EXPECT_NE(oriented->message.find("structurally equivalent"), std::string::npos)
      << oriented->message;
  EXPECT_EQ(oriented->message.find("NOT structurally"), std::string::npos) << oriented->message;
  EXPECT_NE(oriented->message.find("by orientation constraints"), std::string::npos)
      << oriented->message;
  ASSERT_TRUE(plain->exports && oriented->exports);
  const Layout& a = plain->exports->layout;
  const Layout& b = oriented->exports->layout;
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t n = 0; n < a.nodes.size(); ++n) EXPECT_EQ(a.nodes[n].vertex, b.nodes[n].vertex);
  // With node optimization on, the option changes nothing (the optimizer removes fold-overs
  // at its end anyway): the initial solve still shows the sketch's fold-overs.
  WorkerOptions with_nodeopt = steps(1);
  with_nodeopt.remove_foldovers = true;
  const auto first = test::run_job(ex, with_nodeopt);
  ASSERT_EQ(first->status, WorkerStatus::Finished) << first->message;
  EXPECT_EQ(first->metrics.foldovers, plain->metrics.foldovers) << first->message;
}

// "Wrap free holes" (WorkerOptions::wrap_free_holes) reaches the field: on a flat square with a
// free hole the default (capped hole) gives the exact, isometric solve; wrapping the iso-lines
// around the hole distorts and folds (as --wrap-free-holes).
TEST(GuiJob, WrapFreeHolesReachesTheField) {
  const test::MeshAndLayout sq = test::flat_square_with_free_hole();
  const Example ex{std::make_shared<const TriMesh>(sq.mesh), sq.layout};
  WorkerOptions options = steps(1);
  options.node_optimization = false;
  options.align = false;
  const auto capped = test::run_job(ex, options);
  ASSERT_EQ(capped->status, WorkerStatus::Finished) << capped->message;
  options.wrap_free_holes = true;
  const auto wrapped = test::run_job(ex, options);
  ASSERT_EQ(wrapped->status, WorkerStatus::Finished) << wrapped->message;
  std::printf("[stat] flat square with a free hole in the editor: E %.3g capped, %.3g wrapped\n",
              capped->metrics.E, wrapped->metrics.E);
  EXPECT_LT(capped->metrics.E, 1e-9);
  EXPECT_EQ(capped->metrics.foldovers, 0);
  EXPECT_GT(wrapped->metrics.E, 1.0);
  EXPECT_GT(wrapped->metrics.foldovers, 0);
}

// Two states have the same mesh positions and node vertices.
void expect_same_state(const TriMesh& a, const Layout& la, const TriMesh& b, const Layout& lb) {
  ASSERT_EQ(a.n_vertices(), b.n_vertices());
  int moved_differently = 0;
  for (auto v : a.vertices()) moved_differently += a.point(v) != b.point(v);
  EXPECT_EQ(moved_differently, 0);
  ASSERT_EQ(la.nodes.size(), lb.nodes.size());
  for (size_t n = 0; n < la.nodes.size(); ++n)
    EXPECT_EQ(la.nodes[n].vertex, lb.nodes[n].vertex) << "node " << n;
}

// The editor's final state and the engine's result are the same, with the same E.
void expect_same_result(const Snapshot& editor, const OptimizeResult& engine) {
  const Pipeline& p = *engine.pipeline;
  ASSERT_TRUE(editor.exports);
  expect_same_state(editor.exports->mesh, editor.exports->layout, p.mesh(), p.layout());
  const Parameterization& param = *p.parameterization();
  EXPECT_NEAR(editor.energy, param.energy, 1e-9 * std::max(1.0, param.energy));
  EXPECT_EQ(editor.metrics.foldovers, param.foldovers);
}

// A Run whose fold-over removal fails retries by itself as `quadsketch-cli optimize` does (keep
// nodes apart, then the sizing field, while they are left on Auto) and ends where the engine's
// one-call optimize() ends. The case: the flat square whose free hole the field wraps ("Wrap
// free holes"), which folds wherever the nodes go when the untangling is off, so both retries
// run; an explicit choice (On or Off) runs no retry for that setting.
TEST(GuiJob, RunRetriesAsTheCommandLineDoes) {
  const test::MeshAndLayout sq = test::flat_square_with_free_hole();
  const Example ex{std::make_shared<const TriMesh>(sq.mesh), sq.layout};
  WorkerOptions options;
  options.publish_interval_ms = 0;
  options.align = false;
  options.wrap_free_holes = true;
  options.untangle = false;
  ASSERT_FALSE(options.sizing.has_value());
  ASSERT_FALSE(options.keep_nodes_apart.has_value());
  const auto editor = test::run_job(ex, options);
  ASSERT_EQ(editor->status, WorkerStatus::Finished) << editor->message;
  const OptimizeResult engine = optimize(sq.mesh, sq.layout, optimize_settings(options));
  ASSERT_TRUE(engine.nodes);
  ASSERT_GT(engine.nodes->foldovers_final, 0) << "the case must fold";
  ASSERT_TRUE(engine.keep_apart_retry) << "the case must need the keep-apart retry";
  ASSERT_TRUE(engine.sizing_retry) << "the case must need the sizing retry";
  expect_same_result(*editor, engine);
  options.sizing = false;
  options.keep_nodes_apart = false;
  const OptimizeResult decided = optimize(sq.mesh, sq.layout, optimize_settings(options));
  EXPECT_FALSE(decided.keep_apart_retry);
  EXPECT_FALSE(decided.sizing_retry);
}

// "Separate crowded nodes" (WorkerOptions::separate_nodes) reaches the node optimization: on a
// displaced refined cube with nodes on each other's 1-ring, the first state the job shows has
// the nodes where separate_nodes puts them; without it, where they were sketched.
TEST(GuiJob, SeparateCrowdedNodesMovesThemBeforeTheRun) {
  const test::MeshAndLayout cube = test::crowded_refined_cube();
  const Layout& crowded = cube.layout;
  const SeparateNodesResult expected = separate_nodes(cube.mesh, crowded, {});
  ASSERT_GE(expected.moved_nodes.size(), 2u);
  const Example ex{std::make_shared<const TriMesh>(cube.mesh), crowded};
  for (const bool separate : {false, true}) {
    WorkerOptions options = steps(2);
    options.separate_nodes = separate;
    const auto done = test::run_job(ex, options);
    ASSERT_EQ(done->status, WorkerStatus::Finished) << done->message;
    ASSERT_FALSE(done->node_history.empty());
    EXPECT_EQ(done->energy_history.size(), 2u) << "one initial solve, one step";
    const NodeFrame& first = *done->node_history.front();
    const Layout& start = separate ? expected.layout : crowded;
    for (int id : expected.moved_nodes) {
      const auto it = std::find(first.ids.begin(), first.ids.end(), id);
      ASSERT_NE(it, first.ids.end()) << "node " << id;
      const auto& p = first.positions[it - first.ids.begin()];
      const Vec3 want =
          cube.mesh.point(cube.mesh.vertex_handle(start.nodes[start.node_index(id)].vertex));
      EXPECT_NEAR((Vec3(p[0], p[1], p[2]) - want).norm(), 0, 1e-5)
          << "node " << id << (separate ? " separated" : " as sketched");
    }
  }
}

// "Sizing field" (WorkerOptions::sizing) reaches the parameterization: on the bundled sketch
// with fixed nodes the sized targets give a lower residual and no fold-over (as `optimize
// --no-node-opt --sizing`), while the default unit targets fold.
TEST(GuiJob, SizingFieldReachesTheParameterization) {
  const Example ex = example();
  WorkerOptions options = steps(1);
  options.node_optimization = false;
  ASSERT_FALSE(options.sizing) << "the editor follows the library default (off)";
  const auto unit = test::run_job(ex, options);
  ASSERT_EQ(unit->status, WorkerStatus::Finished) << unit->message;
  options.sizing = true;
  const auto sized = test::run_job(ex, options);
  ASSERT_EQ(sized->status, WorkerStatus::Finished) << sized->message;
  std::printf(
      "[stat] bundled sketch in the editor: E %.4g unit targets (%d fold-overs), %.4g sized (%d)\n",
      unit->metrics.E, unit->metrics.foldovers, sized->metrics.E, sized->metrics.foldovers);
  EXPECT_LT(sized->metrics.E, unit->metrics.E);
  EXPECT_GT(unit->metrics.foldovers, 0);
  EXPECT_EQ(sized->metrics.foldovers, 0);
}

// A run with the default settings ends where the engine of `quadsketch-cli optimize` ends:
// the same units (descent steps, hop sweeps, fold-over removal, retries), so the same final mesh
// and node vertices, below the descent alone.
TEST(GuiJob, RunEndsWhereTheOptimizerEnds) {
  const Example ex = example();
  WorkerOptions options;
  options.publish_interval_ms = 0;
  const auto s = test::run_job(ex, options);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  ASSERT_TRUE(s->exports);
  ASSERT_LT(s->iteration, options.max_steps);  // ended by itself
  EXPECT_EQ(int(s->node_history.size()), s->iteration);
  const OptimizeResult r = optimize(*ex.mesh, ex.layout, optimize_settings(options));
  ASSERT_TRUE(r.nodes);
  ASSERT_GT(r.nodes->hop_rounds, 0);
  expect_same_result(*s, r);

  OptimizeSettings descent = optimize_settings(options);
  NodeOptOptions no = node_options(descent);
  no.polish.enabled = false;
  const NodeOptResult d = optimize_nodes(*ex.mesh, ex.layout, pipeline_options(descent), no);
  std::printf("[stat] editor run: %d steps, E %.6g (descent alone %.6g)\n", s->iteration,
              s->metrics.E, d.E_final);
  EXPECT_LT(s->metrics.E, d.E_final * 0.99);
}

// The editor's Run and `quadsketch-cli optimize` are one engine: on the bundled example with
// the default settings both write the same node vertices, mesh positions and E.
TEST(GuiJob, EditorRunEqualsTheCommandLine) {
  const Example ex = example();
  WorkerOptions options;
  options.publish_interval_ms = 0;
  const auto editor = test::run_job(ex, options);
  ASSERT_EQ(editor->status, WorkerStatus::Finished) << editor->message;
  ASSERT_TRUE(editor->exports);

  const std::string dir = test::temp_dir("editor_equals_cli");
  const fs::path assets = fs::path(QS_ASSETS_DIR) / "example";
  std::string log;
  ASSERT_EQ(test::run_command(test::cli_path() + " optimize --quiet --mesh " +
                                  (assets / "ellipsoid.obj").string() + " --layout " +
                                  (assets / "ellipsoid.layout.json").string() + " --out " + dir,
                              &log),
            0)
      << log;
  const TriMesh cli_mesh = load_mesh(dir + "/param.obj");
  const Layout cli_layout = load_layout(dir + "/layout.json", cli_mesh);
  // param.obj stores positions with 17 digits: exactly.
  expect_same_state(cli_mesh, cli_layout, editor->exports->mesh, editor->exports->layout);
  std::ifstream report_file(dir + "/report.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  EXPECT_NEAR(report["E_final"].get<double>(), editor->metrics.E,
              1e-9 * std::max(1.0, editor->metrics.E));
  EXPECT_EQ(report["metrics"]["foldovers"].get<int>(), editor->metrics.foldovers);
  fs::remove_all(dir);
}

// A node pinned between steps keeps its position for the rest of the run (the fold-over
// removal included), while the others go on moving.
TEST(GuiJob, NodePinnedMidRunStaysPut) {
  using namespace std::chrono_literals;
  const Example ex = example();
  WorkerOptions options;
  options.publish_interval_ms = 0;
  Worker worker(pipeline_step);
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{ex.mesh, ex.layout});
  worker.send(cmd::Step{3});  // the initial solve and two descent steps
  auto s = worker.wait_for(
      [](const Snapshot& x) { return x.iteration >= 3 && x.status != WorkerStatus::Running; }, 60s);
  ASSERT_EQ(s->iteration, 3) << s->message;
  ASSERT_TRUE(s->layout && s->exports);
  const LayoutNode& node = s->layout->nodes[0];
  const int id = node.id, vertex = node.vertex;
  const auto position = s->exports->mesh.point(s->exports->mesh.vertex_handle(vertex));
  const auto frame_position = [&](const NodeFrame& f) {
    for (size_t k = 0; k < f.ids.size(); ++k)
      if (f.ids[k] == id) return f.positions[k];
    ADD_FAILURE() << "node " << id << " missing in a frame";
    return std::array<float, 3>{};
  };
  const std::array<float, 3> pinned_at = frame_position(*s->node_history.back());
  worker.send(cmd::SetPin{id, vertex});
  worker.send(cmd::Run{});
  s = worker.wait_for(
      [](const Snapshot& x) {
        return x.status == WorkerStatus::Finished || x.status == WorkerStatus::Failed;
      },
      120s);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  ASSERT_GT(s->iteration, 5);
  for (size_t k = 3; k < s->node_history.size(); ++k)
    EXPECT_EQ(frame_position(*s->node_history[k]), pinned_at) << "frame " << k;
  // The others moved after the pin.
  const NodeFrame& before = *s->node_history[2];
  const NodeFrame& after = *s->node_history.back();
  int others_moved = 0;
  for (size_t k = 0; k < after.ids.size(); ++k)
    others_moved += after.ids[k] != id && after.positions[k] != before.positions[k];
  EXPECT_GT(others_moved, 0);
  const Layout& out = s->exports->layout;
  const auto it = std::find_if(out.nodes.begin(), out.nodes.end(),
                               [&](const LayoutNode& n) { return n.id == id; });
  ASSERT_NE(it, out.nodes.end());
  EXPECT_EQ(it->vertex, vertex);
  EXPECT_TRUE(it->pinned);
  EXPECT_EQ(s->exports->mesh.point(s->exports->mesh.vertex_handle(vertex)), position);
}

// An arc pinned between steps (SetArcPin) keeps its route and its end nodes for the rest of the
// run, and the run goes on (the job is not restarted: its step count and history continue).
TEST(GuiJob, ArcPinnedMidRunKeepsTheJobAndStaysPut) {
  using namespace std::chrono_literals;
  const Example ex = example();
  WorkerOptions options;
  options.publish_interval_ms = 0;
  Worker worker(pipeline_step);
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{ex.mesh, ex.layout});
  worker.send(cmd::Step{3});
  auto s = worker.wait_for(
      [](const Snapshot& x) { return x.iteration >= 3 && x.status != WorkerStatus::Running; }, 60s);
  ASSERT_EQ(s->iteration, 3) << s->message;
  const std::uint64_t generation = s->generation;
  const LayoutArc arc = s->layout->arcs[0];
  const std::vector<int> ends{arc.from, arc.to};
  const auto frame_positions = [&](const NodeFrame& f) {
    std::vector<std::array<float, 3>> out;
    for (int id : ends)
      for (size_t k = 0; k < f.ids.size(); ++k)
        if (f.ids[k] == id) out.push_back(f.positions[k]);
    return out;
  };
  const auto pinned_at = frame_positions(*s->node_history.back());
  ASSERT_EQ(pinned_at.size(), 2u);
  const auto pin_seq = worker.send(cmd::SetArcPin{arc.id, true});
  worker.send(cmd::Run{});
  s = worker.wait_for(
      [](const Snapshot& x) {
        return x.status == WorkerStatus::Finished || x.status == WorkerStatus::Failed;
      },
      120s);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  EXPECT_GE(s->applied_seq, pin_seq);
  EXPECT_EQ(s->generation, generation);  // the same job
  ASSERT_GT(s->iteration, 5);
  ASSERT_EQ(s->node_history.size(), std::size_t(s->iteration));
  for (size_t k = 3; k < s->node_history.size(); ++k)
    EXPECT_EQ(frame_positions(*s->node_history[k]), pinned_at) << "frame " << k;
  const int a = s->layout->arc_index(arc.id);
  ASSERT_GE(a, 0);
  EXPECT_TRUE(s->layout->arcs[a].pinned);
  EXPECT_EQ(s->layout->arcs[a].path, arc.path);
}

// A node that the editor's layout pins and that is released during the run (ClearPin) moves
// from then on.
TEST(GuiJob, LayoutPinReleasedMidRunLetsTheNodeMove) {
  using namespace std::chrono_literals;
  Example ex = example();
  ex.layout.nodes[0].pinned = true;
  const int id = ex.layout.nodes[0].id;
  WorkerOptions options;
  options.publish_interval_ms = 0;
  Worker worker(pipeline_step);
  worker.send(cmd::SetOptions{options});
  worker.send(cmd::LoadMesh{ex.mesh, ex.layout});
  worker.send(cmd::Step{3});
  auto s = worker.wait_for(
      [](const Snapshot& x) { return x.iteration >= 3 && x.status != WorkerStatus::Running; }, 60s);
  ASSERT_EQ(s->iteration, 3) << s->message;
  const auto position = [&](const NodeFrame& f) {
    for (size_t k = 0; k < f.ids.size(); ++k)
      if (f.ids[k] == id) return f.positions[k];
    return std::array<float, 3>{};
  };
  const auto before = position(*s->node_history.front());
  EXPECT_EQ(position(*s->node_history.back()), before);  // pinned so far
  worker.send(cmd::ClearPin{id});
  worker.send(cmd::Run{});
  s = worker.wait_for(
      [](const Snapshot& x) {
        return x.status == WorkerStatus::Finished || x.status == WorkerStatus::Failed;
      },
      120s);
  ASSERT_EQ(s->status, WorkerStatus::Finished) << s->message;
  EXPECT_NE(position(*s->node_history.back()), before);
  const int n = s->layout->node_index(id);
  ASSERT_GE(n, 0);
  EXPECT_FALSE(s->layout->nodes[n].pinned);
}

// A run that keeps the layout symmetric (WorkerOptions::symmetry, set by the editor's mirrored
// sketching) on a sketch that is not symmetric fails, naming the first node without a mirror.
TEST(GuiJob, SymmetricRunOfAnAsymmetricSketchFailsNamingTheNode) {
  WorkerOptions options = steps(5);
  options.symmetry = SymmetryAxis::X;
  const SnapshotPtr s = test::run_job(example(), options);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->status, WorkerStatus::Failed);
  EXPECT_NE(s->message.find("not mirror symmetric"), std::string::npos) << s->message;
  EXPECT_NE(s->message.find("node 1 (vertex 758)"), std::string::npos) << s->message;
}

}  // namespace qs::app
