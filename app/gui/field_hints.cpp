#include "app/gui/field_hints.h"

#include "app/gui/thread_priority.h"
#include "core/mesh/geometry.h"

namespace qs::app {

void FieldHints::poll(const Document& doc, int nice) {
  std::optional<std::shared_ptr<const NaturalField>> result;
  std::string error;
  if (task_.poll(result, error)) {
    field_mesh_ = task_.key();
    field_ = result ? *result : nullptr;
    error_ = error;
    ++version_;
  }
  const std::uint64_t mesh = doc.mesh ? doc.mesh_version : ~0ull;
  if (mesh != mesh_) {
    mesh_ = mesh;
    ++version_;  // field() changes (the cached one belongs to another mesh)
  }
  if (!enabled || !doc.mesh || field_mesh_ == mesh_ || (task_.requested() && task_.key() == mesh_))
    return;
  error_.clear();
  const std::shared_ptr<const TriMesh> shared = doc.mesh;
  task_.start(mesh_, [shared, nice]() -> std::shared_ptr<const NaturalField> {
    lower_solver_thread_priority(nice);
    const GeometryCache geometry = build_geometry(*shared);
    return std::make_shared<const NaturalField>(compute_natural_field(*shared, geometry));
  });
}

int FieldHints::count(int index) const {
  const NaturalField* f = field();
  if (!f) return 0;
  int n = 0;
  for (const auto& s : f->singularities) n += s.index == index;
  return n;
}

}  // namespace qs::app
