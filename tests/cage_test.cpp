// Voxel-cage layouts for meshes without any quad structure (core/import/cage.h), and the tests
// of issues #3 and #4 they make possible on the shared real meshes.
#include "core/import/cage.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <set>

#include "core/base/errors.h"
#include "core/field/cross_field.h"
#include "core/layout/layout_io.h"
#include "core/layout/validate.h"
#include "core/mesh/geometry.h"
#include "core/mesh/mesh_checks.h"
#include "core/mesh/mesh_io.h"
#include "core/pipeline/pipeline.h"
#include "tests/fixtures.h"

namespace qs {
namespace {

using VH = OpenMesh::VertexHandle;

int euler(const TriMesh& m) {
  return static_cast<int>(m.n_vertices()) - static_cast<int>(m.n_edges()) +
         static_cast<int>(m.n_faces());
}

// Number of grid edges at grid point p that lie on the voxel surface, from the occupancy
// alone: an edge is on the surface when the 4 cells around it are neither all occupied nor
// all empty.
int surface_edges_at(const VoxelGrid& g, const std::array<int, 3>& p) {
  int count = 0;
  for (int a = 0; a < 3; ++a) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    for (int dir : {-1, 0}) {  // the edge from p towards -a (cells at a-index p[a]-1) or +a
      int occupied = 0;
      for (int db : {-1, 0}) {
        for (int dc : {-1, 0}) {
          std::array<int, 3> cell = p;
          cell[a] += dir;
          cell[b] += db;
          cell[c] += dc;
          occupied += g.at(cell[0], cell[1], cell[2]);
        }
      }
      count += occupied != 0 && occupied != 4;
    }
  }
  return count;
}

// The cage of a closed mesh: pure quad, manifold, one component of the given genus, every
// vertex valence equal to the number of voxel surface edges at its grid corner.
void expect_cage_matches_voxels(const PolyMesh& cage, const VoxelCageInfo& info, int genus) {
  EXPECT_TRUE(is_pure_quad(cage));
  EXPECT_EQ(info.genus, genus);
  EXPECT_EQ(info.components, 1);
  MeshReport report;
  count_topology(cage, report);
  EXPECT_EQ(report.boundary_loops, 0);
  EXPECT_EQ(report.genus, genus);
  ASSERT_EQ(info.grid_vertex.size(), cage.n_vertices());
  int wrong = 0;
  for (const auto v : cage.vertices()) {
    EXPECT_TRUE(cage.is_manifold(v));
    const int expected = surface_edges_at(info.grid, info.grid_vertex[v.idx()]);
    if (static_cast<int>(cage.valence(v)) != expected && ++wrong < 5) {
      ADD_FAILURE() << "cage vertex " << v.idx() << ": valence " << cage.valence(v)
                    << ", voxel corner has " << expected << " surface edges";
    }
  }
  EXPECT_EQ(wrong, 0);
}

// A layout on a closed mesh: valid, and the node valences satisfy Σ(4 − valence) = 4χ.
void expect_valid_closed_layout(const TriMesh& mesh, const Layout& layout) {
  const ValidationResult validation = validate_layout(mesh, layout);
  EXPECT_TRUE(validation.valid());
  for (const auto& issue : validation.issues) ADD_FAILURE() << format_issue(issue);
  const LayoutTopology topo = build_topology(mesh, layout);
  int sum = 0;
  for (int v : topo.valence) sum += 4 - v;
  EXPECT_EQ(sum, 4 * euler(mesh));
}

TEST(CageLayout, SphereCageIsAVoxelSurfaceAndItsLayoutIsValid) {
  const TriMesh mesh = test::cube_sphere(24).mesh;
  VoxelCageInfo info;
  const PolyMesh cage = voxel_cage(mesh, 6, &info);
  expect_cage_matches_voxels(cage, info, 0);
  EXPECT_GT(cage.n_faces(), 24u);  // rounder than a cube
  // Every cell of a 6-cell sphere voxelization whose centre is well inside is occupied.
  const VoxelGrid& g = info.grid;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        const Vec3 c = g.origin + Vec3(i + 0.5, j + 0.5, k + 0.5) * g.h;
        if (c.norm() < 0.9) {
          EXPECT_TRUE(g.at(i, j, k)) << i << " " << j << " " << k;
        }
        if (c.norm() > 1.1) {
          EXPECT_FALSE(g.at(i, j, k)) << i << " " << j << " " << k;
        }
      }

  CageOptions options;
  options.resolution = 6;
  options.all_edges = true;
  const CageResult result = cage_layout(mesh, options);
  expect_valid_closed_layout(mesh, result.layout);
  // All edges: one node per cage vertex with the cage vertex's valence, one patch per quad.
  const LayoutTopology topo = build_topology(mesh, result.layout);
  ASSERT_EQ(topo.num_nodes, static_cast<int>(result.cage.n_vertices()));
  EXPECT_EQ(topo.patches.size(), result.cage.n_faces());
  for (int n = 0; n < topo.num_nodes; ++n) {
    const int cage_vertex = result.complex.node_vertex[n];
    EXPECT_EQ(topo.valence[n],
              surface_edges_at(result.voxels.grid, result.voxels.grid_vertex[cage_vertex]))
        << "node " << n;
  }
}

TEST(CageLayout, TorusCageHasGenusOneAndABaseComplexLayout) {
  const TriMesh mesh = test::torus_grid(96, 32, 1, 1).mesh;
  CageOptions options;
  options.resolution = 10;
  const CageResult result = cage_layout(mesh, options);
  VoxelCageInfo info;
  const PolyMesh cage = voxel_cage(mesh, result.resolution, &info, result.shift);
  expect_cage_matches_voxels(cage, info, 1);
  expect_valid_closed_layout(mesh, result.layout);
  const LayoutTopology topo = build_topology(mesh, result.layout);
  EXPECT_EQ(static_cast<int>(topo.patches.size()), result.complex.num_patches);
  EXPECT_EQ(topo.num_nodes, static_cast<int>(result.complex.node_vertex.size()));
  // Fitted cage vertices lie on the mesh.
  double worst = 0;
  for (const auto v : result.cage.vertices()) {
    const Vec3 p = result.cage.point(v);
    const double rho = std::hypot(p[0], p[1]) - 2.0;
    worst = std::max(worst, std::abs(std::hypot(rho, p[2]) - 0.7));
  }
  EXPECT_LT(worst, 0.01);  // the triangulated torus deviates from the ideal one by ~0.005
}

TEST(CageLayout, SubsampledCellsAreClassifiedByTheirInsideFraction) {
  // A sphere of radius 1 on cells of 1/3: a cell is occupied exactly when at least half of its
  // 4³ sample points are inside, so cells well inside are occupied and cells well outside
  // empty; the surface is the same kind of manifold voxel surface of genus 0.
  const TriMesh mesh = test::cube_sphere(24).mesh;
  VoxelCageInfo info;
  const PolyMesh cage = voxel_cage(mesh, 6, &info, 0.0, 4);
  expect_cage_matches_voxels(cage, info, 0);
  const VoxelGrid& g = info.grid;
  int inside_fraction_mismatch = 0;
  for (int k = 0; k < g.dims[2]; ++k)
    for (int j = 0; j < g.dims[1]; ++j)
      for (int i = 0; i < g.dims[0]; ++i) {
        // Inside fraction of the cell, sampled like voxel_cage but against the ideal sphere.
        int inside = 0;
        for (int c = 0; c < 64; ++c) {
          const Vec3 q =
              g.origin +
              Vec3(i + (c % 4 + 0.5) / 4, j + (c / 4 % 4 + 0.5) / 4, k + (c / 16 + 0.5) / 4) * g.h;
          inside += q.norm() < 1.0;
        }
        // Cells clearly on one side (away from the 50% boundary, where the triangulated
        // sphere and the ideal one may disagree) must be classified alike.
        if (inside >= 40 && !g.at(i, j, k)) ++inside_fraction_mismatch;
        if (inside <= 24 && g.at(i, j, k)) ++inside_fraction_mismatch;
      }
  EXPECT_EQ(inside_fraction_mismatch, 0);
  EXPECT_EQ(info.flipped_cells, 0);  // no repair flip: the grid is the sampled classification
  try {
    voxel_cage(mesh, 6, nullptr, 0.0, 9);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("subsamples"), std::string::npos) << e.what();
  }
}

TEST(CageLayout, RefinedFittedCageStaysOnTheSurface) {
  const TriMesh mesh = test::torus_grid(96, 32, 1, 1).mesh;
  VoxelCageInfo info;
  PolyMesh cage = voxel_cage(mesh, 10, &info);
  ASSERT_EQ(info.genus, 1);
  fit_cage(cage, mesh);
  const PolyMesh fitted = cage;
  refine_fitted_cage(cage, mesh);
  EXPECT_TRUE(is_pure_quad(cage));
  EXPECT_EQ(cage.n_faces(), 4 * fitted.n_faces());
  MeshReport report;
  count_topology(cage, report);
  EXPECT_EQ(report.genus, 1);
  EXPECT_EQ(report.components, 1);
  // Original vertices keep their positions; new ones lie on the torus (radii 2 and 0.7).
  double moved = 0, worst = 0;
  for (const auto v : cage.vertices()) {
    const Vec3 p = cage.point(v);
    if (static_cast<size_t>(v.idx()) < fitted.n_vertices())
      moved = std::max(moved, (p - fitted.point(v)).norm());
    const double rho = std::hypot(p[0], p[1]) - 2.0;
    worst = std::max(worst, std::abs(std::hypot(rho, p[2]) - 0.7));
  }
  EXPECT_EQ(moved, 0.0);
  EXPECT_LT(worst, 0.01);
  // The base complex keeps its nodes: split vertices are regular.
  EXPECT_EQ(base_complex(cage).node_vertex.size(), base_complex(fitted).node_vertex.size());
}

int irregular_vertices(const PolyMesh& quads) {
  int n = 0;
  for (const auto v : quads.vertices()) n += quads.valence(v) != 4;
  return n;
}

TEST(CageLayout, CancellingIrregularVerticesKeepsAClosedQuadMeshOfTheGenus) {
  const TriMesh mesh = test::torus_grid(96, 32, 1, 1).mesh;
  for (const int rounds : {0, 5}) {
    VoxelCageInfo info;
    const PolyMesh cage = voxel_cage(mesh, 10, &info);
    ASSERT_EQ(info.genus, 1);
    PolyMesh quads = cage;
    QuadSimplifyOptions options;
    options.rounds = rounds;
    options.depth = 2;
    std::vector<int> kept;
    const CageSimplifyStats st = cancel_irregular_vertices(quads, options, nullptr, &kept);
    EXPECT_TRUE(is_pure_quad(quads));
    MeshReport report;
    count_topology(quads, report);
    EXPECT_EQ(report.genus, 1);
    EXPECT_EQ(report.components, 1);
    EXPECT_EQ(report.boundary_loops, 0);
    for (const auto v : quads.vertices()) EXPECT_GE(quads.valence(v), 3u);
    EXPECT_EQ(st.irregular_before, irregular_vertices(cage));
    EXPECT_EQ(st.irregular_after, irregular_vertices(quads));
    EXPECT_LT(st.irregular_after, st.irregular_before) << "rounds " << rounds;
    // A collapse removes one quad and moves one vertex (to a midpoint); a rotation neither.
    EXPECT_EQ(st.quads_after, st.quads_before - st.collapses);
    EXPECT_EQ(static_cast<int>(quads.n_faces()), st.quads_after);
    ASSERT_EQ(kept.size(), quads.n_vertices());
    EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
    int moved = 0;
    for (const auto v : quads.vertices()) moved += quads.point(v) != cage.point(VH(kept[v.idx()]));
    EXPECT_LE(moved, st.collapses);
    std::printf(
        "[stat] torus voxel cage (rounds %d): %d -> %d irregular vertices, %d -> %d quads\n",
        rounds, st.irregular_before, st.irregular_after, st.quads_before, st.quads_after);
  }
}

TEST(CageLayout, CancellingWithNormalsKeepsCornersWithinTheAngleRange) {
  // The voxel cage of a torus: every quad is a square on a cube face. With normals, no face an
  // operation makes may turn against them or have a corner sharper than asin(0.5) = 30°.
  const TriMesh mesh = test::torus_grid(96, 32, 1, 1).mesh;
  VoxelCageInfo info;
  PolyMesh quads = voxel_cage(mesh, 8, &info);
  ASSERT_EQ(info.genus, 1);
  std::vector<Vec3> normals;
  for (const auto v : quads.vertices()) {
    Vec3 n(0, 0, 0);
    for (const auto f : quads.vf_range(v)) n += quads.calc_face_normal(f);
    normals.push_back(n / n.norm());
  }
  const int irregular = irregular_vertices(quads);
  const std::vector<Vec3> positions(quads.points(), quads.points() + quads.n_vertices());
  std::set<std::array<int, 4>> original;
  for (const auto f : quads.faces()) {
    std::array<int, 4> q{};
    int k = 0;
    for (const auto v : quads.fv_range(f)) q[k++] = v.idx();
    std::sort(q.begin(), q.end());
    original.insert(q);
  }
  std::vector<int> kept;
  const CageSimplifyStats st = cancel_irregular_vertices(quads, {}, &normals, &kept);
  EXPECT_EQ(st.irregular_before, irregular);
  EXPECT_LT(st.irregular_after, st.irregular_before);
  // The faces an operation made, on vertices that did not move (rotations; a merged vertex
  // takes a mean normal the test does not know).
  int checked = 0;
  for (const auto f : quads.faces()) {
    std::vector<VH> vs(quads.fv_begin(f), quads.fv_end(f));
    std::array<int, 4> q{};
    bool unmoved = true;
    for (int i = 0; i < 4; ++i) {
      q[i] = kept[vs[i].idx()];
      unmoved = unmoved && quads.point(vs[i]) == positions[q[i]];
    }
    std::sort(q.begin(), q.end());
    if (!unmoved || original.count(q)) continue;
    ++checked;
    for (int i = 0; i < 4; ++i) {
      const Vec3 p = quads.point(vs[i]);
      const Vec3 e1 = quads.point(vs[(i + 1) % 4]) - p, e2 = quads.point(vs[(i + 3) % 4]) - p;
      EXPECT_GT(OpenMesh::dot(OpenMesh::cross(e1, e2), normals[kept[vs[i].idx()]]),
                0.5 * e1.norm() * e2.norm())
          << "face " << f.idx() << " corner " << i;
    }
  }
  EXPECT_GT(checked, 0);  // this cage is simplified by edge rotations
  std::printf(
      "[stat] torus voxel cage with normals: %d -> %d irregular vertices, %d new faces "
      "checked\n",
      st.irregular_before, st.irregular_after, checked);
}

TEST(CageLayout, SimplifiedLayoutHasFewerIrregularNodes) {
  const TriMesh mesh = test::cube_sphere(24).mesh;
  CageOptions options;
  options.resolution = 8;
  options.attempts = 1;
  const CageResult plain = cage_layout(mesh, options);
  options.simplify = true;
  const CageResult simplified = cage_layout(mesh, options);
  ASSERT_TRUE(simplified.simplified) << (simplified.warnings.empty() ? "" : simplified.warnings[0]);
  expect_valid_closed_layout(mesh, simplified.layout);
  auto irregular_nodes = [&](const Layout& layout) {
    const LayoutTopology topo = build_topology(mesh, layout);
    int n = 0;
    for (int v : topo.valence) n += v != 4;
    return n;
  };
  EXPECT_EQ(irregular_nodes(simplified.layout), simplified.simplify.irregular_after);
  EXPECT_LT(irregular_nodes(simplified.layout), irregular_nodes(plain.layout));
  // Nodes are the first vertices of the split coarse mesh, arcs its coarse edges.
  EXPECT_EQ(simplified.complex.num_patches * 16, static_cast<int>(simplified.cage.n_faces()));
  std::printf("[stat] sphere: irregular nodes %d (plain) -> %d (simplified), patches %d -> %d\n",
              irregular_nodes(plain.layout), irregular_nodes(simplified.layout),
              plain.complex.num_patches, simplified.complex.num_patches);
}

TEST(CageLayout, RefusesMeshesWithBoundaryAndWrongResolutions) {
  const TriMesh disk = test::disk_grid(8, 8, 2, 2).mesh;
  EXPECT_THROW(cage_layout(disk), InvalidInputError);
  const TriMesh sphere = test::cube_sphere(8).mesh;
  EXPECT_THROW(voxel_cage(sphere, 1), InvalidInputError);
  try {
    voxel_cage(sphere, 1000);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("resolution"), std::string::npos) << e.what();
  }
  // A torus voxelized far too coarsely loses its hole: a clear error listing the attempts.
  const TriMesh torus = test::torus_grid(48, 16, 1, 1).mesh;
  CageOptions options;
  options.resolution = 2;
  options.attempts = 2;
  try {
    cage_layout(torus, options);
    ADD_FAILURE() << "no error";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("genus"), std::string::npos) << e.what();
  }
}

// Shared real meshes -----------------------------------------------------------------------

struct RealCase {
  const char* file;
  int resolution;
  int attempts;
  double coarsen;
};

CageResult real_layout(const TriMesh& mesh, const RealCase& c) {
  CageOptions options;
  options.resolution = c.resolution;
  options.attempts = c.attempts;
  options.coarsen = c.coarsen;
  return cage_layout(mesh, options);
}

// Issue #3: the field of a cage layout on a higher-genus model has exactly the layout's
// singularities, measured on the field alone.
void check_field_singularities(const RealCase& c, int genus) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent (real-mesh test)";
  const TriMesh mesh = load_mesh(dir + "/" + c.file);
  ASSERT_EQ(euler(mesh), 2 - 2 * genus);
  const CageResult cage = real_layout(mesh, c);
  expect_valid_closed_layout(mesh, cage.layout);
  const GeometryCache geometry = build_geometry(mesh);
  const LayoutTopology topo = build_topology(mesh, cage.layout);
  const CrossField field = compute_cross_field(mesh, geometry, cage.layout, topo);
  const std::vector<int> indices = field_quarter_indices(geometry, field.theta);
  std::vector<int> expected(mesh.n_vertices(), 0);
  int irregular = 0;
  for (int n = 0; n < topo.num_nodes; ++n) {
    expected[cage.layout.nodes[n].vertex] = 4 - topo.valence[n];
    irregular += topo.valence[n] != 4;
  }
  int wrong = 0, spurious = 0;
  for (const auto v : mesh.vertices()) {
    if (indices[v.idx()] == expected[v.idx()]) continue;
    spurious += expected[v.idx()] == 0;
    if (++wrong <= 5)
      ADD_FAILURE() << "vertex " << v.idx() << ": index " << indices[v.idx()] << "/4, expected "
                    << expected[v.idx()] << "/4";
  }
  EXPECT_EQ(wrong, 0) << spurious << " of them away from the nodes";
  EXPECT_EQ(std::accumulate(indices.begin(), indices.end(), 0), 4 * euler(mesh));
  EXPECT_GT(irregular, 0);
  std::printf("[stat] %s: resolution %d, %d nodes (%d irregular), %zu patches\n", c.file,
              cage.resolution, topo.num_nodes, irregular, topo.patches.size());
}

TEST(CageLayout, FieldSingularitiesOn3HolesGenus3) {
  check_field_singularities({"3holes.off", 12, 2, 1.5}, 3);
}

TEST(CageLayout, FieldSingularitiesOnJointGenus2) {
  check_field_singularities({"joint.obj", 12, 2, 1.5}, 2);
}

// Issue #4: E° of the aligned parameterization is lower than that of the --no-align baseline
// with the same layout, with whole constraint clusters (the default) and with split curvature
// clusters (CrossFieldOptions::max_cluster_faces).
void check_alignment_lowers_angle_error(const RealCase& c) {
  const std::string dir = test::shared_meshes_dir();
  if (dir.empty()) GTEST_SKIP() << "../shared/data/meshes is absent (real-mesh test)";
  const TriMesh mesh = load_mesh(dir + "/" + c.file);
  const CageResult cage = real_layout(mesh, c);
  double angle[3] = {0, 0, 0};
  int folds[3] = {0, 0, 0};
  for (int run = 0; run < 3; ++run) {  // --no-align, aligned, aligned with split clusters
    PipelineOptions options;
    options.field.constraints.curvature = run != 0;  // as optimize --no-align
    if (run == 2) options.field.max_cluster_faces = 10;
    Pipeline pipeline(mesh, cage.layout, options);
    pipeline.compute_parameterization();
    const ParamMetrics m = pipeline.metrics();
    EXPECT_TRUE(std::isfinite(m.E));
    angle[run] = m.E_angle_deg;
    folds[run] = m.foldovers;
  }
  std::printf(
      "[stat] %s: E° --no-align %.3f deg (%d fold-overs), aligned %.3f deg (%d), split "
      "clusters %.3f deg (%d)\n",
      c.file, angle[0], folds[0], angle[1], folds[1], angle[2], folds[2]);
  EXPECT_LT(angle[1], angle[0]);
  EXPECT_LT(angle[2], angle[0]);
}

TEST(CageLayout, AlignmentLowersAngleErrorOnRockerArm) {
  check_alignment_lowers_angle_error({"rocker-arm.obj", 15, 2, 1.5});
}

TEST(CageLayout, AlignmentLowersAngleErrorOn3Holes) {
  check_alignment_lowers_angle_error({"3holes.off", 12, 2, 1.5});
}

// The command line: writes a layout that loads and validates; a mesh with a boundary is an
// input error (exit code 2).
TEST(CageLayout, CommandLine) {
  if (!std::filesystem::exists(test::cli_path())) GTEST_SKIP() << "quadsketch-cli not built";
  const std::string dir = test::temp_dir("cage_cli");
  const test::MeshAndLayout sphere = test::cube_sphere(24);
  test::write_obj(sphere.mesh, dir + "/sphere.obj");
  std::string output;
  const int code = test::run_command(test::cli_path() + " cage-layout --mesh " + dir +
                                         "/sphere.obj --resolution 6 --all-edges --out " + dir +
                                         "/sphere.layout.json --cage " + dir + "/cage.obj",
                                     &output);
  ASSERT_EQ(code, 0) << output;
  const TriMesh mesh = load_mesh(dir + "/sphere.obj");
  const Layout layout = load_layout(dir + "/sphere.layout.json", mesh);
  expect_valid_closed_layout(mesh, layout);
  const PolyMesh cage = load_poly_mesh(dir + "/cage.obj");
  EXPECT_EQ(build_topology(mesh, layout).patches.size(), cage.n_faces());

  const test::MeshAndLayout disk = test::disk_grid(6, 6, 2, 2);
  test::write_obj(disk.mesh, dir + "/disk.obj");
  EXPECT_EQ(test::run_command(test::cli_path() + " cage-layout --mesh " + dir + "/disk.obj --out " +
                                  dir + "/disk.layout.json",
                              &output),
            2)
      << output;
  EXPECT_NE(output.find("boundary"), std::string::npos) << output;
}

}  // namespace
}  // namespace qs
