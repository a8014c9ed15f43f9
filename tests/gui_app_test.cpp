// The editor end to end under Xvfb (software OpenGL): each test runs `quadsketch` with a
// --script of editor commands (app/gui/automation.h), which drives the same code as the mouse,
// keys and panels, and checks the state the app writes as JSON (app/gui/state_dump.h). Every
// run gets its own home, config and autosave folders. Skipped without xvfb-run or without the
// app (QS_GUI_APP, set by tests/cmake/gui_smoke.cmake).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
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
  const std::string script = "run\nwait_step 2\nstop\nframes 3\nstate " + p("stopped.json") +
                             "\nkeep\nframes 2\nstate " + p("kept.json") + "\nquit\n";
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
  const std::string script = "run\nwait_finished\nframes 2\nstate " + p("finished.json") +
                             "\nkeep\nframes 3\nstate " + p("kept.json") + "\nquit\n";
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

}  // namespace
