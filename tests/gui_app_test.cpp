// The editor end to end under Xvfb (software OpenGL): each test runs `quadsketch` with a
// --script of editor commands (app/gui/automation.h), which drives the same code as the mouse,
// keys and panels, and checks the state the app writes as JSON (app/gui/state_dump.h). Every
// run gets its own home, config and autosave folders. Skipped without xvfb-run or without the
// app (QS_GUI_APP, set by tests/cmake/gui_smoke.cmake).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kAssets = QS_ASSETS_DIR;
const fs::path kExampleMesh = kAssets / "example" / "ellipsoid.obj";
const fs::path kExampleLayout = kAssets / "example" / "ellipsoid.layout.json";

std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) return nullptr;
  return json::parse(in, nullptr, false);
}

// The arc with id \p id in a state's layout (null when missing).
json arc_by_id(const json& layout, int id) {
  for (const auto& a : layout.at("arcs"))
    if (a.at("id") == id) return a;
  return nullptr;
}

// The vertex positions of an OBJ file (its "v" lines).
std::vector<std::array<double, 3>> obj_vertices(const fs::path& path) {
  std::vector<std::array<double, 3>> out;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    std::array<double, 3> p{};
    if (ls >> tag && tag == "v" && ls >> p[0] >> p[1] >> p[2]) out.push_back(p);
  }
  return out;
}

// The vertex of \p vertices nearest to \p p.
int nearest_vertex(const std::vector<std::array<double, 3>>& vertices, std::array<double, 3> p) {
  int best = -1;
  double best_d = 1e300;
  for (int v = 0; v < int(vertices.size()); ++v) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += (vertices[v][k] - p[k]) * (vertices[v][k] - p[k]);
    if (d < best_d) {
      best_d = d;
      best = v;
    }
  }
  return best;
}

class GuiApp : public ::testing::Test {
 protected:
  void SetUp() override {
#ifndef QS_GUI_APP
    GTEST_SKIP() << "the editor is not built (QS_BUILD_APP off)";
#else
    if (std::system("command -v xvfb-run > /dev/null 2>&1") != 0)
      GTEST_SKIP() << "xvfb-run is not installed (apt-get install xvfb xauth)";
    dir_ = fs::temp_directory_path() /
           ("qs_gui_app_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "home" / "Documents");
#endif
  }
  void TearDown() override {
    std::error_code ec;
    if (!dir_.empty() && !HasFailure()) fs::remove_all(dir_, ec);
  }

  // Runs the app with \p args and the script \p script (one command per line); returns its exit
  // code. The app's output goes to dir_/run<N>.log.
  int run_app(const std::vector<std::string>& args, const std::string& script) {
#ifdef QS_GUI_APP
    const int n = ++runs_;
    const fs::path script_file = dir_ / ("script" + std::to_string(n) + ".txt");
    std::ofstream(script_file) << script;
    std::string command = "env LIBGL_ALWAYS_SOFTWARE=1 HOME=" + quote((dir_ / "home").string()) +
                          " XDG_CONFIG_HOME=" + quote((dir_ / "config").string()) +
                          " QS_AUTOSAVE_DIR=" + quote((dir_ / "autosave").string()) +
                          " xvfb-run -a -s '-screen 0 1280x800x24' " + quote(QS_GUI_APP) +
                          " --width 1280 --height 800 --script " + quote(script_file.string());
    for (const auto& a : args) command += " " + quote(a);
    const fs::path log = dir_ / ("run" + std::to_string(n) + ".log");
    command += " > " + quote(log.string()) + " 2>&1";
    const int status = std::system(command.c_str());
    if (status == -1 || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
#else
    (void)args;
    (void)script;
    return -1;
#endif
  }
  fs::path path(const std::string& name) const {
    return dir_ / name;
  }
  std::string p(const std::string& name) const {
    return path(name).string();
  }

  fs::path dir_;
  int runs_ = 0;
};

// Pinning an arc while a run is paused sends it to the run: Run goes on with the same job
// (no restart, nothing lost) and the arc is pinned in its result.
TEST_F(GuiApp, ArcPinnedDuringARunGoesToTheRun) {
  const std::string script = "run\nwait_step 2\npause\nwait_status paused\nstate " +
                             p("before.json") + "\npin_arc 0\nframes 1\nstate " + p("pinned.json") +
                             "\nrun\nwait_finished\nframes 2\nstate " + p("after.json") +
                             "\nquit\n";
  ASSERT_EQ(run_app({}, script), 0);
  const json before = read_json(path("before.json"));
  const json pinned = read_json(path("pinned.json"));
  const json after = read_json(path("after.json"));
  ASSERT_FALSE(before.is_null() || pinned.is_null() || after.is_null());
  ASSERT_FALSE(before.at("result").is_null());
  EXPECT_EQ(before.at("result").at("status"), "paused");
  EXPECT_NE(pinned.at("status").get<std::string>().find("Pinned arc 0 in the run"),
            std::string::npos)
      << pinned.at("status");
  EXPECT_FALSE(pinned.at("document").at("dirty").get<bool>());  // the sketch is untouched
  EXPECT_EQ(pinned.at("result").at("kind"), "live");
  const json& result = after.at("result");
  ASSERT_FALSE(result.is_null());
  EXPECT_EQ(result.at("status"), "finished") << result.at("message");
  EXPECT_EQ(result.at("generation"), before.at("result").at("generation"));  // the same run
  EXPECT_GT(result.at("iteration").get<int>(), before.at("result").at("iteration").get<int>());
  const json arc = arc_by_id(result.at("layout"), 0);
  ASSERT_FALSE(arc.is_null());
  EXPECT_TRUE(arc.at("pinned").get<bool>());
  EXPECT_EQ(arc.at("path"), arc_by_id(before.at("result").at("layout"), 0).at("path"));
}

// Stop ends the run and keeps the state reached on screen; Keep result adopts it.
TEST_F(GuiApp, StopKeepsTheStateReachedAndKeepAdoptsIt) {
  // After Stop the worker ends the run at its next step: wait for that, not for a frame count.
  const std::string script = "run\nwait_step 2\nstop\nwait_status cancelled 120\nframes 2\nstate " +
                             p("stopped.json") + "\nkeep\nframes 2\nstate " + p("kept.json") +
                             "\nquit\n";
  ASSERT_EQ(run_app({}, script), 0);
  const json stopped = read_json(path("stopped.json"));
  const json kept = read_json(path("kept.json"));
  ASSERT_FALSE(stopped.is_null() || kept.is_null());
  ASSERT_FALSE(stopped.at("result").is_null());
  EXPECT_EQ(stopped.at("result").at("kind"), "stopped");
  EXPECT_GE(stopped.at("result").at("iteration").get<int>(), 2);
  EXPECT_FALSE(stopped.at("result").at("energy").is_null());
  EXPECT_EQ(stopped.at("job").at("status"), "cancelled");  // the run did end
  EXPECT_NE(stopped.at("status_bar").at("job").get<std::string>().find("stopped"),
            std::string::npos);
  ASSERT_FALSE(kept.at("result").is_null());
  EXPECT_EQ(kept.at("result").at("kind"), "kept");
  EXPECT_TRUE(kept.at("document").at("dirty").get<bool>());
  const json& reached = stopped.at("result").at("layout").at("nodes");
  const json& adopted = kept.at("document").at("nodes");
  ASSERT_EQ(reached.size(), adopted.size());
  for (std::size_t k = 0; k < reached.size(); ++k)
    EXPECT_EQ(reached[k].at("vertex"), adopted[k].at("vertex"));
}

// Keep result keeps the energy, the quad mesh and the quad export of a finished run.
TEST_F(GuiApp, KeepResultKeepsTheEnergyAndTheQuadMesh) {
  // The worker takes the kept layout on its own time: wait for it, not for a frame count.
  const std::string script = "run\nwait_finished\nframes 2\nstate " + p("finished.json") +
                             "\nkeep\nwait_status idle 120\nframes 2\nstate " + p("kept.json") +
                             "\nquit\n";
  ASSERT_EQ(run_app({}, script), 0);
  const json finished = read_json(path("finished.json"));
  const json kept = read_json(path("kept.json"));
  ASSERT_FALSE(finished.is_null() || kept.is_null());
  const json& f = finished.at("result");
  ASSERT_FALSE(f.is_null());
  ASSERT_EQ(f.at("status"), "finished") << f.at("message");
  ASSERT_GT(f.at("quads").get<int>(), 0);
  const json& k = kept.at("result");
  ASSERT_FALSE(k.is_null());
  EXPECT_EQ(k.at("kind"), "kept");
  EXPECT_EQ(kept.at("job").at("status"), "idle");  // the worker took the kept layout
  EXPECT_EQ(k.at("energy"), f.at("energy"));
  EXPECT_EQ(k.at("quads"), f.at("quads"));
  EXPECT_TRUE(k.at("has_quad_export").get<bool>());
}

// After a session is killed, a plain start (the bundled example) offers its autosave with the
// mesh's name and the time; Restore opens that mesh with the autosaved layout.
TEST_F(GuiApp, PlainStartOffersTheAutosaveOfAKilledSession) {
  const fs::path other = path("other.obj");
  fs::copy_file(kExampleMesh, other);
  EXPECT_EQ(run_app({"--mesh", other.string()}, "tool place_node\nclick_vertex 100\nabort\n"), 137);
  ASSERT_TRUE(fs::exists(path("autosave") / "autosave.layout.json"));

  ASSERT_EQ(run_app({}, "frames 2\nstate " + p("offer.json") + "\nquit\n"), 0);
  const json offer = read_json(path("offer.json"));
  ASSERT_FALSE(offer.is_null());
  EXPECT_EQ(fs::path(offer.at("document").at("mesh").get<std::string>()).filename(),
            "ellipsoid.obj");
  ASSERT_FALSE(offer.at("autosave_offer").is_null());
  EXPECT_EQ(fs::path(offer.at("autosave_offer").at("mesh").get<std::string>()).filename(),
            "other.obj");
  EXPECT_FALSE(offer.at("autosave_offer").at("saved_at").get<std::string>().empty());

  ASSERT_EQ(run_app({}, "restore_autosave\nframes 2\nstate " + p("restored.json") + "\nquit\n"), 0);
  const json restored = read_json(path("restored.json"));
  ASSERT_FALSE(restored.is_null());
  EXPECT_EQ(fs::path(restored.at("document").at("mesh").get<std::string>()).filename(),
            "other.obj");
  EXPECT_EQ(restored.at("document").at("nodes").size(), 1u);
  EXPECT_TRUE(restored.at("document").at("dirty").get<bool>());
  EXPECT_TRUE(restored.at("autosave_offer").is_null());
}

// Numpad 1 / Ctrl+3 / 7 look along -z / +x / -y (the world's y is up), numpad 5 switches to
// orthographic; a turntable drag never rolls.
TEST_F(GuiApp, NumpadViewsSetTheCameraDirection) {
  const std::string script =
      "key KP_1\nwait_camera\nstate " + p("front.json") + "\nkey KP_3 ctrl\nwait_camera\nstate " +
      p("left.json") + "\nkey KP_7\nwait_camera\nstate " + p("top.json") +
      "\nkey KP_5\nframes 1\nstate " + p("ortho.json") +
      "\ndrag 800 300 1000 450\nframes 1\nstate " + p("dragged.json") + "\nquit\n";
  ASSERT_EQ(run_app({}, script), 0);
  const auto direction = [&](const char* file) {
    const json s = read_json(path(file));
    return s.is_null() ? json(nullptr) : s.at("camera");
  };
  const auto expect_near = [](const json& v, std::vector<double> want, const char* what) {
    ASSERT_EQ(v.size(), 3u) << what;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(v[i].get<double>(), want[i], 1e-3) << what << " " << i;
  };
  expect_near(direction("front.json").at("view_direction"), {0, 0, -1}, "front");
  expect_near(direction("front.json").at("up"), {0, 1, 0}, "front up");
  expect_near(direction("left.json").at("view_direction"), {1, 0, 0}, "left");
  expect_near(direction("top.json").at("view_direction"), {0, -1, 0}, "top");
  expect_near(direction("top.json").at("up"), {0, 0, -1}, "top up");
  EXPECT_FALSE(direction("top.json").at("orthographic").get<bool>());
  EXPECT_TRUE(direction("ortho.json").at("orthographic").get<bool>());
  const json dragged = direction("dragged.json");
  EXPECT_EQ(dragged.at("mode"), "turntable");
  const json& d = dragged.at("view_direction");
  const json& u = dragged.at("up");
  // No roll: the view's right axis (direction x up) stays horizontal.
  const double right_y =
      d[2].get<double>() * u[0].get<double>() - d[0].get<double>() * u[2].get<double>();
  EXPECT_NEAR(right_y, 0.0, 1e-4);
  EXPECT_GT(std::abs(d[1].get<double>()), 0.05);  // the drag tilted it off the top view
}

// A mesh that cannot be opened: the window opens with the message (and Run says why).
TEST_F(GuiApp, AMissingMeshOpensTheWindowWithTheMessage) {
  const std::string missing = p("missing.obj");
  ASSERT_EQ(run_app({"--mesh", missing}, "frames 2\nstate " + p("state.json") + "\nquit\n"), 0);
  const json s = read_json(path("state.json"));
  ASSERT_FALSE(s.is_null());
  EXPECT_GE(s.at("frames").get<int>(), 2);  // drawn in a window
  EXPECT_FALSE(s.at("document").at("mesh_loaded").get<bool>());
  ASSERT_EQ(s.at("errors").size(), 1u);
  EXPECT_NE(s.at("errors")[0].get<std::string>().find(missing), std::string::npos);
  EXPECT_NE(s.at("status_bar").at("run_blocker").get<std::string>().find("no mesh"),
            std::string::npos);
}

// Run on an invalid layout says why on the status line instead of doing nothing.
TEST_F(GuiApp, RunOnAnInvalidLayoutSaysWhy) {
  ASSERT_EQ(run_app({"--mesh", kExampleMesh.string(), "--layout",
                     (kAssets / "bad" / "five_sided_patch.layout.json").string()},
                    "run\nframes 2\nstate " + p("state.json") + "\nquit\n"),
            0);
  const json s = read_json(path("state.json"));
  ASSERT_FALSE(s.is_null());
  const std::string message = s.at("status_bar").at("message");
  EXPECT_NE(message.find("Cannot run"), std::string::npos) << message;
  EXPECT_NE(message.find("5 corners"), std::string::npos) << message;
  EXPECT_FALSE(s.at("running").get<bool>());
}

// Ctrl+S on the bundled example asks for a file name in the browser (at ~/Documents) instead
// of writing the bundled file; the browser saves there; Ctrl+O opens a mesh through it.
TEST_F(GuiApp, FileBrowserSavesAwayFromTheBundledFilesAndOpens) {
  const auto bundled_time = fs::last_write_time(kExampleLayout);
  const fs::path meshes = path("meshes");
  fs::create_directories(meshes);
  fs::copy_file(kExampleMesh, meshes / "other.obj");
  const std::string script = "key S ctrl\nframes 1\nstate " + p("save_dialog.json") +
                             "\nbrowser_accept\nframes 1\nstate " + p("saved.json") +
                             "\nkey O ctrl\nbrowser_folder " + meshes.string() +
                             "\nbrowser_name other.obj\nframes 1\nstate " + p("open_dialog.json") +
                             "\nbrowser_accept\nframes 2\nstate " + p("opened.json") + "\nquit\n";
  ASSERT_EQ(run_app({}, script), 0);
  const json dialog = read_json(path("save_dialog.json"));
  ASSERT_FALSE(dialog.is_null());
  EXPECT_TRUE(dialog.at("browser").at("open").get<bool>());
  EXPECT_EQ(dialog.at("browser").at("mode"), "save");
  EXPECT_EQ(fs::path(dialog.at("browser").at("folder").get<std::string>()),
            fs::weakly_canonical(path("home") / "Documents"));
  EXPECT_EQ(dialog.at("browser").at("file_name"), "ellipsoid.layout.json");
  EXPECT_FALSE(dialog.at("save_path_bundled").get<bool>());
  const json saved = read_json(path("saved.json"));
  ASSERT_FALSE(saved.is_null());
  EXPECT_FALSE(saved.at("browser").at("open").get<bool>());
  EXPECT_TRUE(fs::exists(path("home") / "Documents" / "ellipsoid.layout.json"));
  EXPECT_EQ(fs::last_write_time(kExampleLayout), bundled_time);
  const json open_dialog = read_json(path("open_dialog.json"));
  ASSERT_FALSE(open_dialog.is_null());
  EXPECT_EQ(open_dialog.at("browser").at("mode"), "open");
  EXPECT_EQ(open_dialog.at("browser").at("entries"), 1);  // other.obj
  const json opened = read_json(path("opened.json"));
  ASSERT_FALSE(opened.is_null());
  EXPECT_FALSE(opened.at("browser").at("open").get<bool>());
  EXPECT_EQ(fs::path(opened.at("document").at("mesh").get<std::string>()).filename(), "other.obj");
}

// Mirrored sketching through the app's tools: with the mirror about x = 0, a node beside the
// plane and two near it, joined by arcs, give a valid layout that is its own mirror image: every
// node and every arc's path reflected lands on a node and an arc of the layout (this
// tessellation is exactly symmetric, so within 1e-6 of the diagonal); the two plane nodes are
// on the plane.
TEST_F(GuiApp, MirroredSketchIsASymmetricLayout) {
  const auto x = obj_vertices(kExampleMesh);
  ASSERT_FALSE(x.empty());
  const int top = nearest_vertex(x, {0.02, 0.95, 0.2});  // near the plane: goes onto it
  const int side = nearest_vertex(x, {0.9, 0.1, 0.5});
  const int bottom = nearest_vertex(x, {0.0, -0.3, 0.7});
  const std::string nodes = "click_vertex " + std::to_string(top) + "\nclick_vertex " +
                            std::to_string(side) + "\nclick_vertex " + std::to_string(bottom);
  const std::string script =
      "symmetry x\nwait_guides 60\nkey KP_1\nwait_camera\ntool place_node\n" + nodes +
      "\ntool draw_arc\n" + nodes + "\nkey ESCAPE\nframes 2\nstate " + p("state.json") + "\nquit\n";
  ASSERT_EQ(run_app({"--mesh", kExampleMesh.string()}, script), 0);
  const json s = read_json(path("state.json"));
  ASSERT_FALSE(s.is_null());
  EXPECT_TRUE(s.at("symmetry").at("ready").get<bool>());
  EXPECT_EQ(s.at("symmetry").at("normal"), json::array({1.0, 0.0, 0.0}));
  const json& doc = s.at("document");
  ASSERT_EQ(doc.at("nodes").size(), 4u) << s.at("status");  // side, its mirror, two on the plane
  ASSERT_EQ(doc.at("arcs").size(), 4u) << s.at("status");
  EXPECT_EQ(doc.at("validation_errors"), 0);
  const double tolerance = 1e-6 * std::sqrt(2.6 * 2.6 + 2.0 * 2.0 + 1.5 * 1.5);
  const auto mirrored = [&](int a, int b) {  // vertex b is the reflection of vertex a
    return std::abs(x[a][0] + x[b][0]) < tolerance && std::abs(x[a][1] - x[b][1]) < tolerance &&
           std::abs(x[a][2] - x[b][2]) < tolerance;
  };
  int on_plane = 0;
  for (const auto& n : doc.at("nodes")) {
    const int v = n.at("vertex");
    on_plane += mirrored(v, v);
    bool found = false;
    for (const auto& m : doc.at("nodes")) found |= mirrored(v, m.at("vertex").get<int>());
    EXPECT_TRUE(found) << "node " << n.at("id") << " has no mirror";
  }
  EXPECT_EQ(on_plane, 2);
  for (const auto& a : doc.at("arcs")) {
    const std::vector<int> pa = a.at("path");
    bool found = false;
    for (const auto& b : doc.at("arcs")) {
      std::vector<int> pb = b.at("path");
      for (int turn = 0; turn < 2 && !found; ++turn) {
        bool same = pa.size() == pb.size();
        for (std::size_t k = 0; same && k < pa.size(); ++k) same = mirrored(pa[k], pb[k]);
        found = same;
        std::reverse(pb.begin(), pb.end());
      }
    }
    EXPECT_TRUE(found) << "arc " << a.at("id") << " has no mirror";
  }
}

// The edge-loop tools through the app: a click on an arc inserts a loop through the chord
// crossing it (4 nodes and 8 arcs more, the layout still valid, so every patch of this closed
// surface is 4-sided: 2·#arcs = 4·#patches), a click on one of its arcs removes it again.
TEST_F(GuiApp, EdgeLoopIsInsertedAndRemovedWithTheLoopTools) {
  const fs::path exact = kAssets / "example" / "ellipsoid_exact.layout.json";
  const json layout = read_json(exact);
  const auto x = obj_vertices(kExampleMesh);
  ASSERT_FALSE(layout.is_null() || x.empty());
  // The front view looks along -z: an arc vertex with the largest z is in sight.
  const auto frontmost = [&](const json& arcs, const json& skip) {
    int best = -1;
    for (const auto& a : arcs) {
      if (!skip.is_null() && !arc_by_id(skip, a.at("id")).is_null()) continue;
      const std::vector<int> path = a.at("path");
      const int v = path[path.size() / 2];
      if (path.size() >= 3 && (best < 0 || x[v][2] > x[best][2])) best = v;
    }
    return best;
  };
  const int insert_at = frontmost(layout.at("arcs"), nullptr);
  ASSERT_GE(insert_at, 0);
  ASSERT_EQ(run_app({"--mesh", kExampleMesh.string(), "--layout", exact.string()},
                    "key KP_1\nwait_camera\ntool insert_loop\nclick_vertex " +
                        std::to_string(insert_at) + "\nframes 2\nstate " + p("inserted.json") +
                        "\nsave " + p("with_loop.layout.json") + "\nquit\n"),
            0);
  const json inserted = read_json(path("inserted.json"));
  ASSERT_FALSE(inserted.is_null());
  const json& with = inserted.at("document");
  const std::size_t nodes = layout.at("nodes").size(), arcs = layout.at("arcs").size();
  ASSERT_EQ(with.at("nodes").size(), nodes + 4) << inserted.at("status");
  ASSERT_EQ(with.at("arcs").size(), arcs + 8);
  EXPECT_EQ(with.at("validation_errors"), 0);
  const int patches = int(with.at("arcs").size()) - int(with.at("nodes").size()) + 2;  // Euler
  EXPECT_EQ(4 * patches, 2 * int(with.at("arcs").size()));

  // Remove it through one of its new arcs, from the layout saved with the loop.
  const int remove_at = frontmost(with.at("arcs"), layout);
  ASSERT_GE(remove_at, 0);
  ASSERT_EQ(
      run_app({"--mesh", kExampleMesh.string(), "--layout", p("with_loop.layout.json")},
              "key KP_1\nwait_camera\ntool remove_loop\nclick_vertex " + std::to_string(remove_at) +
                  "\nframes 2\nstate " + p("removed.json") + "\nquit\n"),
      0);
  const json removed = read_json(path("removed.json"));
  ASSERT_FALSE(removed.is_null());
  EXPECT_EQ(removed.at("document").at("nodes").size(), nodes) << removed.at("status");
  EXPECT_EQ(removed.at("document").at("arcs").size(), arcs);
  EXPECT_EQ(removed.at("document").at("validation_errors"), 0);
}

// The guides through the app: a fitted mirror plane of the exactly symmetric example, and the
// field hints' 8 singularities of index +1/4 (where a cube layout has its corners); a screenshot
// with both is written. Without a mesh, waiting for them fails the script at once.
TEST_F(GuiApp, GuidesAreShownAndWaitingWithoutAMeshFails) {
  ASSERT_EQ(run_app({"--mesh", kExampleMesh.string()},
                    "symmetry auto\nfield_hints on\nhint_scale 0.1\nwait_guides 120\nframes "
                    "2\nscreenshot " +
                        p("guides.png") + "\nstate " + p("state.json") + "\nquit\n"),
            0);
  const json s = read_json(path("state.json"));
  ASSERT_FALSE(s.is_null());
  EXPECT_TRUE(s.at("symmetry").at("ready").get<bool>());
  EXPECT_LT(s.at("symmetry").at("residual").get<double>(), 1e-9);
  // One of the ellipsoid's three mirror planes (all fit exactly: any may win).
  double along_axis = 0.0;
  for (const auto& c : s.at("symmetry").at("normal"))
    along_axis = std::max(along_axis, std::abs(c.get<double>()));
  EXPECT_NEAR(along_axis, 1.0, 1e-9);
  EXPECT_NEAR(s.at("symmetry").at("offset").get<double>(), 0.0, 1e-9);
  const json& singularities = s.at("field_hints").at("singularities");
  ASSERT_TRUE(singularities.is_array());
  EXPECT_EQ(singularities.size(), 8u);
  for (const auto& v : singularities) EXPECT_EQ(v.at("index"), 1);
  EXPECT_EQ(s.at("field_hints").at("scale"), 0.1);
  EXPECT_EQ(s.at("field_hints").at("all_singularities"), 8);
  EXPECT_GT(fs::file_size(path("guides.png")), 1000u);

  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(run_app({"--mesh", p("missing.obj")}, "symmetry x\nwait_guides 100\nquit\n"), 1);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60));
  std::ifstream log(path("run2.log"));
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("wait_guides: no mesh is open"), std::string::npos) << text;
}

// The live-drag benchmark: a scripted drag of one node of the example layout, its numbers
// printed, the result after the release the solve of the released layout; the state dump shows
// the moved node.
TEST_F(GuiApp, BenchDragDragsANodeAndPrintsItsNumbers) {
  ASSERT_EQ(run_app({"--bench-drag", "20", "--state-json", p("state.json")}, ""), 0);
  std::ifstream log(path("run1.log"));
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  const auto line = text.find("bench-drag: node ");
  ASSERT_NE(line, std::string::npos) << text;
  const std::string bench = text.substr(line, text.find('\n', line) - line);
  EXPECT_NE(bench.find("over 20 mouse positions"), std::string::npos) << bench;
  EXPECT_NE(bench.find("solves/s while dragging"), std::string::npos) << bench;
  EXPECT_NE(bench.find("latency mouse event -> solve shown: median "), std::string::npos) << bench;
  EXPECT_NE(bench.find("after the release: step 1, initial solve: E = "), std::string::npos)
      << bench;
  EXPECT_EQ(bench.find(" 0 shown"), std::string::npos) << bench;
  const json s = read_json(path("state.json"));
  ASSERT_FALSE(s.is_null());
  EXPECT_TRUE(s.at("document").at("dirty").get<bool>()) << "the drag moved no node";
  EXPECT_EQ(s.at("document").at("can_undo"), true);
  ASSERT_FALSE(s.at("result").is_null());
  EXPECT_EQ(s.at("result").at("status"), "finished");
}

}  // namespace
