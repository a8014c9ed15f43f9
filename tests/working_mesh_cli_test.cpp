// A layout whose nodes are surface points off the mesh vertices and whose arcs are surface
// polylines runs through quadsketch-cli on a working mesh refined from the input
// (docs/interfaces.md, "working_mesh" in report.json): validate and optimize accept it, and the
// result is fold-free and structurally equivalent.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "core/layout/layout_io.h"
#include "core/mesh/mesh_io.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

// The bundled example's layout with every node moved off its vertex to a point inside one of
// its faces (weight 0.6 on the vertex) and every arc given by the midpoints of its path's edges.
std::string point_layout(const std::string& dir) {
  const std::string example = test::assets_dir() + "/example/ellipsoid";
  const TriMesh mesh = load_mesh(example + ".obj");
  Layout layout = load_layout(example + ".layout.json", mesh);
  const auto point_in_face = [&](int f, int v, double w) {
    SurfacePoint p{f, {{0, 0, 0}}};
    int k = 0;
    for (auto u : mesh.fv_range(mesh.face_handle(f))) {
      p.bary[k] = u.idx() == v ? w : 0;
      ++k;
    }
    for (double& b : p.bary)
      if (b == 0) b = (1 - w) / 2;
    return p;
  };
  for (LayoutNode& node : layout.nodes) {
    const int f = mesh.vf_range(mesh.vertex_handle(node.vertex)).begin()->idx();
    node.point = point_in_face(f, node.vertex, 0.6);
    node.vertex = -1;
  }
  for (LayoutArc& arc : layout.arcs) {
    arc.points.clear();
    for (size_t k = 0; k + 1 < arc.path.size(); ++k) {
      const auto h =
          mesh.find_halfedge(mesh.vertex_handle(arc.path[k]), mesh.vertex_handle(arc.path[k + 1]));
      const int f = mesh.face_handle(h).is_valid() ? mesh.face_handle(h).idx()
                                                   : mesh.opposite_face_handle(h).idx();
      SurfacePoint p{f, {{0, 0, 0}}};
      int j = 0;
      for (auto u : mesh.fv_range(mesh.face_handle(f))) {
        if (u.idx() == arc.path[k] || u.idx() == arc.path[k + 1]) p.bary[j] = 0.5;
        ++j;
      }
      arc.points.push_back(p);
    }
    arc.path.clear();
  }
  layout.mesh_vertices = layout.mesh_faces = -1;
  const std::string path = dir + "/points.layout.json";
  std::ofstream(path) << layout_to_json(layout);
  return path;
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(WorkingMeshCli, PointLayoutValidatesAndOptimizesOnAWorkingMesh) {
  const std::string dir = test::temp_dir("working_mesh_cli");
  const std::string layout = point_layout(dir);
  const std::string mesh = test::mesh_file(test::assets_dir() + "/example/ellipsoid.obj");
  std::string log;
  ASSERT_EQ(test::run_command(test::cli_path() + " validate --mesh " + mesh + " --layout " +
                                  layout + " --out " + dir + "/validate",
                              &log),
            0)
      << log;
  const auto valid = read_json(dir + "/validate/report.json");
  EXPECT_EQ(valid["status"], "ok");
  EXPECT_TRUE(valid["working_mesh"]["refined"].get<bool>());
  EXPECT_GT(valid["working_mesh"]["faces"].get<int>(), valid["mesh"]["faces"].get<int>());

  ASSERT_EQ(test::run_command(test::cli_path() + " optimize --steps 15 --mesh " + mesh +
                                  " --layout " + layout + " --out " + dir + "/out",
                              &log),
            0)
      << log;
  const auto report = read_json(dir + "/out/report.json");
  std::printf("[stat] point layout: input %d faces, working %d faces; E %.6g -> %.6g\n",
              report["mesh"]["faces"].get<int>(), report["working_mesh"]["faces"].get<int>(),
              report["E_init"].get<double>(), report["E_final"].get<double>());
  EXPECT_TRUE(report["working_mesh"]["refined"].get<bool>());
  EXPECT_LE(report["working_mesh"]["growth"].get<double>(), 3.0);
  EXPECT_EQ(report["metrics"]["foldovers"].get<int>(), 0);
  EXPECT_TRUE(report["structurally_equivalent"].get<bool>());
  EXPECT_LE(report["E_final"].get<double>(), report["E_init"].get<double>());
  EXPECT_LT(report["E_final"].get<double>(), 0.6);
  // The written layout refers to the written mesh (the working mesh): it validates on it.
  ASSERT_EQ(test::run_command(test::cli_path() + " validate --mesh " + dir + "/out/param.obj" +
                                  " --layout " + dir + "/out/layout.json",
                              &log),
            0)
      << log;
}

TEST(WorkingMeshCli, TwoNodesAtOnePointAreRefusedWithTheirIds) {
  const std::string dir = test::temp_dir("working_mesh_cli_bad");
  const std::string layout = point_layout(dir);
  auto doc = read_json(layout);
  doc["nodes"][1]["point"] = doc["nodes"][0]["point"];
  std::ofstream(dir + "/bad.layout.json") << doc.dump();
  std::string log;
  const int rc =
      test::run_command(test::cli_path() + " validate --mesh " + test::assets_dir() +
                            "/example/ellipsoid.obj --layout " + dir + "/bad.layout.json",
                        &log);
  EXPECT_NE(rc, 0);
  EXPECT_NE(log.find("bad.layout.json"), std::string::npos) << log;
  const std::string id0 = "node " + doc["nodes"][0]["id"].dump();
  const std::string id1 = "node " + doc["nodes"][1]["id"].dump();
  EXPECT_NE(log.find(id0), std::string::npos) << log;
  EXPECT_NE(log.find(id1), std::string::npos) << log;
}

}  // namespace
}  // namespace qs
