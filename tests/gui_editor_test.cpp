// The editor's state without a window (app/gui/editor.h, job_control.h and their parts):
// results that are never lost (pins during a run, Stop, Keep result), the autosave offer, the
// default save path, file errors, why Run cannot start, the file browser's listing, the key
// map and camera views, the plot's ticks and the ASCII text fallback. The editor runs its real
// pipeline job on the bundled example. The key map and camera tests need the render library
// (QS_TEST_RENDER, when the app is built).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <thread>

#include "app/gui/editor.h"
#include "app/gui/file_browser.h"
#include "app/gui/plot_ticks.h"
#include "app/gui/ui_text.h"
#include "core/layout/layout_io.h"
#include "tests/gui_editor_fixture.h"
#include "tests/scoped_env.h"
#ifdef QS_TEST_RENDER
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>  // key codes only

#include "app/gui/actions.h"
#endif

namespace qs::app {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const fs::path kAssets = QS_ASSETS_DIR;
const fs::path kExampleMesh = kAssets / "example" / "ellipsoid.obj";
const fs::path kExampleLayout = kAssets / "example" / "ellipsoid.layout.json";

// Every test gets its own home, config and autosave folders (the editor autosaves every edit).
class GuiEditor : public ::testing::Test {
 protected:
  GuiEditor()
      : sandbox_("qs_gui_editor", ::testing::UnitTest::GetInstance()->current_test_info()->name()),
        dir_(sandbox_.dir()) {
    fs::create_directories(dir_ / "home" / "Documents");
  }
  static EditorConfig config() { return test::editor_test_config(); }
  static bool poll_until(Editor& editor, const std::function<bool()>& done,
                         std::chrono::seconds timeout = 120s) {
    return test::poll_editor_until(editor, done, timeout);
  }
  static bool finished(const Editor& editor) {
    const SnapshotPtr& s = editor.job.latest();
    return s && (s->status == WorkerStatus::Finished || s->status == WorkerStatus::Failed);
  }

  test::EditorSandbox sandbox_;
  const fs::path dir_;
};

TEST_F(GuiEditor, ArcPinnedDuringARunGoesToTheRunWhichGoesOn) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  editor.job.options.publish_interval_ms = 0;
  editor.run();
  ASSERT_TRUE(poll_until(editor, [&] {
    const Snapshot* s = editor.result();
    return s && s->iteration >= 2;
  }));
  const Snapshot* before = editor.result();
  ASSERT_TRUE(before && before->layout) << editor.job.latest()->message;
  const std::uint64_t generation = before->generation;
  const int iteration = before->iteration;
  const int arc = before->layout->arcs[0].id;
  ASSERT_TRUE(editor.job.live_pins());
  editor.toggle_arc_pin(arc);
  EXPECT_TRUE(editor.arc_pinned(arc));  // shown at once
  EXPECT_FALSE(editor.doc.dirty);       // the edited layout is untouched: no restart
  ASSERT_TRUE(poll_until(editor, [&] { return finished(editor); }));
  const Snapshot* after = editor.result();
  ASSERT_TRUE(after) << editor.job.latest()->message;
  EXPECT_EQ(after->status, WorkerStatus::Finished) << after->message;
  EXPECT_EQ(after->generation, generation);  // the same run
  EXPECT_GT(after->iteration, iteration);
  const int k = after->layout->arc_index(arc);
  ASSERT_GE(k, 0);
  EXPECT_TRUE(after->layout->arcs[k].pinned);
  EXPECT_TRUE(editor.arc_pinned(arc));
}

TEST_F(GuiEditor, StopKeepsTheStateReachedAndKeepAdoptsIt) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  editor.job.options.publish_interval_ms = 0;
  editor.run();
  ASSERT_TRUE(poll_until(editor, [&] {
    const Snapshot* s = editor.result();
    return s && s->iteration >= 2;
  }));
  editor.stop();
  ASSERT_TRUE(
      poll_until(editor, [&] { return editor.job.latest()->status == WorkerStatus::Cancelled; }));
  const Snapshot* stopped = editor.result();
  ASSERT_TRUE(stopped);
  EXPECT_EQ(editor.result_kind(), ResultKind::Stopped);
  EXPECT_GE(stopped->iteration, 2);
  EXPECT_TRUE(std::isfinite(stopped->energy));
  EXPECT_FALSE(editor.job.running());
  const double energy = stopped->energy;
  const Layout reached = *stopped->layout;

  editor.keep_result();
  EXPECT_EQ(editor.result_kind(), ResultKind::Kept);
  ASSERT_TRUE(editor.result());
  EXPECT_EQ(editor.result()->energy, energy);
  const Layout& kept = editor.doc.editor.layout();
  ASSERT_EQ(kept.nodes.size(), reached.nodes.size());
  for (std::size_t n = 0; n < kept.nodes.size(); ++n)
    EXPECT_EQ(kept.nodes[n].vertex, reached.nodes[n].vertex);
  EXPECT_TRUE(editor.doc.dirty);
  // Undo brings the sketch back, and the kept result no longer describes it.
  editor.undo();
  EXPECT_EQ(editor.result_kind(), ResultKind::None);
}

TEST_F(GuiEditor, StopThenDiscardShowsTheEditedLayout) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  editor.job.options.publish_interval_ms = 0;
  editor.run();
  ASSERT_TRUE(poll_until(editor, [&] { return editor.result() != nullptr; }));
  editor.stop();
  ASSERT_TRUE(
      poll_until(editor, [&] { return editor.job.latest()->status == WorkerStatus::Cancelled; }));
  EXPECT_EQ(editor.result_kind(), ResultKind::Stopped);
  editor.discard_result();
  EXPECT_EQ(editor.result_kind(), ResultKind::None);
  EXPECT_FALSE(editor.doc.dirty);
}

TEST_F(GuiEditor, KeepResultKeepsTheEnergyTheQuadMeshAndTheExport) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  editor.run();
  ASSERT_TRUE(poll_until(editor, [&] { return finished(editor); }));
  const Snapshot* done = editor.result();
  ASSERT_TRUE(done);
  ASSERT_EQ(done->status, WorkerStatus::Finished) << done->message;
  ASSERT_TRUE(done->quads);
  const double energy = done->energy;
  const std::size_t quads = done->quads->quads.size();
  EXPECT_GT(quads, 0u);

  editor.keep_result();
  // Also after the worker took the kept layout (its job reset).
  ASSERT_TRUE(
      poll_until(editor, [&] { return editor.job.latest()->status == WorkerStatus::Idle; }));
  EXPECT_EQ(editor.result_kind(), ResultKind::Kept);
  const Snapshot* kept = editor.result();
  ASSERT_TRUE(kept && kept->quads && kept->exports && kept->exports->quads);
  EXPECT_EQ(kept->energy, energy);
  EXPECT_EQ(kept->quads->quads.size(), quads);
  editor.exports.dir = (dir_ / "export").string();
  editor.export_files(ExportSelection{});
  EXPECT_FALSE(editor.exports.failed) << editor.exports.message;
  EXPECT_TRUE(fs::exists(dir_ / "export" / "quads.obj"));
  EXPECT_NE(editor.job_summary().find("kept"), std::string::npos);
  // An edit after Keep: the result no longer describes the layout.
  editor.toggle_node_pin(editor.doc.editor.layout().nodes[0].id);
  EXPECT_EQ(editor.result_kind(), ResultKind::None);
}

TEST_F(GuiEditor, PlainStartOffersAnAutosaveOfAnotherMesh) {
  // An earlier session edited another mesh and was killed: its autosave is on disk.
  const fs::path other = dir_ / "other.obj";
  fs::copy_file(kExampleMesh, other);
  {
    Editor crashed(config());
    ASSERT_TRUE(crashed.start(other.string(), ""));
    ASSERT_TRUE(crashed.doc.editor.add_node(5));  // the edit autosaves
    ASSERT_TRUE(fs::exists(autosave_path()));
  }
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));  // the bundled example
  ASSERT_TRUE(editor.autosave_offer.has_value());
  EXPECT_EQ(fs::path(editor.autosave_offer->mesh_path).filename(), "other.obj");
  EXPECT_FALSE(editor.autosave_offer->saved_at.empty());
  ASSERT_TRUE(editor.restore_autosave());
  EXPECT_EQ(fs::path(editor.doc.mesh_path).filename(), "other.obj");
  ASSERT_EQ(editor.doc.editor.layout().nodes.size(), 1u);
  EXPECT_EQ(editor.doc.editor.layout().nodes[0].vertex, 5);
  EXPECT_TRUE(editor.doc.dirty);
  EXPECT_FALSE(editor.autosave_offer.has_value());
}

TEST_F(GuiEditor, AnEditSetsAnUnansweredAutosaveAside) {
  {
    Editor crashed(config());
    ASSERT_TRUE(crashed.start("", ""));
    ASSERT_TRUE(crashed.doc.editor.toggle_node_pin(crashed.doc.editor.layout().nodes[0].id));
  }
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  ASSERT_TRUE(editor.autosave_offer.has_value());
  // Ignoring the offer, another edit.
  ASSERT_TRUE(editor.doc.editor.toggle_node_pin(editor.doc.editor.layout().nodes[1].id));
  EXPECT_FALSE(editor.autosave_offer.has_value());
  const fs::path previous = autosave_dir() / "autosave.previous.layout.json";
  ASSERT_TRUE(fs::exists(previous));
  const Layout old = load_layout(previous.string(), *editor.doc.mesh);
  EXPECT_TRUE(old.nodes[0].pinned);
  EXPECT_FALSE(old.nodes[1].pinned);
  const Layout current = load_layout(autosave_path().string(), *editor.doc.mesh);
  EXPECT_FALSE(current.nodes[0].pinned);
  EXPECT_TRUE(current.nodes[1].pinned);
}

TEST_F(GuiEditor, SaveNeverDefaultsToABundledFile) {
  Editor editor(config());
  ASSERT_TRUE(editor.start("", ""));
  EXPECT_TRUE(editor.is_bundled(kExampleLayout.string()));
  EXPECT_FALSE(editor.is_bundled((dir_ / "x.layout.json").string()));
  EXPECT_FALSE(editor.is_bundled(editor.save_path)) << editor.save_path;
  EXPECT_EQ(fs::path(editor.save_path).parent_path(), dir_ / "home" / "Documents");
  const auto before = fs::last_write_time(kExampleLayout);
  EXPECT_FALSE(editor.quick_save());  // Ctrl+S asks for a name instead
  EXPECT_EQ(fs::last_write_time(kExampleLayout), before);
  // After a save, the next default is next to it.
  const fs::path saved = dir_ / "work" / "mine.layout.json";
  fs::create_directories(saved.parent_path());
  ASSERT_TRUE(editor.save(saved.string()));
  EXPECT_EQ(editor.save_path, saved.string());
  EXPECT_TRUE(editor.quick_save());
  const fs::path other = dir_ / "other.obj";
  fs::copy_file(kExampleMesh, other);
  ASSERT_TRUE(editor.open_mesh(other.string()));
  EXPECT_EQ(editor.save_path, (saved.parent_path() / "other.layout.json").string());
}

TEST_F(GuiEditor, AMeshThatCannotBeOpenedIsReportedAndRunSaysWhy) {
  Editor editor(config());
  const std::string missing = (dir_ / "missing.obj").string();
  EXPECT_FALSE(editor.start(missing, ""));
  ASSERT_FALSE(editor.errors().empty());
  EXPECT_NE(editor.errors()[0].find(missing), std::string::npos);
  EXPECT_FALSE(editor.doc.mesh);
  EXPECT_NE(editor.run_blocker().find("no mesh"), std::string::npos);
  editor.run();
  EXPECT_NE(editor.status().find("Cannot run"), std::string::npos);
}

TEST_F(GuiEditor, RunOnAnInvalidLayoutSaysWhyInsteadOfDoingNothing) {
  Editor editor(config());
  ASSERT_TRUE(editor.start(kExampleMesh.string(),
                           (kAssets / "bad" / "five_sided_patch.layout.json").string()));
  const std::string why = editor.run_blocker();
  EXPECT_NE(why.find("validation error"), std::string::npos) << why;
  EXPECT_NE(why.find("5 corners"), std::string::npos) << why;
  editor.run();
  EXPECT_NE(editor.status().find("Cannot run"), std::string::npos);
  EXPECT_FALSE(editor.job.running());
}

TEST_F(GuiEditor, FileBrowserListsFoldersFirstAndFiltersByExtension) {
  const fs::path d = dir_ / "browse";
  fs::create_directories(d / "sub");
  for (const char* f : {"b.obj", "a.layout.json", "c.txt", "D.PLY", ".hidden.obj"})
    std::ofstream(d / f) << "x";
  FileBrowser browser;
  browser.open(BrowserMode::Open, (d / "b.obj").string());
  EXPECT_EQ(browser.folder(), d.string());
  std::vector<std::string> names;
  for (const auto& e : browser.entries()) names.push_back(e.name);
  EXPECT_EQ(names, (std::vector<std::string>{"sub", "a.layout.json", "b.obj", "D.PLY"}));
  browser.set_filter(2);  // layouts
  names.clear();
  for (const auto& e : browser.entries()) names.push_back(e.name);
  EXPECT_EQ(names, (std::vector<std::string>{"sub", "a.layout.json"}));
  browser.select(browser.entries()[0]);  // into "sub"
  EXPECT_EQ(browser.folder(), (d / "sub").string());
  ASSERT_TRUE(browser.up());
  EXPECT_EQ(browser.folder(), d.string());
  EXPECT_FALSE(browser.navigate((d / "nope").string()));
  EXPECT_FALSE(browser.error().empty());
  browser.open(BrowserMode::Save, (d / "new").string());
  EXPECT_EQ(browser.chosen_path(), (d / "new.layout.json").string());
}

#ifdef QS_TEST_RENDER
TEST(GuiKeys, NumpadViewsSetTheCameraDirectionAsInBlender) {
  struct Case {
    int key, mods;
    glm::vec3 direction, up;
  };
  const Case cases[] = {
      {GLFW_KEY_KP_1, 0, {0, 0, -1}, {0, 1, 0}},
      {GLFW_KEY_KP_1, GLFW_MOD_CONTROL, {0, 0, 1}, {0, 1, 0}},
      {GLFW_KEY_KP_3, 0, {-1, 0, 0}, {0, 1, 0}},
      {GLFW_KEY_KP_3, GLFW_MOD_CONTROL, {1, 0, 0}, {0, 1, 0}},
      {GLFW_KEY_KP_7, 0, {0, -1, 0}, {0, 0, -1}},
      {GLFW_KEY_KP_7, GLFW_MOD_CONTROL, {0, 1, 0}, {0, 0, 1}},
  };
  for (const auto mode : {render::OrbitMode::Turntable, render::OrbitMode::Trackball}) {
    EditorConfig config;
    config.remember_recent = false;
    config.step = [](WorkerState&, const WorkerObserver&) { return StepResult{}; };
    Editor editor(config);
    Tools tools;
    render::Camera camera;
    render::SurfacePicker picker;
    UiState ui;
    AppContext ctx{editor, tools, camera, picker, ui};
    camera.set_viewport(800, 600);
    camera.set_scene({0, 0, 0}, 1.0f);
    camera.set_orbit_mode(mode);
    camera.reset(true);
    for (const auto& c : cases) {
      perform(key_binding(c.key, c.mods), ctx);
      for (int i = 0; i < 200 && camera.animating(); ++i) camera.update(0.05f);
      EXPECT_FALSE(camera.animating());
      const glm::vec3 d = camera.view_direction(), u = camera.up_direction();
      EXPECT_NEAR(glm::length(d - c.direction), 0.0f, 1e-3f)
          << "key " << c.key << " mods " << c.mods << ": " << d.x << " " << d.y << " " << d.z;
      EXPECT_NEAR(glm::length(u - c.up), 0.0f, 1e-3f)
          << "key " << c.key << " mods " << c.mods << ": up " << u.x << " " << u.y << " " << u.z;
      // The target stays: eye = target - distance * direction.
      EXPECT_NEAR(glm::length(camera.eye() - (camera.target() - camera.distance() * d)), 0.0f,
                  1e-3f);
    }
    EXPECT_FALSE(camera.orthographic());
    perform(key_binding(GLFW_KEY_KP_5, 0), ctx);
    EXPECT_TRUE(camera.orthographic());
    // Orthographic picking still hits the sphere's centre straight ahead.
    const render::Ray ray = camera.ray(0.5f * camera.viewport());
    EXPECT_NEAR(glm::length(glm::cross(glm::vec3(ray.direction), camera.view_direction())), 0.0f,
                1e-4f);
  }
}

TEST(GuiKeys, TurntableDragsNeverRoll) {
  render::Camera camera;
  camera.set_viewport(800, 600);
  camera.set_scene({0, 0, 0}, 1.0f);
  camera.reset(true);
  ASSERT_EQ(camera.orbit_mode(), render::OrbitMode::Turntable);
  const auto right = [&] { return glm::cross(camera.view_direction(), camera.up_direction()); };
  // Circular drags (which roll a trackball).
  camera.begin_orbit({400, 300});
  for (int k = 0; k <= 90; ++k) {
    const float a = float(k) * 0.2f;
    camera.orbit_to({400 + 250 * std::cos(a), 300 + 250 * std::sin(a)});
    ASSERT_NEAR(right().y, 0.0f, 1e-5f) << "step " << k;
    ASSERT_GE(camera.up_direction().y, -1e-5f) << "upside down at step " << k;
  }
  // The same drags roll a trackball.
  camera.set_orbit_mode(render::OrbitMode::Trackball);
  camera.begin_orbit({400, 300});
  float max_roll = 0.0f;
  for (int k = 0; k <= 90; ++k) {
    const float a = float(k) * 0.2f;
    camera.orbit_to({400 + 250 * std::cos(a), 300 + 250 * std::sin(a)});
    max_roll = std::max(max_roll, std::abs(right().y));
  }
  EXPECT_GT(max_roll, 0.1f);
  // Back to the turntable: the roll is dropped.
  camera.set_orbit_mode(render::OrbitMode::Turntable);
  EXPECT_NEAR(right().y, 0.0f, 1e-5f);
}

TEST(GuiKeys, KeyMapCoversTheShortcuts) {
  EXPECT_EQ(key_binding(GLFW_KEY_Z, GLFW_MOD_CONTROL).action, Action::Undo);
  EXPECT_EQ(key_binding(GLFW_KEY_Z, GLFW_MOD_CONTROL | GLFW_MOD_SHIFT).action, Action::Redo);
  EXPECT_EQ(key_binding(GLFW_KEY_O, GLFW_MOD_CONTROL).action, Action::Open);
  EXPECT_EQ(key_binding(GLFW_KEY_S, GLFW_MOD_CONTROL).action, Action::Save);
  EXPECT_EQ(key_binding(GLFW_KEY_S, GLFW_MOD_CONTROL | GLFW_MOD_SHIFT).action, Action::SaveAs);
  EXPECT_EQ(key_binding(GLFW_KEY_KP_DECIMAL, 0).action, Action::FrameSelected);
  EXPECT_EQ(key_binding(GLFW_KEY_HOME, 0).action, Action::FrameAll);
  EXPECT_EQ(key_binding(GLFW_KEY_3, 0).action, Action::SetTool);
  EXPECT_EQ(key_binding(GLFW_KEY_3, 0).tool, 2);
  EXPECT_EQ(key_binding(GLFW_KEY_S, 0).action, Action::None);
  EXPECT_EQ(key_from_name("KP_7"), GLFW_KEY_KP_7);
  EXPECT_EQ(key_from_name("O"), GLFW_KEY_O);
  EXPECT_EQ(key_from_name("HOME"), GLFW_KEY_HOME);
  EXPECT_EQ(key_from_name("nope"), -1);
}

#endif  // QS_TEST_RENDER

TEST(GuiPlot, TicksCoverTheRangeWithReadableLabels) {
  // Three decades: the powers of ten.
  auto t = log_ticks(0.002, 3.0);
  std::vector<std::string> labels;
  for (const auto& x : t) labels.push_back(x.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"0.01", "0.1", "1"}));
  // One decade: with 2 and 5 times them.
  t = log_ticks(0.3, 4.0);
  labels.clear();
  for (const auto& x : t) labels.push_back(x.label);
  EXPECT_EQ(labels, (std::vector<std::string>{"0.5", "1", "2"}));
  // Less than a decade: evenly spaced, inside the range, at least two.
  t = log_ticks(0.43, 0.62);
  ASSERT_GE(t.size(), 2u);
  for (const auto& x : t) {
    EXPECT_GE(x.value, 0.43 - 1e-12);
    EXPECT_LE(x.value, 0.62 + 1e-12);
  }
  EXPECT_TRUE(log_ticks(-1.0, 2.0).empty());
  EXPECT_EQ(tick_label(2e-5), "2e-5");
  // Steps: integers, ordered, within the range, at most the given count.
  const auto s = step_ticks(1, 36, 6);
  ASSERT_GE(s.size(), 2u);
  EXPECT_LE(s.size(), 6u);
  for (std::size_t k = 0; k < s.size(); ++k) {
    EXPECT_EQ(s[k].value, std::round(s[k].value));
    EXPECT_GE(s[k].value, 1.0);
    EXPECT_LE(s[k].value, 36.0);
    if (k > 0) {
      EXPECT_GT(s[k].value, s[k - 1].value);
    }
  }
}

TEST(GuiText, AsciiFallbackSpellsOutTheSigns) {
  EXPECT_EQ(ascii_text("nodes \u2212 arcs + patches = 8 \u2260 8 + 3"),
            "nodes - arcs + patches = 8 != 8 + 3");
  EXPECT_EQ(ascii_text("\u03c3\u2081 \u2192 35\u00b0"), "sigma? -> 35 deg");
  EXPECT_EQ(ascii_text("plain"), "plain");
  EXPECT_EQ(ascii_text(std::string("cut \xe2\x88")), "cut ?");  // truncated UTF-8
  set_unicode_text(false);
  EXPECT_EQ(ui_text("a \u2264 b"), "a <= b");
  set_unicode_text(true);
  EXPECT_EQ(ui_text("a \u2264 b"), "a \u2264 b");
}

}  // namespace
}  // namespace qs::app
