#include "app/gui/document.h"

#include <algorithm>
#include <exception>

#include "core/layout/layout_io.h"

namespace qs::app {

std::string Document::open_mesh(const std::string& path) {
  try {
    MeshReport report_out;
    auto loaded = std::make_shared<const TriMesh>(load_mesh(path, &report_out));
    mesh = std::move(loaded);
    report = std::move(report_out);
    mesh_path = path;
    layout_path.clear();
    ++mesh_version;
    editor.reset(mesh.get(), Layout{});
    dirty = false;
    validated_layout_version = ~0ull;
    return {};
  } catch (const std::exception& e) {
    return std::string("Cannot open mesh ") + path + ":\n" + e.what();
  }
}

std::string Document::open_layout(const std::string& path) {
  if (!mesh) return "Open a mesh before opening a layout (" + path + ")";
  try {
    Layout layout = load_layout(path, *mesh);
    editor.reset(mesh.get(), std::move(layout));
    layout_path = path;
    dirty = false;
    validated_layout_version = ~0ull;
    return {};
  } catch (const std::exception& e) {
    return std::string("Cannot open layout ") + path + ":\n" + e.what();
  }
}

std::string Document::save_layout_to(const std::string& path) {
  const std::string target = path.empty() ? layout_path : path;
  if (target.empty()) return "Choose a file name for the layout";
  try {
    save_layout(editor.layout(), target, mesh.get());
    layout_path = target;
    dirty = false;
    return {};
  } catch (const std::exception& e) {
    return std::string("Cannot save layout ") + target + ":\n" + e.what();
  }
}

bool Document::refresh_validation() {
  if (!mesh || editor.version() == validated_layout_version) return false;
  validated_layout_version = editor.version();
  try {
    validation = validate_layout(*mesh, editor.layout());
  } catch (const std::exception& e) {
    validation = {};
    LayoutIssue issue;
    issue.code = "validation_failed";
    issue.message = std::string("validation failed: ") + e.what();
    validation.issues.push_back(issue);
  }
  return true;
}

void Document::bounds(Vec3& center, double& radius) const {
  center = Vec3(0, 0, 0);
  radius = 1.0;
  if (!mesh || mesh->n_vertices() == 0) return;
  Vec3 lo = mesh->point(*mesh->vertices_begin()), hi = lo;
  for (auto vh : mesh->vertices()) {
    lo.minimize(mesh->point(vh));
    hi.maximize(mesh->point(vh));
  }
  center = 0.5 * (lo + hi);
  radius = std::max(0.5 * (hi - lo).norm(), 1e-9);
}

}  // namespace qs::app
