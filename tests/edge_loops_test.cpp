// Edge loops (core/layout/edge_loops.h): inserting a loop through a closed poly-chord (cube
// layout, torus) and an open one (a disk, ending on boundary arcs) keeps the layout valid with
// every patch 4-sided and N more patches, on the plain mesh (route_layout) and on a working
// mesh (embed_layout); removing the inserted loop gives back the layout before; loops and
// chords that cannot be edited are refused naming the arc, node or patch.
#include "core/layout/edge_loops.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "core/base/errors.h"
#include "core/layout/embed.h"
#include "core/layout/routing.h"
#include "core/layout/validate.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// The inserted loop's layout routed on the plain mesh (route_layout).
Layout routed(const TriMesh& mesh, Layout layout) {
  route_layout(mesh, layout);
  return layout;
}

std::string first_error(const TriMesh& mesh, const Layout& layout) {
  for (const auto& issue : validate_layout(mesh, layout).issues)
    if (issue.severity == IssueSeverity::Error) return format_issue(issue);
  return {};
}

// Every patch a disk with 4 corners and 4 arc sides; returns the patch count.
int count_four_sided_patches(const TriMesh& mesh, const Layout& layout) {
  const LayoutTopology topo = build_topology(mesh, layout);
  int count = 0;
  for (const auto& p : topo.patches) {
    EXPECT_EQ(p.corners.size(), 4u);
    EXPECT_EQ(p.darts.size(), 4u);
    EXPECT_FALSE(p.trimmed);
    count += p.corners.size() == 4 && p.darts.size() == 4 && !p.trimmed;
  }
  return count;
}

// Ids, ends and paths of nodes and arcs, in id order.
struct Structure {
  std::vector<std::pair<int, int>> nodes;  // (id, vertex)
  std::vector<std::tuple<int, int, int, std::vector<int>>> arcs;
  bool operator==(const Structure&) const = default;
};

Structure structure(const Layout& layout) {
  Structure s;
  for (const auto& n : layout.nodes) s.nodes.emplace_back(n.id, n.vertex);
  for (const auto& a : layout.arcs) s.arcs.emplace_back(a.id, a.from, a.to, a.path);
  std::sort(s.nodes.begin(), s.nodes.end());
  std::sort(s.arcs.begin(), s.arcs.end());
  return s;
}

// Inserts a loop through arc \p arc_id, checks the result on the plain mesh, removes the loop
// again through one of its new arcs and checks that the layout is back.
void insert_and_remove(const test::MeshAndLayout& ex, int arc_id, std::size_t chord_patches,
                       bool closed) {
  const TriMesh& mesh = ex.mesh;
  ASSERT_TRUE(validate_layout(mesh, ex.layout).valid());
  const int patches = count_four_sided_patches(mesh, ex.layout);
  const EdgeLoopInsertion ins = insert_edge_loop(mesh, ex.layout, arc_id);
  EXPECT_EQ(ins.chord.closed, closed);
  EXPECT_EQ(ins.chord.patches.size(), chord_patches);
  EXPECT_EQ(ins.chord.arcs.size(), chord_patches + (closed ? 0 : 1));
  EXPECT_EQ(ins.new_nodes.size(), ins.chord.arcs.size());
  EXPECT_EQ(ins.new_arcs.size(), chord_patches);
  for (int id : ins.new_nodes) {
    const auto& node = ins.layout.nodes[ins.layout.node_index(id)];
    ASSERT_TRUE(node.point.has_value());
    EXPECT_EQ(snap_to_vertex(mesh, *node.point), node.vertex);  // a consistent file
  }
  const Layout plain = routed(mesh, ins.layout);
  ASSERT_TRUE(validate_layout(mesh, plain).valid()) << first_error(mesh, plain);
  EXPECT_EQ(count_four_sided_patches(mesh, plain), patches + int(chord_patches));
  EXPECT_EQ(plain.nodes.size(), ex.layout.nodes.size() + ins.new_nodes.size());
  EXPECT_EQ(plain.arcs.size(), ex.layout.arcs.size() + ins.split_arcs.size() + ins.new_arcs.size());
  const LayoutTopology topo = build_topology(mesh, plain);
  for (int id : ins.new_nodes) {
    const int n = plain.node_index(id);
    const bool boundary = mesh.is_boundary(OpenMesh::VertexHandle(plain.nodes[n].vertex));
    EXPECT_EQ(topo.valence[n], boundary ? 3 : 4) << "node " << id;
  }
  // Removing the loop through any of its arcs gives the layout back.
  for (int arc : {ins.new_arcs.front(), ins.new_arcs.back()}) {
    const Layout removed = remove_edge_loop(mesh, plain, arc);
    EXPECT_TRUE(structure(removed) == structure(ex.layout)) << "removed through arc " << arc;
    EXPECT_TRUE(validate_layout(mesh, removed).valid());
  }
}

TEST(EdgeLoops, ClosedChordOfTheCubeLayout) {
  const auto ex = test::cube_sphere(8);
  insert_and_remove(ex, 0, 4, /*closed=*/true);
}

TEST(EdgeLoops, ClosedChordAroundATorus) {
  const auto ex = test::torus_grid(24, 12, 4, 2);
  // A 4 × 2 grid of patches: the chord across an arc of one family runs around the torus.
  const LayoutTopology topo = build_topology(ex.mesh, ex.layout);
  const PolyChord chord = find_poly_chord(ex.layout, topo, 0);
  ASSERT_TRUE(chord.closed);
  insert_and_remove(ex, ex.layout.arcs[0].id, chord.patches.size(), true);
}

TEST(EdgeLoops, OpenChordOfADiskEndsOnBoundaryArcs) {
  const auto ex = test::disk_grid(12, 12, 3, 3);
  const LayoutTopology topo = build_topology(ex.mesh, ex.layout);
  // An interior arc: its chord runs across the disk from boundary to boundary.
  int interior = -1;
  for (int a = 0; a < int(ex.layout.arcs.size()) && interior < 0; ++a) {
    const auto& path = ex.layout.arcs[a].path;
    bool inside = true;
    for (int v : path) inside = inside && !ex.mesh.is_boundary(OpenMesh::VertexHandle(v));
    if (inside) interior = a;
  }
  ASSERT_GE(interior, 0);
  const PolyChord chord = find_poly_chord(ex.layout, topo, interior);
  EXPECT_FALSE(chord.closed);
  EXPECT_EQ(chord.patches.size(), 3u);
  insert_and_remove(ex, ex.layout.arcs[interior].id, 3, false);
}

TEST(EdgeLoops, TwoLoopsInOneChordAndTheFirstRemoved) {
  const auto ex = test::cube_sphere(8);
  const Layout once = routed(ex.mesh, insert_edge_loop(ex.mesh, ex.layout, 0).layout);
  // Arc 0's first half keeps id 0: the same chord again.
  const EdgeLoopInsertion second = insert_edge_loop(ex.mesh, once, 0);
  const Layout twice = routed(ex.mesh, second.layout);
  ASSERT_TRUE(validate_layout(ex.mesh, twice).valid()) << first_error(ex.mesh, twice);
  EXPECT_EQ(count_four_sided_patches(ex.mesh, twice), 14);
  const Layout back = remove_edge_loop(ex.mesh, twice, second.new_arcs[1]);
  EXPECT_TRUE(structure(back) == structure(once));
}

TEST(EdgeLoops, InsertedLoopEmbedsOnAWorkingMesh) {
  const auto ex = test::cube_sphere(8);
  const EdgeLoopInsertion ins = insert_edge_loop(ex.mesh, ex.layout, 5);
  const auto input = std::make_shared<TriMesh>(ex.mesh);
  const EmbeddedLayout embedded = embed_layout(input, ins.layout);
  const TriMesh& w = embedded.mesh->mesh();
  ASSERT_TRUE(validate_layout(w, embedded.layout).valid()) << first_error(w, embedded.layout);
  EXPECT_EQ(count_four_sided_patches(w, embedded.layout), 10);
  // The new nodes sit exactly at their arcs' midpoints.
  for (int id : ins.new_nodes) {
    const auto& node = embedded.layout.nodes[embedded.layout.node_index(id)];
    const auto& given = ins.layout.nodes[ins.layout.node_index(id)];
    EXPECT_LT((w.point(OpenMesh::VertexHandle(node.vertex)) - embedded.mesh->position(*given.point))
                  .norm(),
              1e-12);
  }
}

TEST(EdgeLoops, LoopsThatCannotBeEditedAreRefusedWithTheirNames) {
  const auto cube = test::cube_sphere(8);
  // The cube's edges run through its valence-3 corners: no edge loop to remove.
  try {
    remove_edge_loop(cube.mesh, cube.layout, 0);
    FAIL() << "removed a loop through valence-3 nodes";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("of valence 3"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("through arc 0"), std::string::npos) << e.what();
  }
  EXPECT_THROW(insert_edge_loop(cube.mesh, cube.layout, 99), InvalidInputError);
  // Arcs of one mesh edge leave no vertex for the new nodes.
  const auto coarse = test::cube_sphere(1);
  ASSERT_TRUE(validate_layout(coarse.mesh, coarse.layout).valid());
  try {
    insert_edge_loop(coarse.mesh, coarse.layout, 0);
    FAIL() << "inserted a loop into single-edge arcs";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("single mesh edge"), std::string::npos) << e.what();
  }
  // A star of dangling arcs: trimmed patches, no chord.
  const auto star = test::flat_square_with_free_hole();
  ASSERT_TRUE(validate_layout(star.mesh, star.layout).valid());
  EXPECT_THROW(insert_edge_loop(star.mesh, star.layout, star.layout.arcs[0].id), InvalidInputError);
  // An invalid layout is refused with its first error.
  Layout broken = cube.layout;
  broken.arcs.pop_back();
  try {
    insert_edge_loop(cube.mesh, broken, 0);
    FAIL() << "inserted a loop into an invalid layout";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs a valid layout"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace qs
