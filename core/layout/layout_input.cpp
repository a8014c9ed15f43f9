#include "core/layout/layout_input.h"

#include <memory>
#include <utility>

#include "core/base/errors.h"
#include "core/layout/layout_io.h"

namespace qs {

bool layout_needs_working_mesh(const Layout& layout) {
  for (const LayoutNode& node : layout.nodes) {
    if (node.vertex >= 0 || !node.point) continue;
    int zeros = 0;
    for (double b : node.point->bary) zeros += b == 0;
    if (zeros < 2) return true;
  }
  for (const LayoutArc& arc : layout.arcs)
    if (arc.path.empty() && !arc.points.empty()) return true;
  return false;
}

SurfaceLayout load_layout_on_surface(const std::string& path, TriMesh input,
                                     const EmbedOptions& options) {
  SurfaceLayout out;
  out.input_vertices = static_cast<int>(input.n_vertices());
  out.input_faces = static_cast<int>(input.n_faces());
  Layout layout = read_layout_file(path);
  if (!layout_needs_working_mesh(layout)) {
    resolve_layout(path, layout, input);
    out.mesh = std::move(input);
    out.layout = std::move(layout);
    return out;
  }
  check_layout_on_mesh(path, layout, input, /*snap_points=*/false);
  // A node given by a vertex (and a point that agrees with it) is that vertex.
  for (LayoutNode& node : layout.nodes)
    if (node.vertex >= 0) node.point.reset();
  EmbeddedLayout embedded;
  try {
    embedded = embed_layout(std::make_shared<const TriMesh>(std::move(input)), layout, options);
  } catch (const InvalidInputError& e) {
    throw InvalidInputError(path + ": " + e.what());
  }
  out.mesh = embedded.mesh->mesh();
  out.layout = std::move(embedded.layout);
  for (LayoutNode& node : out.layout.nodes) node.point.reset();
  out.layout.mesh_vertices = -1;
  out.layout.mesh_faces = -1;
  out.on_working_mesh = true;
  out.embed = embedded.stats;
  return out;
}

}  // namespace qs
