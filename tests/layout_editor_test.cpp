// Sketch edits and their undo/redo (app/gui/layout_editor.cpp, GL-free), autosave and the
// recent-files list. Built from tests/cmake/gui_smoke.cmake with the app sources it needs.
#include "app/gui/layout_editor.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "app/gui/autosave.h"
#include "app/gui/recent_files.h"
#include "core/base/atomic_file.h"
#include "core/layout/layout_io.h"

namespace qs::app {
namespace {

namespace fs = std::filesystem;

// (n+1) x (n+1) vertices on the unit square, vertex (i, j) has index j * (n + 1) + i.
TriMesh grid(int n) {
  TriMesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) mesh.add_vertex(Vec3(double(i) / n, double(j) / n, 0.0));
  auto v = [&](int i, int j) { return OpenMesh::VertexHandle(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      mesh.add_face(v(i, j), v(i + 1, j), v(i + 1, j + 1));
      mesh.add_face(v(i, j), v(i + 1, j + 1), v(i, j + 1));
    }
  return mesh;
}

int vid(int i, int j, int n = 10) {
  return j * (n + 1) + i;
}

// Exact comparison through the serializer, which writes every field.
std::string dump(const Layout& layout) {
  return layout_to_json(layout);
}

class LayoutEditorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    mesh_ = grid(10);
    editor_.reset(&mesh_, Layout{});
  }
  // A square of four nodes and four arcs.
  void sketch_square() {
    ids_ = {editor_.add_node(vid(2, 2)).id, editor_.add_node(vid(8, 2)).id,
            editor_.add_node(vid(8, 8)).id, editor_.add_node(vid(2, 8)).id};
    for (int k = 0; k < 4; ++k) ASSERT_TRUE(editor_.add_arc(ids_[k], ids_[(k + 1) % 4]).ok);
  }
  TriMesh mesh_;
  LayoutEditor editor_;
  std::vector<int> ids_;
};

TEST_F(LayoutEditorTest, UndoRedoRestoresTheExactLayoutAfterEveryEdit) {
  std::vector<std::string> states = {dump(editor_.layout())};
  auto record = [&](const EditResult& r) {
    ASSERT_TRUE(r.ok) << r.error;
    states.push_back(dump(editor_.layout()));
  };
  record(editor_.add_node(vid(2, 2)));
  record(editor_.add_node(vid(8, 2)));
  record(editor_.add_node(vid(8, 8)));
  record(editor_.add_node(vid(2, 8)));
  const auto& nodes = editor_.layout().nodes;
  record(editor_.add_arc(nodes[0].id, nodes[1].id));
  record(editor_.add_arc(nodes[1].id, nodes[2].id));
  record(editor_.add_arc(nodes[2].id, nodes[3].id));
  record(editor_.add_arc(nodes[3].id, nodes[0].id));
  const int arc0 = editor_.layout().arcs[0].id;
  const int interior = editor_.layout().arcs[0].path[2];
  record(editor_.split_arc(arc0, interior));
  record(editor_.toggle_node_pin(editor_.layout().nodes[0].id));
  record(editor_.toggle_arc_pin(editor_.layout().arcs[1].id));
  record(editor_.move_node(editor_.layout().nodes[2].id, vid(9, 9)));
  record(editor_.delete_arc(editor_.layout().arcs[2].id));
  record(editor_.delete_node(editor_.layout().nodes[0].id));
  ASSERT_EQ(editor_.history_size(), states.size() - 1);

  for (std::size_t k = states.size() - 1; k > 0; --k) {
    ASSERT_TRUE(editor_.undo());
    EXPECT_EQ(dump(editor_.layout()), states[k - 1]) << "after undoing step " << k;
  }
  EXPECT_FALSE(editor_.undo());
  for (std::size_t k = 1; k < states.size(); ++k) {
    ASSERT_TRUE(editor_.redo());
    EXPECT_EQ(dump(editor_.layout()), states[k]) << "after redoing step " << k;
  }
  EXPECT_FALSE(editor_.redo());
}

TEST_F(LayoutEditorTest, ANewEditDropsTheRedoBranch) {
  sketch_square();
  ASSERT_TRUE(editor_.undo());
  EXPECT_TRUE(editor_.can_redo());
  ASSERT_TRUE(editor_.add_node(vid(5, 5)).ok);
  EXPECT_FALSE(editor_.can_redo());
}

TEST_F(LayoutEditorTest, ArcsFollowMeshEdgesBetweenTheirNodes) {
  sketch_square();
  const Layout& layout = editor_.layout();
  ASSERT_EQ(layout.arcs.size(), 4u);
  for (const auto& arc : layout.arcs) {
    ASSERT_GE(arc.path.size(), 2u);
    EXPECT_EQ(arc.path.front(), layout.nodes[layout.node_index(arc.from)].vertex);
    EXPECT_EQ(arc.path.back(), layout.nodes[layout.node_index(arc.to)].vertex);
    for (std::size_t i = 0; i + 1 < arc.path.size(); ++i)
      EXPECT_TRUE(mesh_
                      .find_halfedge(OpenMesh::VertexHandle(arc.path[i]),
                                     OpenMesh::VertexHandle(arc.path[i + 1]))
                      .is_valid());
  }
}

TEST_F(LayoutEditorTest, DeletingANodeDeletesItsArcs) {
  sketch_square();
  ASSERT_TRUE(editor_.delete_node(ids_[0]).ok);
  EXPECT_EQ(editor_.layout().nodes.size(), 3u);
  EXPECT_EQ(editor_.layout().arcs.size(), 2u);
  for (const auto& arc : editor_.layout().arcs) {
    EXPECT_NE(arc.from, ids_[0]);
    EXPECT_NE(arc.to, ids_[0]);
  }
}

TEST_F(LayoutEditorTest, RefusedEditsChangeNothing) {
  sketch_square();
  const std::string before = dump(editor_.layout());
  const auto history = editor_.history_size();
  const auto version = editor_.version();
  EXPECT_FALSE(editor_.add_node(vid(2, 2)).ok);                         // node already there
  EXPECT_FALSE(editor_.add_node(editor_.layout().arcs[0].path[1]).ok);  // on an arc
  EXPECT_FALSE(editor_.add_node(100000).ok);                            // out of range
  EXPECT_FALSE(editor_.add_arc(ids_[0], ids_[0]).ok);                   // loop
  EXPECT_FALSE(editor_.add_arc(ids_[0], 999).ok);                       // unknown node
  EXPECT_FALSE(editor_.delete_arc(999).ok);
  EXPECT_FALSE(editor_.move_node(ids_[0], vid(8, 8)).ok);                      // occupied by a node
  EXPECT_FALSE(editor_.split_arc(editor_.layout().arcs[0].id, vid(2, 2)).ok);  // an end
  EXPECT_EQ(dump(editor_.layout()), before);
  EXPECT_EQ(editor_.history_size(), history);
  EXPECT_EQ(editor_.version(), version);
}

TEST_F(LayoutEditorTest, SplitKeepsTheRouteAndAddsANode) {
  sketch_square();
  const LayoutArc arc = editor_.layout().arcs[0];
  const int mid = arc.path[arc.path.size() / 2];
  const auto r = editor_.split_arc(arc.id, mid);
  ASSERT_TRUE(r.ok) << r.error;
  const Layout& layout = editor_.layout();
  EXPECT_EQ(layout.nodes.size(), 5u);
  EXPECT_EQ(layout.arcs.size(), 5u);
  const auto& first = layout.arcs[layout.arc_index(arc.id)];
  EXPECT_EQ(first.to, r.id);
  EXPECT_EQ(first.path.back(), mid);
  EXPECT_EQ(node_valence(layout, r.id), 2);
}

TEST_F(LayoutEditorTest, MovingANodeReroutesItsArcs) {
  sketch_square();
  ASSERT_TRUE(editor_.move_node(ids_[2], vid(9, 9)).ok);
  const Layout& layout = editor_.layout();
  for (const auto& arc : layout.arcs) {
    if (arc.from == ids_[2]) {
      EXPECT_EQ(arc.path.front(), vid(9, 9));
    }
    if (arc.to == ids_[2]) {
      EXPECT_EQ(arc.path.back(), vid(9, 9));
    }
  }
}

TEST_F(LayoutEditorTest, ADragIsOneUndoStep) {
  sketch_square();
  const std::string before = dump(editor_.layout());
  const auto history = editor_.history_size();
  ASSERT_TRUE(editor_.begin_drag(ids_[2]));
  EXPECT_TRUE(editor_.drag_to(vid(9, 8)).ok);
  EXPECT_TRUE(editor_.drag_to(vid(9, 9)).ok);
  EXPECT_FALSE(editor_.add_node(vid(5, 5)).ok);  // no edits in the middle of a drag
  editor_.end_drag();
  EXPECT_EQ(editor_.history_size(), history + 1);
  EXPECT_EQ(editor_.layout().nodes[editor_.layout().node_index(ids_[2])].vertex, vid(9, 9));
  ASSERT_TRUE(editor_.undo());
  EXPECT_EQ(dump(editor_.layout()), before);

  // A cancelled drag restores the layout and records nothing.
  ASSERT_TRUE(editor_.begin_drag(ids_[2]));
  EXPECT_TRUE(editor_.drag_to(vid(9, 9)).ok);
  editor_.cancel_drag();
  EXPECT_EQ(dump(editor_.layout()), before);
  EXPECT_EQ(editor_.history_size(), history + 1);
  EXPECT_TRUE(editor_.can_redo());
}

TEST_F(LayoutEditorTest, OnChangeFiresForEditsUndoAndRedo) {
  int calls = 0;
  editor_.on_change = [&](const Layout&) { ++calls; };
  ASSERT_TRUE(editor_.add_node(vid(1, 1)).ok);
  EXPECT_FALSE(editor_.add_node(vid(1, 1)).ok);
  editor_.undo();
  editor_.redo();
  EXPECT_EQ(calls, 3);
}

class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

fs::path fresh_dir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("qs_gui_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST_F(LayoutEditorTest, AutosaveIsValidJsonAfterAnEdit) {
  const fs::path dir = fresh_dir("autosave");
  ScopedEnv env("QS_AUTOSAVE_DIR", dir.string());
  ASSERT_EQ(autosave_path(), dir / "autosave.layout.json");
  const fs::path mesh_file = dir / "grid.obj";
  std::ofstream(mesh_file) << "# placeholder name only\n";
  editor_.on_change = [&](const Layout& layout) {
    write_autosave(layout, &mesh_, mesh_file.string(), "");
  };
  sketch_square();

  const auto json = nlohmann::json::parse(read_file(autosave_path().string()));
  EXPECT_EQ(json.at("format"), "quadsketch-layout");
  EXPECT_EQ(json.at("nodes").size(), 4u);
  EXPECT_EQ(json.at("arcs").size(), 4u);
  // And it loads back as the same layout.
  const Layout back = load_layout(autosave_path().string(), mesh_);
  EXPECT_EQ(back.arcs.size(), 4u);
  EXPECT_EQ(back.arcs[2].path, editor_.layout().arcs[2].path);

  const auto offer = find_autosave(mesh_file.string(), "");
  ASSERT_TRUE(offer.has_value());
  EXPECT_EQ(offer->path, autosave_path());
  EXPECT_FALSE(find_autosave((dir / "other.obj").string(), "").has_value());
  // One file carries the layout and its description (a single atomic write), no sidecar.
  EXPECT_EQ(json.at("autosave").at("mesh"), fs::weakly_canonical(mesh_file).string());
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 2u);  // grid.obj and autosave.layout.json
  // A torn or foreign file is never offered.
  std::ofstream(autosave_path()) << "{ \"format\": \"quadsketch-layout\", \"nod";
  EXPECT_FALSE(find_autosave(mesh_file.string(), "").has_value());
  fs::remove_all(dir);
}

TEST(RecentFiles, ToleratesMissingAndCorruptFiles) {
  const fs::path dir = fresh_dir("recent");
  RecentFiles recent;
  recent.load(dir / "missing" / "recent.json");
  EXPECT_TRUE(recent.meshes().empty());
  recent.add_mesh("/a/b.obj");
  recent.add_mesh("/a/c.obj");
  recent.add_mesh("/a/b.obj");
  recent.add_layout("/a/b.layout.json");
  ASSERT_TRUE(recent.save());

  RecentFiles again;
  again.load(dir / "missing" / "recent.json");
  ASSERT_EQ(again.meshes().size(), 2u);
  EXPECT_EQ(again.meshes()[0], "/a/b.obj");  // most recent first, no duplicates
  EXPECT_EQ(again.layouts().size(), 1u);

  std::ofstream(dir / "corrupt.json") << "{ not json";
  RecentFiles corrupt;
  corrupt.load(dir / "corrupt.json");
  EXPECT_TRUE(corrupt.meshes().empty());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace qs::app
