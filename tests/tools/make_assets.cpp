// Regenerates the bundled example and the broken layouts in assets/ (run by hand:
// build/tests/qs_make_assets <repo>/assets). The outputs are committed.
#include <filesystem>
#include <fstream>
#include <iostream>

#include "core/import/perturb.h"
#include "core/layout/layout_io.h"
#include "tests/fixtures.h"

using namespace qs;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: qs_make_assets ASSETS_DIR\n";
    return 1;
  }
  const std::filesystem::path dir(argv[1]);
  std::filesystem::create_directories(dir / "example");
  std::filesystem::create_directories(dir / "bad");

  // Default example: an ellipsoid with the cube layout (8 valence-3 nodes, 6 patches), the
  // nodes displaced by 3 edge rings like an imprecise hand sketch, so that optimization
  // visibly pulls them into place. ellipsoid_exact.layout.json has the symmetric corners.
  auto [mesh, layout] = test::cube_sphere(12, Vec3(1.3, 1.0, 0.75));
  layout.mesh_vertices = static_cast<int>(mesh.n_vertices());
  layout.mesh_faces = static_cast<int>(mesh.n_faces());
  test::write_obj(mesh, (dir / "example" / "ellipsoid.obj").string());
  save_layout(layout, (dir / "example" / "ellipsoid_exact.layout.json").string(), &mesh);
  PerturbLayoutOptions perturb;
  perturb.rings = 3;
  perturb.seed = 2026;
  const Layout sketch = perturb_layout(mesh, layout, perturb).layout;
  save_layout(sketch, (dir / "example" / "ellipsoid.layout.json").string(), &mesh);

  // Crossing arcs: two new nodes at the centres of the faces next to arc 0 and an arc between
  // them through the middle vertex of arc 0.
  {
    Layout bad = layout;
    const auto& arc0 = bad.arcs[0];
    const int mid = arc0.path[arc0.path.size() / 2];
    const auto vm = mesh.vertex_handle(mid);
    std::vector<int> across;  // the two neighbours of mid off the arc, on opposite sides
    for (auto h : mesh.voh_range(vm)) {
      const int w = mesh.to_vertex_handle(h).idx();
      if (std::find(arc0.path.begin(), arc0.path.end(), w) != arc0.path.end()) continue;
      across.push_back(w);
    }
    LayoutNode a, b;
    a.id = 100, a.vertex = across.front();
    b.id = 101, b.vertex = across.back();
    bad.nodes.push_back(a);
    bad.nodes.push_back(b);
    LayoutArc c;
    c.id = 100, c.from = 100, c.to = 101, c.path = {a.vertex, mid, b.vertex};
    bad.arcs.push_back(c);
    save_layout(bad, (dir / "bad" / "crossing_arcs.layout.json").string(), &mesh);
  }
  // Five-sided patches: arc 0 split by a valence-2 node.
  {
    Layout bad = layout;
    LayoutArc& arc = bad.arcs[0];
    const size_t half = arc.path.size() / 2;
    LayoutNode mid;
    mid.id = 100, mid.vertex = arc.path[half];
    bad.nodes.push_back(mid);
    LayoutArc second = arc;
    second.id = 100, second.from = 100;
    second.path.assign(arc.path.begin() + half, arc.path.end());
    arc.to = 100;
    arc.path.resize(half + 1);
    bad.arcs.push_back(second);
    save_layout(bad, (dir / "bad" / "five_sided_patch.layout.json").string(), &mesh);
  }
  // Missing node id.
  {
    Layout bad = layout;
    bad.arcs[3].to = 42;
    save_layout(bad, (dir / "bad" / "missing_node.layout.json").string(), &mesh);
  }
  // Malformed JSON: the example cut in the middle.
  {
    const std::string text = layout_to_json(layout, &mesh);
    std::ofstream((dir / "bad" / "malformed.layout.json").string())
        << text.substr(0, text.size() / 3);
  }
  std::cout << "wrote example (" << mesh.n_vertices() << " vertices, " << mesh.n_faces()
            << " faces) and bad layouts to " << dir << "\n";
  return 0;
}
