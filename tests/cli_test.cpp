// quadsketch-cli end to end: exit codes, the bad-input corpus, and the output files.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "core/import/perturb.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

namespace fs = std::filesystem;

// The bundled example's mesh (a jittered copy under QS_TEST_JITTER, tests/jitter.h).
const std::string kMesh = test::mesh_file(test::assets_dir() + "/example/ellipsoid.obj");
const std::string kLayout = test::assets_dir() + "/example/ellipsoid.layout.json";  // the sketch
const std::string kExact = test::assets_dir() + "/example/ellipsoid_exact.layout.json";

std::string cli(const std::string& args) {
  return test::cli_path() + " " + args;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// Expected words per broken mesh, from the table in assets/bad/README.md.
std::map<std::string, std::vector<std::string>> mesh_expectations() {
  std::map<std::string, std::vector<std::string>> out;
  std::ifstream in(test::assets_dir() + "/bad/README.md");
  std::string line;
  const std::regex row(R"(^\| `([^`]+)` \|.*\| (.*) \|\s*$)");
  const std::regex word("`([^`]+)`");
  while (std::getline(in, line)) {
    std::smatch m;
    if (!std::regex_match(line, m, row)) continue;
    const std::string cell = m[2];
    for (auto it = std::sregex_iterator(cell.begin(), cell.end(), word);
         it != std::sregex_iterator(); ++it)
      out[m[1]].push_back((*it)[1]);
  }
  return out;
}

const std::map<std::string, std::vector<std::string>> kLayoutExpectations = {
    {"crossing_arcs.layout.json", {"arc_crossing", "arcs 0 and 100"}},
    {"five_sided_patch.layout.json", {"patch_valence", "5 corners", "a full patch needs 4"}},
    {"missing_node.layout.json", {"unknown_node", "arc 3", "unknown node 42"}},
    {"node_vertex_and_point.layout.json",
     {"node 0: has both \"vertex\": 39 and a \"point\" that snaps to vertex"}},
    {"malformed.layout.json", {"malformed JSON", "line"}},
};

TEST(Cli, VersionAndUsage) {
  std::string out;
  EXPECT_EQ(test::run_command(cli("--version"), &out), 0);
  EXPECT_NE(out.find("quadsketch-cli"), std::string::npos);
  EXPECT_EQ(test::run_command(cli("validate --help"), &out), 0);
  EXPECT_NE(out.find("--layout"), std::string::npos);
  EXPECT_EQ(test::run_command(cli("validate --mesh " + kMesh), &out), 1)
      << out;  // --layout missing
  EXPECT_EQ(test::run_command(cli("frobnicate"), &out), 1) << out;
}

TEST(Cli, ValidatesTheExample) {
  std::string out;
  ASSERT_EQ(test::run_command(cli("validate --mesh " + kMesh + " --layout " + kLayout), &out), 0)
      << out;
  EXPECT_NE(out.find("8 nodes (8 irregular), 12 arcs, 6 patches"), std::string::npos) << out;
}

TEST(Cli, MissingFileIsInvalidInput) {
  std::string out;
  EXPECT_EQ(test::run_command(cli("validate --mesh /nonexistent/x.obj --layout " + kLayout), &out),
            2)
      << out;
  EXPECT_NE(out.find("/nonexistent/x.obj"), std::string::npos) << out;
}

TEST(Cli, LayoutThatIsNotARegularFileIsRefusedWithoutReadingOrBlocking) {
  const std::string dir = test::temp_dir("cli_fifo");
  const std::string fifo = dir + "/layout.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // `timeout` turns a run that blocks on the FIFO (or reads /dev/zero for ever) into exit 124.
  for (const auto& [path, kind] : {std::pair<std::string, std::string>{fifo, "a FIFO (named pipe)"},
                                   {"/dev/zero", "a character device"},
                                   {dir, "a directory"}}) {
    std::string out;
    EXPECT_EQ(test::run_command(
                  "timeout 60 " + cli("validate --mesh " + kMesh + " --layout " + path), &out),
              2)
        << out;
    EXPECT_NE(out.find(path + ": cannot open file: it is " + kind + ", not a regular file"),
              std::string::npos)
        << out;
  }
}

TEST(Cli, EveryBrokenInputGivesItsErrorAndExitCode2) {
  const auto mesh_words = mesh_expectations();
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(test::assets_dir() + "/bad")) {
    const std::string name = entry.path().filename().string();
    if (name == "README.md") continue;
    std::string out;
    int code;
    std::vector<std::string> words;
    if (name.size() > 12 && name.substr(name.size() - 12) == ".layout.json") {
      ASSERT_TRUE(kLayoutExpectations.count(name)) << "no expectation for " << name;
      words = kLayoutExpectations.at(name);
      code = test::run_command(
          cli("validate --mesh " + kMesh + " --layout " + entry.path().string()), &out);
    } else {
      ASSERT_TRUE(mesh_words.count(name)) << name << " has no row in assets/bad/README.md";
      words = mesh_words.at(name);
      code = test::run_command(
          cli("validate --mesh " + entry.path().string() + " --layout " + kLayout), &out);
    }
    EXPECT_EQ(code, 2) << name << ":\n" << out;
    for (const auto& w : words)
      EXPECT_NE(out.find(w), std::string::npos) << name << ": missing '" << w << "' in\n" << out;
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

TEST(Cli, FailedRunsWriteAFailedReport) {
  const std::string dir = test::temp_dir("cli_failed");
  std::string out;
  const int code =
      test::run_command(cli("optimize --no-node-opt --mesh " + kMesh + " --layout " +
                            test::assets_dir() + "/bad/five_sided_patch.layout.json --out " + dir),
                        &out);
  EXPECT_EQ(code, 2) << out;
  const auto report = read_json(dir + "/report.json");
  EXPECT_EQ(report["status"], "failed");
  EXPECT_NE(report["message"].get<std::string>().find("patch_valence"), std::string::npos);
}

TEST(Cli, FieldWritesSingularitiesAndDirections) {
  const std::string dir = test::temp_dir("cli_field");
  std::string out;
  ASSERT_EQ(test::run_command(
                cli("field --mesh " + kMesh + " --layout " + kLayout + " --out " + dir), &out),
            0)
      << out;
  const auto report = read_json(dir + "/report.json");
  EXPECT_EQ(report["status"], "ok");
  ASSERT_EQ(report["singularities"].size(), 8u);
  for (const auto& s : report["singularities"]) EXPECT_DOUBLE_EQ(s["index"].get<double>(), 0.25);
  const TriMesh mesh = load_mesh(kMesh);
  std::ifstream field(dir + "/field.txt");
  int lines = 0;
  double x, y, z;
  while (field >> x >> y >> z) {
    EXPECT_NEAR(x * x + y * y + z * z, 1.0, 1e-6);
    ++lines;
  }
  EXPECT_EQ(lines, static_cast<int>(mesh.n_faces()));
}

TEST(Cli, FieldAndOptimizeReportReleasedConstraintsAndWarn) {
  // The curvature clusters of this ellipsoid contradict the cube layout and are released
  // (tests/field_test.cpp): both commands say so in report.json and on stderr, even --quiet.
  const auto in = test::cube_sphere(10, Vec3(2.0, 1.0, 0.75));
  const std::string dir = test::temp_dir("cli_released");
  test::write_obj(in.mesh, dir + "/mesh.obj");
  save_layout(in.layout, dir + "/layout.json", &in.mesh);
  const std::string files = " --mesh " + dir + "/mesh.obj --layout " + dir + "/layout.json";
  auto check = [](const nlohmann::json& c, const std::string& output) {
    const int constrained =
        c["curvature"].get<int>() + c["feature"].get<int>() + c["boundary"].get<int>();
    const auto& f = c["in_force"];
    EXPECT_GT(constrained, 0);
    EXPECT_EQ(f["total"].get<int>(),
              f["curvature"].get<int>() + f["feature"].get<int>() + f["boundary"].get<int>());
    EXPECT_LE(f["curvature"].get<int>(), c["curvature"].get<int>());
    EXPECT_LT(f["total"].get<int>(), constrained / 2);
    EXPECT_GT(c["dropped_clusters"].get<int>(), 0);
    EXPECT_LE(c["dropped_clusters"].get<int>(), c["clusters"].get<int>());
    EXPECT_NE(output.find("warning:"), std::string::npos) << output;
    EXPECT_NE(output.find("released"), std::string::npos) << output;
  };
  std::string out;
  ASSERT_EQ(test::run_command(cli("field" + files + " --out " + dir + "/field"), &out), 0) << out;
  check(read_json(dir + "/field/report.json")["constraints"], out);
  ASSERT_EQ(test::run_command(
                cli("optimize --quiet --no-node-opt" + files + " --out " + dir + "/opt"), &out),
            0)
      << out;
  const auto report = read_json(dir + "/opt/report.json");
  check(report["field"]["constraints"], out);
  EXPECT_EQ(report["field"]["singularities"].get<int>(), 8);
  // With node optimization the warning comes once, before the run, about the initial field.
  ASSERT_EQ(test::run_command(
                cli("optimize --quiet --steps 2" + files + " --out " + dir + "/steps"), &out),
            0)
      << out;
  check(read_json(dir + "/steps/report.json")["field"]["constraints"], out);
  const size_t first = out.find("released");
  ASSERT_NE(first, std::string::npos) << out;
  EXPECT_EQ(out.find("released", first + 1), std::string::npos) << out;
  EXPECT_NE(out.find("optimize (initial field)"), std::string::npos) << out;
  // No constraints, no such warning: the bundled example with --no-align.
  ASSERT_EQ(test::run_command(cli("optimize --quiet --no-node-opt --no-align --mesh " + kMesh +
                                  " --layout " + kLayout + " --out " + dir + "/plain"),
                              &out),
            0)
      << out;
  EXPECT_EQ(out.find("released"), std::string::npos) << out;
  EXPECT_EQ(read_json(dir + "/plain/report.json")["field"]["constraints"]["in_force"]["total"], 0);
}

TEST(Cli, MaxClusterFacesKeepsMoreCurvatureConstraintsInForce) {
  // The same ellipsoid: with --max-cluster-faces 10 the split curvature clusters stay in force
  // where they fit the layout (CrossFieldOptions::max_cluster_faces), in both commands, and the
  // layout's 8 singularities stay. A negative size is a usage error (exit code 1).
  const auto in = test::cube_sphere(10, Vec3(2.0, 1.0, 0.75));
  const std::string dir = test::temp_dir("cli_split_clusters");
  test::write_obj(in.mesh, dir + "/mesh.obj");
  save_layout(in.layout, dir + "/layout.json", &in.mesh);
  const std::string files = " --mesh " + dir + "/mesh.obj --layout " + dir + "/layout.json";
  std::string out;
  ASSERT_EQ(test::run_command(
                cli("field" + files + " --max-cluster-faces 0 --out " + dir + "/whole"), &out),
            0)
      << out;
  ASSERT_EQ(test::run_command(
                cli("field" + files + " --max-cluster-faces 10 --out " + dir + "/split"), &out),
            0)
      << out;
  const auto whole = read_json(dir + "/whole/report.json")["constraints"];
  const auto split = read_json(dir + "/split/report.json")["constraints"];
  EXPECT_GT(split["in_force"]["curvature"].get<int>(),
            whole["in_force"]["curvature"].get<int>() + split["curvature"].get<int>() / 4);
  EXPECT_GE(split["clusters"].get<int>(), split["curvature"].get<int>() / 10);
  ASSERT_EQ(test::run_command(cli("optimize --quiet --no-node-opt --max-cluster-faces 10" + files +
                                  " --out " + dir + "/opt"),
                              &out),
            0)
      << out;
  const auto report = read_json(dir + "/opt/report.json");
  EXPECT_EQ(report["field"]["constraints"]["in_force"]["curvature"],
            split["in_force"]["curvature"]);
  EXPECT_EQ(report["field"]["singularities"].get<int>(), 8);
  EXPECT_EQ(test::run_command(
                cli("field" + files + " --max-cluster-faces -1 --out " + dir + "/bad"), &out),
            1)
      << out;
  EXPECT_NE(out.find("--max-cluster-faces"), std::string::npos) << out;
}

TEST(Cli, OptimizeWithoutNodeOptimizationWritesEverything) {
  const std::string dir = test::temp_dir("cli_optimize");
  std::string out;
  ASSERT_EQ(test::run_command(cli("optimize --no-node-opt --mesh " + kMesh + " --layout " + kExact +
                                  " --out " + dir),
                              &out),
            0)
      << out;
  const auto report = read_json(dir + "/report.json");
  EXPECT_EQ(report["status"], "ok");
  EXPECT_TRUE(report["structurally_equivalent"].get<bool>());
  EXPECT_EQ(report["metrics"]["foldovers"], 0);
  EXPECT_GT(report["E_final"].get<double>(), 0.0);
  EXPECT_GE(report["metrics"]["E_confor"].get<double>(), 2.0);
  for (const char* key :
       {"load", "field", "parameterization", "node_optimization", "extraction", "total"})
    EXPECT_TRUE(report["timings_s"].contains(key)) << key;
  // param.obj: same vertices and faces, one vt per corner.
  const TriMesh mesh = load_mesh(kMesh);
  std::ifstream obj(dir + "/param.obj");
  std::string line;
  int v = 0, vt = 0, f = 0;
  while (std::getline(obj, line)) {
    if (line.rfind("v ", 0) == 0) ++v;
    if (line.rfind("vt ", 0) == 0) ++vt;
    if (line.rfind("f ", 0) == 0) {
      ++f;
      EXPECT_NE(line.find('/'), std::string::npos);
    }
  }
  EXPECT_EQ(v, static_cast<int>(mesh.n_vertices()));
  EXPECT_EQ(f, static_cast<int>(mesh.n_faces()));
  EXPECT_EQ(vt, 3 * f);
  // layout.json is a valid input layout carrying the traced arcs.
  const Layout layout = load_layout(dir + "/layout.json", mesh);
  EXPECT_TRUE(validate_layout(mesh, layout).valid());
  EXPECT_EQ(layout.patches.size(), 6u);
  for (const auto& arc : layout.arcs) {
    EXPECT_TRUE(arc.label == "u" || arc.label == "v");
    EXPECT_GE(arc.samples.size(), 2u);
    EXPECT_EQ(arc.samples.size(), arc.polyline.size());
  }
  for (const auto& p : layout.patches) {
    EXPECT_EQ(p.nodes.size(), 4u);
    EXPECT_GT(p.size[0], 0);
    EXPECT_GT(p.size[1], 0);
  }
}

TEST(Cli, OptimizeMovesTheSketchedNodesAndRemovesFoldovers) {
  // The bundled sketch has nodes 3 rings off; with fixed nodes its parameterization folds.
  const std::string fixed = test::temp_dir("cli_fixed"), moved = test::temp_dir("cli_moved");
  std::string out;
  ASSERT_EQ(test::run_command(cli("optimize --no-node-opt --quiet --mesh " + kMesh + " --layout " +
                                  kLayout + " --out " + fixed),
                              &out),
            0)
      << out;
  ASSERT_EQ(test::run_command(cli("optimize --quiet --mesh " + kMesh + " --layout " + kLayout +
                                  " --out " + moved),
                              &out),
            0)
      << out;
  const auto before = read_json(fixed + "/report.json"), after = read_json(moved + "/report.json");
  EXPECT_GT(before["metrics"]["foldovers"].get<int>(), 0);
  EXPECT_EQ(after["metrics"]["foldovers"].get<int>(), 0);
  EXPECT_TRUE(after["structurally_equivalent"].get<bool>());
  EXPECT_LT(after["E_final"].get<double>(), 0.5 * after["E_init"].get<double>());
  // A retry with nodes kept apart runs only when the first run needed it (core/nodeopt/retry.h).
  const auto& node = after["node_optimization"];
  if (node.contains("keep_apart_retry")) {
    const auto& retry = node["keep_apart_retry"];
    EXPECT_TRUE(retry["foldovers_without"].get<int>() > 0 ||
                retry["untangled_without"].get<bool>() || retry["fell_back_without"].get<bool>())
        << retry.dump();
  }
  ASSERT_GT(after["steps"].size(), 0u);
  double previous = after["E_init"].get<double>();
  for (const auto& step : after["steps"]) {
    if (!step["accepted"].get<bool>() || step["phase"] != "descent") continue;
    EXPECT_LE(step["E"].get<double>(), previous * (1 + 1e-12));
    previous = step["E"].get<double>();
  }
}

// Results never depend on thread timing: the example optimized twice with two math-library
// threads (and the optimizer's own second threads, whose results are used exactly where the
// sequential order would use them) writes the same energy, layout and parameterization, byte
// for byte. With one thread the math library sums in another order, so only the outcome is the
// same: no fold-over, structurally equivalent, E equal to 1e-6.
TEST(Cli, ThreadTimingNeverChangesTheResult) {
  std::string out;
  struct Run {
    nlohmann::json report;
    std::string layout, param;
  };
  const auto run = [&](int threads, const std::string& name) {
    const std::string dir = test::temp_dir(name);
    Run r;
    EXPECT_EQ(test::run_command(cli("optimize --quiet --threads " + std::to_string(threads) +
                                    " --mesh " + kMesh + " --layout " + kLayout + " --out " + dir),
                                &out),
              0)
        << out;
    r.report = read_json(dir + "/report.json");
    std::ifstream layout(dir + "/layout.json"), param(dir + "/param.obj");
    r.layout.assign(std::istreambuf_iterator<char>(layout), {});
    r.param.assign(std::istreambuf_iterator<char>(param), {});
    EXPECT_FALSE(r.layout.empty() || r.param.empty());
    return r;
  };
  const Run a = run(2, "cli_threads_a"), b = run(2, "cli_threads_b"), one = run(1, "cli_threads_1");
  EXPECT_EQ(a.report["E_final"].get<double>(), b.report["E_final"].get<double>());
  EXPECT_TRUE(a.layout == b.layout) << "layout.json differs between two runs";
  EXPECT_TRUE(a.param == b.param) << "param.obj differs between two runs";
  for (const Run* r : {&a, &one}) {
    EXPECT_EQ(r->report["metrics"]["foldovers"].get<int>(), 0);
    EXPECT_TRUE(r->report["structurally_equivalent"].get<bool>());
  }
  const double e1 = one.report["E_final"].get<double>(), e2 = a.report["E_final"].get<double>();
  EXPECT_NEAR(e1, e2, 1e-6 * e2);
}

// --keep-nodes-apart is passed to the node optimization and recorded (the report's
// node_optimization.keep_nodes_apart; no retry then), and it excludes --no-keep-nodes-apart.
// NodeOptOptions::Moves::keep_nodes_apart itself is tested in orientation_displaced_test.cpp, the
// retry rules in retry_test.cpp.
TEST(Cli, KeepNodesApartIsPassedOnAndRecorded) {
  const std::string dir = test::temp_dir("cli_keep_apart");
  std::string out;
  ASSERT_EQ(test::run_command(cli("optimize --keep-nodes-apart --quiet --mesh " + kMesh +
                                  " --layout " + kLayout + " --out " + dir),
                              &out),
            0)
      << out;
  const auto report = read_json(dir + "/report.json");
  const auto& node = report["node_optimization"];
  EXPECT_TRUE(node["keep_nodes_apart"].get<bool>());
  EXPECT_FALSE(node.contains("keep_apart_retry"));
  EXPECT_EQ(report["metrics"]["foldovers"].get<int>(), 0);
  EXPECT_TRUE(report["structurally_equivalent"].get<bool>());
  EXPECT_LT(report["E_final"].get<double>(), 0.5 * report["E_init"].get<double>());
  EXPECT_EQ(test::run_command(cli("optimize --keep-nodes-apart --no-keep-nodes-apart --mesh " +
                                  kMesh + " --layout " + kLayout + " --out " + dir),
                              &out),
            1)
      << out;
  EXPECT_NE(out.find("excludes"), std::string::npos) << out;
  EXPECT_EQ(node["crowded_nodes"].get<int>(), 0);  // nothing separated without --separate-nodes
  EXPECT_TRUE(node["separated_nodes"].empty());

  // A displaced refined cube with nodes on each other's 1-ring: moved apart first with
  // --separate-nodes (their ids recorded), left in place without it.
  const test::MeshAndLayout cube = test::crowded_refined_cube();
  const Layout& crowded = cube.layout;
  const SeparateNodesResult expected = separate_nodes(cube.mesh, crowded, {});
  ASSERT_GE(expected.moved_nodes.size(), 2u);
  save_mesh_obj(cube.mesh, dir + "/cube.obj");
  save_layout(crowded, dir + "/crowded.layout.json", &cube.mesh);
  for (const bool separate : {true, false}) {
    ASSERT_EQ(test::run_command(
                  cli(std::string("optimize --keep-nodes-apart --steps 2") +
                      (separate ? " --separate-nodes" : "") + " --mesh " + dir +
                      "/cube.obj --layout " + dir + "/crowded.layout.json --out " + dir + "/cube"),
                  &out),
              0)
        << out;
    const auto cube_report = read_json(dir + "/cube/report.json");
    const auto& moved = cube_report["node_optimization"]["separated_nodes"];
    EXPECT_EQ(out.find("crowded node(s) moved apart") != std::string::npos, separate) << out;
    if (separate) {
      EXPECT_EQ(cube_report["node_optimization"]["crowded_nodes"].get<int>(),
                static_cast<int>(expected.crowded_nodes.size()));
      EXPECT_EQ(moved.get<std::vector<int>>(), expected.moved_nodes);
    } else {
      EXPECT_EQ(cube_report["node_optimization"]["crowded_nodes"].get<int>(), 0);
      EXPECT_TRUE(moved.empty());
    }
  }
  for (const char* other : {" --no-node-opt", " --discrete-relocation"}) {
    EXPECT_EQ(test::run_command(cli(std::string("optimize --separate-nodes") + other + " --mesh " +
                                    kMesh + " --layout " + kLayout + " --out " + dir),
                                &out),
              2)
        << out;
    EXPECT_NE(out.find("--separate-nodes applies to the continuous node optimization"),
              std::string::npos)
        << out;
  }
}

// --time-limit: the node movement ends at the limit and the run finishes from the state reached
// (the continuous run's fold-over removal, every output), for the continuous and the discrete
// relocation; the report says so. Without --time-limit nothing is limited; with --no-node-opt the
// flag is an input error, and a limit that is not positive a usage error.
TEST(Cli, TimeLimitEndsTheNodeMovementAndFinishes) {
  const std::string dir = test::temp_dir("cli_time_limit");
  std::string out;
  for (const std::string method : {"", " --discrete-relocation"}) {
    SCOPED_TRACE(method);
    ASSERT_EQ(test::run_command(cli("optimize --mesh " + kMesh + " --layout " + kLayout +
                                    " --out " + dir + " --time-limit 0.001" + method),
                                &out),
              0)
        << out;
    EXPECT_NE(out.find("the time limit (0.001 s) ended the node movement"), std::string::npos)
        << out;
    const auto report = read_json(dir + "/report.json");
    EXPECT_TRUE(report["node_optimization"]["time_limited"].get<bool>());
    EXPECT_LE(report["node_optimization"]["steps"].get<int>(), 1);
    if (method.empty()) {  // the discrete baseline removes no fold-overs
      EXPECT_EQ(report["metrics"]["foldovers"].get<int>(), 0);
      EXPECT_TRUE(report["structurally_equivalent"].get<bool>());
    }
    for (const char* file : {"param.obj", "layout.json", "field.txt"})
      EXPECT_TRUE(fs::exists(dir + "/" + file)) << file;
  }
  ASSERT_EQ(
      test::run_command(
          cli("optimize --quiet --mesh " + kMesh + " --layout " + kLayout + " --out " + dir), &out),
      0)
      << out;
  const auto whole = read_json(dir + "/report.json");
  EXPECT_FALSE(whole["node_optimization"]["time_limited"].get<bool>());
  EXPECT_GT(whole["node_optimization"]["steps"].get<int>(), 1);
  EXPECT_EQ(test::run_command(cli("optimize --no-node-opt --time-limit 5 --mesh " + kMesh +
                                  " --layout " + kLayout + " --out " + dir),
                              &out),
            2)
      << out;
  EXPECT_NE(out.find("--time-limit applies to the node optimization"), std::string::npos) << out;
  // A limit that is not a positive number is a usage error (exit code 1, like every malformed
  // option) that says what the flag needs.
  for (const std::string bad : {"0", "-2", "soon"}) {
    EXPECT_EQ(test::run_command(cli("optimize --time-limit " + bad + " --mesh " + kMesh +
                                    " --layout " + kLayout + " --out " + dir),
                                &out),
              1)
        << out;
    EXPECT_NE(out.find("--time-limit: must be a positive number of seconds, got " + bad),
              std::string::npos)
        << out;
  }
}

// --no-node-opt --orientation: the fixed nodes' parameterization with strict orientation
// constraints. The bundled sketch folds with fixed nodes (see above); with --orientation the
// same nodes give a fold-free, structurally equivalent embedding, and the report says what the
// fold-over removal did. The flag is refused where it does not apply.
TEST(Cli, OrientationRemovesFoldoversWithoutNodeOptimization) {
  const std::string plain = test::temp_dir("cli_plain"), oriented = test::temp_dir("cli_oriented");
  const std::string files = " --mesh " + kMesh + " --layout " + kLayout;
  std::string out;
  ASSERT_EQ(
      test::run_command(cli("optimize --no-node-opt --quiet" + files + " --out " + plain), &out), 0)
      << out;
  ASSERT_EQ(test::run_command(
                cli("optimize --no-node-opt --orientation" + files + " --out " + oriented), &out),
            0)
      << out;
  EXPECT_NE(out.find("orientation constraints:"), std::string::npos) << out;
  const auto before = read_json(plain + "/report.json"),
             after = read_json(oriented + "/report.json");
  const int folds = before["metrics"]["foldovers"].get<int>();
  ASSERT_GT(folds, 0);
  EXPECT_FALSE(before.contains("fold_removal"));
  EXPECT_EQ(after["metrics"]["foldovers"].get<int>(), 0);
  EXPECT_TRUE(after["structurally_equivalent"].get<bool>());
  EXPECT_EQ(after["bad_cones"].get<int>(), 0);
  const auto& removal = after["fold_removal"];
  EXPECT_EQ(removal["method"], "orientation");
  EXPECT_EQ(removal["foldovers_before"].get<int>(), folds);
  EXPECT_EQ(removal["foldovers_after"].get<int>(), 0);
  EXPECT_TRUE(removal["orientation"]["ran"].get<bool>());
  EXPECT_GT(removal["orientation"]["constrained_faces"].get<int>(), 0);
  // The nodes did not move: the same node vertices in both output layouts.
  const Layout l0 = load_layout(plain + "/layout.json", load_mesh(kMesh));
  const Layout l1 = load_layout(oriented + "/layout.json", load_mesh(kMesh));
  ASSERT_EQ(l0.nodes.size(), l1.nodes.size());
  for (size_t i = 0; i < l0.nodes.size(); ++i) EXPECT_EQ(l0.nodes[i].vertex, l1.nodes[i].vertex);
  // A fold-free input: nothing to remove, the same parameterization as without the flag.
  const std::string exact = test::temp_dir("cli_exact_oriented");
  ASSERT_EQ(test::run_command(cli("optimize --no-node-opt --orientation --quiet --mesh " + kMesh +
                                  " --layout " + kExact + " --out " + exact),
                              &out),
            0)
      << out;
  const auto exact_report = read_json(exact + "/report.json");
  EXPECT_EQ(exact_report["fold_removal"]["method"], "none");
  EXPECT_EQ(exact_report["fold_removal"]["foldovers_before"].get<int>(), 0);
  EXPECT_FALSE(exact_report["fold_removal"]["orientation"]["ran"].get<bool>());
  // Refused combinations: exit code 2 with the reason.
  EXPECT_EQ(test::run_command(cli("optimize --orientation" + files + " --out " + plain), &out), 2);
  EXPECT_NE(out.find("--orientation applies to --no-node-opt"), std::string::npos) << out;
  EXPECT_EQ(test::run_command(cli("optimize --no-node-opt --orientation --no-orientation" + files +
                                  " --out " + plain),
                              &out),
            2);
  EXPECT_NE(out.find("contradict"), std::string::npos) << out;
}

// Where the orientation constraints are infeasible (mask_confmap.obj with a star of dangling
// arcs to its free eye holes and the field wrapping around them, --wrap-free-holes, as in
// orientation_test), the report lists the faces they violate most and a warning names the
// layout node next to them. Only with the field frame's sectors (--orientation-sectors field):
// the default goes on to the solution frame's, which unfold this case.
TEST(Cli, InfeasibleOrientationNamesTheNodesWhereTheLayoutFolds) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real meshes skipped";
  const std::string mesh_file = test::mesh_file(dir + "/mask_confmap.obj");
  const TriMesh mesh = load_mesh(mesh_file);
  const test::MaskStar star = test::mask_star(mesh);
  ASSERT_EQ(star.boundary_loops, 3u);
  const Layout layout = test::dangling_star_layout(mesh, star.center, star.targets);
  const std::string out_dir = test::temp_dir("cli_infeasible_orientation");
  const std::string layout_file = out_dir + "/star.layout.json";
  save_layout(layout, layout_file, &mesh);
  std::string out;
  // The fixed star with orientation constraints on the wrapping field; \p sectors: extra option.
  auto run_star = [&](const std::string& sectors, const std::string& dir) {
    return test::run_command(
        cli("optimize --no-node-opt --orientation --no-align "
            "--wrap-free-holes " +
            sectors + " --mesh " + mesh_file + " --layout " + layout_file + " --out " + dir),
        &out);
  };
  ASSERT_EQ(run_star("--orientation-sectors field --no-untangle", out_dir), 0) << out;
  const auto report = read_json(out_dir + "/report.json");
  const auto& orientation = report["fold_removal"]["orientation"];
  ASSERT_TRUE(orientation["ran"].get<bool>());
  ASSERT_FALSE(orientation["success"].get<bool>()) << "the case should stay infeasible";
  const auto faces = orientation["infeasible_faces"].get<std::vector<int>>();
  ASSERT_FALSE(faces.empty());
  for (int f : faces) {
    EXPECT_GE(f, 0);
    EXPECT_LT(f, static_cast<int>(mesh.n_faces()));
  }
  const int left = report["metrics"]["foldovers"].get<int>();
  ASSERT_GT(left, 0);
  // The star's only node is its center.
  const LayoutNode& center = layout.nodes.at(0);
  ASSERT_EQ(center.vertex, star.center);
  const std::string expected = "warning: " + std::to_string(left) +
                               " fold-over(s) remain; the layout cannot be unfolded near node " +
                               std::to_string(center.id) + " (vertex " +
                               std::to_string(center.vertex) + ")";
  EXPECT_NE(out.find(expected), std::string::npos) << out;
  EXPECT_NE(out.find("most violated at face"), std::string::npos) << out;
  EXPECT_EQ(orientation["sector_frame"].get<std::string>(), "field");
  EXPECT_FALSE(orientation["untangle"]["ran"].get<bool>());

  // The same with the untangling (the default): it starts where the infeasible QP left the
  // map, keeps the exact constraints and leaves fewer fold-overs; the report says so.
  const std::string untangled_dir = test::temp_dir("cli_orientation_untangled");
  ASSERT_EQ(run_star("--orientation-sectors field", untangled_dir), 0) << out;
  const auto untangled = read_json(untangled_dir + "/report.json");
  const auto& ut = untangled["fold_removal"]["orientation"];
  std::printf("[stat] mask star, field sectors, untangled: %d -> %d fold-overs, %s\n",
              untangled["fold_removal"]["foldovers_before"].get<int>(),
              untangled["metrics"]["foldovers"].get<int>(),
              ut["message"].get<std::string>().c_str());
  EXPECT_TRUE(ut["untangle"]["ran"].get<bool>());
  EXPECT_GT(ut["untangle"]["newton_steps"].get<int>(), 0);
  EXPECT_LT(untangled["metrics"]["foldovers"].get<int>(), left);
  EXPECT_EQ(ut["untangle"]["foldovers_after"].get<int>(),
            untangled["metrics"]["foldovers"].get<int>());
  EXPECT_TRUE(ut["success"].get<bool>());
  EXPECT_NE(ut["message"].get<std::string>().find("untangling: "), std::string::npos);

  // The default (auto): the field frame's sectors fail as above, the solution frame's unfold
  // every face, and that result is kept and named.
  const std::string auto_dir = test::temp_dir("cli_orientation_sectors_auto");
  ASSERT_EQ(run_star("", auto_dir), 0) << out;
  const auto auto_report = read_json(auto_dir + "/report.json");
  const auto& auto_orientation = auto_report["fold_removal"]["orientation"];
  std::printf("[stat] mask star, wrapping holes, auto sectors: %d -> %d fold-overs, %s\n",
              auto_report["fold_removal"]["foldovers_before"].get<int>(),
              auto_report["metrics"]["foldovers"].get<int>(),
              auto_orientation["message"].get<std::string>().c_str());
  EXPECT_TRUE(auto_orientation["success"].get<bool>());
  EXPECT_EQ(auto_orientation["sector_frame"].get<std::string>(), "solution");
  EXPECT_LT(auto_report["metrics"]["foldovers"].get<int>(), left);
  EXPECT_NE(auto_orientation["message"].get<std::string>().find("field-frame sectors: "),
            std::string::npos);
  EXPECT_EQ(run_star("--orientation-sectors sideways", auto_dir), 1)
      << "a usage error, like every malformed option: " << out;
  EXPECT_NE(out.find("--orientation-sectors"), std::string::npos) << out;
}

// Sliding along the boundary from the command line: a boundary node of a flat grid layout two
// edges off its place slides back by default (report: sliding_nodes), stays with --no-sliding;
// --keep-sharp-edges is accepted (the flat grid has no sharp edges: the same result).
TEST(Cli, OptimizeSlidesBoundaryNodes) {
  const auto grid = test::disk_grid(8, 8, 2, 2);
  Layout layout = grid.layout;
  int node = -1;
  for (int n = 0; n < static_cast<int>(layout.nodes.size()); ++n)
    if (layout.nodes[n].vertex == 4) node = n;  // grid point (4, 0)
  ASSERT_GE(node, 0);
  // The node two edges along the boundary, its arcs along the boundary following it.
  LayoutArc* right = nullptr;
  LayoutArc* left = nullptr;
  for (auto& arc : layout.arcs) {
    if (arc.from == layout.nodes[node].id && arc.path[1] == 5) right = &arc;
    if (arc.to == layout.nodes[node].id && arc.path[arc.path.size() - 2] == 3) left = &arc;
  }
  ASSERT_TRUE(right && left);
  right->path.erase(right->path.begin(), right->path.begin() + 2);  // from (6, 0) on
  left->path.push_back(5);
  left->path.push_back(6);
  layout.nodes[node].vertex = 6;
  for (auto& arc : layout.arcs)  // the arc into the grid starts at (6, 0), then goes up
    if (arc.from == layout.nodes[node].id && arc.path[1] == 13)
      arc.path = {6, 15, 14, 13, 22, 31, 40};
  ASSERT_TRUE(validate_layout(grid.mesh, layout).valid());
  const std::string dir = test::temp_dir("cli_slide");
  test::write_obj(grid.mesh, dir + "/mesh.obj");
  save_layout(layout, dir + "/layout.json", &grid.mesh);
  auto run = [&](const std::string& flags, const std::string& out) {
    std::string output;
    EXPECT_EQ(test::run_command(cli("optimize --quiet --mesh " + dir + "/mesh.obj --layout " + dir +
                                    "/layout.json --out " + dir + "/" + out + " " + flags),
                                &output),
              0)
        << output;
    return read_json(dir + "/" + out + "/report.json");
  };
  const auto slide = run("", "slide"), keep = run("--keep-sharp-edges", "keep"),
             stay = run("--no-sliding", "stay");
  EXPECT_GT(slide["node_optimization"]["sliding_nodes"].get<int>(), 0);
  EXPECT_EQ(stay["node_optimization"]["sliding_nodes"].get<int>(), 0);
  EXPECT_LT(slide["E_final"].get<double>(), 1e-6 * slide["E_init"].get<double>());
  EXPECT_GT(stay["E_final"].get<double>(), 0.05 * stay["E_init"].get<double>());
  EXPECT_EQ(keep["E_final"].get<double>(), slide["E_final"].get<double>());
  EXPECT_TRUE(slide["structurally_equivalent"].get<bool>());
}

}  // namespace
}  // namespace qs
