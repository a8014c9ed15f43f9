// Tests of layout perturbation (core/import/perturb.h), of separate_nodes
// (core/layout/node_shift.h) and of `quadsketch-cli perturb`.
#include "core/import/perturb.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"
#include "core/import/quad_import.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

using VH = OpenMesh::VertexHandle;
using test::quad_cube;

//! Breadth-first edge distance between two vertices.
int ring_distance(const TriMesh& mesh, int a, int b) {
  std::vector<int> dist(mesh.n_vertices(), -1);
  std::vector<int> queue{a};
  dist[a] = 0;
  for (size_t head = 0; head < queue.size(); ++head) {
    const int v = queue[head];
    if (v == b) return dist[v];
    for (const auto w : mesh.vv_range(VH(v))) {
      if (dist[w.idx()] < 0) {
        dist[w.idx()] = dist[v] + 1;
        queue.push_back(w.idx());
      }
    }
  }
  return -1;
}

//! Cyclic arc-id orders per node, each rotated to start at its smallest half-arc.
std::vector<std::vector<int>> cyclic_orders(const TriMesh& mesh, const Layout& layout) {
  const LayoutTopology topo = build_topology(mesh, layout);
  std::vector<std::vector<int>> out;
  for (auto list : topo.node_half_arcs) {
    if (!list.empty())
      std::rotate(list.begin(), std::min_element(list.begin(), list.end()), list.end());
    out.push_back(list);
  }
  return out;
}

void expect_valid_same_structure(const TriMesh& mesh, const Layout& before, const Layout& after) {
  const ValidationResult vr = validate_layout(mesh, after);
  ASSERT_TRUE(vr.valid()) << (vr.issues.empty() ? "" : format_issue(vr.issues[0]));
  EXPECT_EQ(build_topology(mesh, before).patches.size(),
            build_topology(mesh, after).patches.size());
  EXPECT_EQ(cyclic_orders(mesh, before), cyclic_orders(mesh, after));
}

QuadImportResult refined_cube(int k, int refine) {
  QuadImportOptions options;
  options.refine = refine;
  return import_quads(quad_cube(k), nullptr, options);
}

TEST(Perturb, CubeNodesMoveByTheRequestedRings) {
  const QuadImportResult r = refined_cube(2, 4);  // arcs of 8 edges
  for (int rings : {1, 2, 3}) {
    PerturbLayoutOptions options;
    options.rings = rings;
    options.seed = 7;
    const PerturbResult p = perturb_layout(r.mesh, r.layout, options);
    expect_valid_same_structure(r.mesh, r.layout, p.layout);
    EXPECT_EQ(p.moved_nodes.size() + p.stuck_nodes.size(), r.layout.nodes.size());
    EXPECT_GE(p.moved_nodes.size(), r.layout.nodes.size() / 2) << "rings " << rings;
    for (int id : p.moved_nodes) {
      const int n = r.layout.node_index(id);
      EXPECT_EQ(ring_distance(r.mesh, r.layout.nodes[n].vertex, p.layout.nodes[n].vertex), rings);
    }
    for (int id : p.stuck_nodes) {
      const int n = r.layout.node_index(id);
      EXPECT_EQ(r.layout.nodes[n].vertex, p.layout.nodes[n].vertex);
    }
  }
}

TEST(Perturb, SameSeedSameResult) {
  const QuadImportResult r = refined_cube(2, 4);
  PerturbLayoutOptions options;
  options.rings = 2;
  options.seed = 42;
  const std::string a = layout_to_json(perturb_layout(r.mesh, r.layout, options).layout);
  const std::string b = layout_to_json(perturb_layout(r.mesh, r.layout, options).layout);
  EXPECT_EQ(a, b);
  options.seed = 43;
  const std::string c = layout_to_json(perturb_layout(r.mesh, r.layout, options).layout);
  EXPECT_NE(a, c);
}

TEST(Perturb, MovedNodesDropTheOutputFieldsOfTheirOldVertex) {
  const QuadImportResult r = refined_cube(2, 4);
  // Like an optimize output: every node carries a point at its vertex, a position, a valence.
  Layout input = r.layout;
  for (LayoutNode& node : input.nodes) {
    const auto vh = r.mesh.vertex_handle(node.vertex);
    const auto fh = *r.mesh.cvf_begin(vh);
    SurfacePoint at_vertex{fh.idx(), {0.0, 0.0, 0.0}};
    int k = 0;
    for (const auto corner : r.mesh.fv_range(fh)) at_vertex.bary[k++] = corner == vh ? 1.0 : 0.0;
    node.point = at_vertex;
    const Vec3& x = r.mesh.point(vh);
    node.position = std::array<double, 3>{x[0], x[1], x[2]};
    node.valence = 3;
  }
  PerturbLayoutOptions options;
  options.rings = 2;
  options.seed = 7;
  const PerturbResult p = perturb_layout(r.mesh, input, options);
  ASSERT_FALSE(p.moved_nodes.empty());
  for (int id : p.moved_nodes) {
    const LayoutNode& node = p.layout.nodes[p.layout.node_index(id)];
    EXPECT_FALSE(node.point.has_value()) << "node " << id;
    EXPECT_FALSE(node.position.has_value()) << "node " << id;
    EXPECT_EQ(node.valence, -1) << "node " << id;
  }
  for (int id : p.stuck_nodes) {
    EXPECT_TRUE(p.layout.nodes[p.layout.node_index(id)].point.has_value()) << "node " << id;
  }
  // The written result is a valid input: no node's point contradicts its vertex.
  const std::string path = test::temp_dir("perturb_outputs") + "/perturbed.json";
  save_layout(p.layout, path, &r.mesh);
  EXPECT_NO_THROW(load_layout(path, r.mesh));
}

TEST(Perturb, PinnedNodesStay) {
  QuadImportResult r = refined_cube(2, 4);
  r.layout.nodes[0].pinned = true;
  PerturbLayoutOptions options;
  options.rings = 1;
  const PerturbResult p = perturb_layout(r.mesh, r.layout, options);
  EXPECT_EQ(p.layout.nodes[0].vertex, r.layout.nodes[0].vertex);
  EXPECT_EQ(p.pinned_nodes, std::vector<int>{r.layout.nodes[0].id});
}

TEST(Perturb, InvalidLayoutOrRingsAreErrors) {
  QuadImportResult r = refined_cube(1, 3);
  PerturbLayoutOptions options;
  options.rings = 0;
  EXPECT_THROW(perturb_layout(r.mesh, r.layout, options), InvalidInputError);
  options.rings = 1;
  r.layout.arcs.pop_back();  // leaves a patch with a missing side
  EXPECT_THROW(perturb_layout(r.mesh, r.layout, options), InvalidInputError);
}

TEST(Perturb, RealSpotRefined) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes not found; real meshes skipped";
  QuadImportOptions io;
  io.refine = 3;
  const QuadImportResult r =
      import_quads(test::load_poly_mesh(dir + "/spot/spot_quadrangulated.obj"), nullptr, io);
  PerturbLayoutOptions options;
  options.rings = 2;
  options.seed = 1;
  const PerturbResult p = perturb_layout(r.mesh, r.layout, options);
  expect_valid_same_structure(r.mesh, r.layout, p.layout);
  EXPECT_GE(p.moved_nodes.size(), r.layout.nodes.size() * 3 / 4);
  for (int id : p.moved_nodes) {
    const int n = r.layout.node_index(id);
    EXPECT_EQ(ring_distance(r.mesh, r.layout.nodes[n].vertex, p.layout.nodes[n].vertex), 2);
  }
}

//! Ids of the nodes with another node on their vertex's 1-ring.
std::vector<int> nodes_next_to_others(const TriMesh& mesh, const Layout& layout) {
  std::vector<int> node_at(mesh.n_vertices(), -1);
  for (size_t n = 0; n < layout.nodes.size(); ++n) node_at[layout.nodes[n].vertex] = n;
  std::vector<int> out;
  for (size_t n = 0; n < layout.nodes.size(); ++n) {
    for (const auto w : mesh.vv_range(VH(layout.nodes[n].vertex))) {
      if (node_at[w.idx()] >= 0) {
        out.push_back(layout.nodes[n].id);
        break;
      }
    }
  }
  return out;
}

TEST(SeparateNodes, CrowdedNodesMoveApartKeepingTheStructure) {
  const test::MeshAndLayout r = test::crowded_refined_cube();  // the exact cube displaced
  const Layout& displaced = r.layout;
  const std::vector<int> crowded = nodes_next_to_others(r.mesh, displaced);
  ASSERT_GE(crowded.size(), 2u);

  const SeparateNodesResult s = separate_nodes(r.mesh, displaced, {});
  expect_valid_same_structure(r.mesh, displaced, s.layout);
  std::vector<int> listed = s.crowded_nodes;
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(listed, crowded);
  EXPECT_FALSE(s.moved_nodes.empty());
  EXPECT_EQ(nodes_next_to_others(r.mesh, s.layout), s.still_crowded);
  EXPECT_LT(s.still_crowded.size(), crowded.size());
  for (size_t n = 0; n < displaced.nodes.size(); ++n) {
    const int id = displaced.nodes[n].id;
    const bool moved =
        std::find(s.moved_nodes.begin(), s.moved_nodes.end(), id) != s.moved_nodes.end();
    const int d = ring_distance(r.mesh, displaced.nodes[n].vertex, s.layout.nodes[n].vertex);
    if (moved) {
      EXPECT_TRUE(std::find(crowded.begin(), crowded.end(), id) != crowded.end()) << id;
      EXPECT_GE(d, 1);
      EXPECT_LE(d, SeparateNodesOptions{}.search_rings);
    } else {
      EXPECT_EQ(d, 0) << "node " << id << " moved without being listed";
    }
  }

  // Nodes that may not move stay: none movable, or the crowded ones pinned.
  const SeparateNodesResult none =
      separate_nodes(r.mesh, displaced, std::vector<char>(displaced.nodes.size(), 0));
  EXPECT_TRUE(none.moved_nodes.empty());
  EXPECT_EQ(layout_to_json(none.layout), layout_to_json(displaced));
  Layout pinned = displaced;
  for (auto& node : pinned.nodes)
    if (std::find(crowded.begin(), crowded.end(), node.id) != crowded.end()) node.pinned = true;
  EXPECT_TRUE(separate_nodes(r.mesh, pinned, {}).moved_nodes.empty());

  // An exact layout has no crowded node and is returned as it is; bad options are refused.
  const QuadImportResult cube = refined_cube(2, 2);
  ASSERT_EQ(cube.mesh.n_vertices(), r.mesh.n_vertices());
  const SeparateNodesResult exact = separate_nodes(cube.mesh, cube.layout, {});
  EXPECT_TRUE(exact.crowded_nodes.empty());
  EXPECT_EQ(layout_to_json(exact.layout), layout_to_json(cube.layout));
  SeparateNodesOptions bad;
  bad.search_rings = 0;
  EXPECT_THROW(separate_nodes(r.mesh, displaced, {}, bad), InvalidInputError);
  EXPECT_THROW(separate_nodes(r.mesh, displaced, std::vector<char>(1, 1)), InvalidInputError);
}

TEST(PerturbCli, WritesAValidLayout) {
  const std::string dir = test::temp_dir("perturb_cli");
  const QuadImportResult r = refined_cube(2, 4);
  test::write_obj(r.mesh, dir + "/mesh.obj");
  save_layout(r.layout, dir + "/layout.json", &r.mesh);
  std::string output;
  const std::string cmd = test::cli_path() + " perturb --mesh " + dir + "/mesh.obj --layout " +
                          dir + "/layout.json --rings 2 --seed 5 --out ";
  ASSERT_EQ(test::run_command(cmd + dir + "/p1.json", &output), 0) << output;
  ASSERT_EQ(test::run_command(cmd + dir + "/p2.json", &output), 0) << output;
  EXPECT_EQ(read_file(dir + "/p1.json"), read_file(dir + "/p2.json"));
  ASSERT_EQ(test::run_command(test::cli_path() + " validate --mesh " + dir + "/mesh.obj --layout " +
                                  dir + "/p1.json",
                              &output),
            0)
      << output;
  EXPECT_NE(read_file(dir + "/p1.json"), read_file(dir + "/layout.json"));
}

}  // namespace
}  // namespace qs
