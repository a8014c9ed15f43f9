#include "app/gui/field_hints.h"

#include <algorithm>
#include <cmath>

#include "app/gui/thread_priority.h"
#include "core/mesh/geometry.h"

namespace qs::app {

void FieldHints::poll(const Document& doc, int nice) {
  std::optional<std::shared_ptr<const NaturalField>> result;
  std::string error;
  if (task_.poll(result, error)) {
    field_mesh_ = task_.key();
    field_ = result ? *result : nullptr;
    ++field_generation_;
    shown_.reset();
    error_ = error;
    ++version_;
  }
  const std::uint64_t mesh = doc.mesh ? doc.mesh_version : ~0ull;
  if (mesh != mesh_) {
    mesh_ = mesh;
    ++version_;  // field() changes (the cached one belongs to another mesh)
  }
  // The singularities at the hint scale, also off the UI thread (one Dijkstra ball of the
  // scale per singularity: up to a second on a large mesh at a large scale).
  std::optional<std::vector<FieldSingularity>> paired;
  std::string pairing_error;
  if (pairing_.poll(paired, pairing_error) && pairing_field_ == field_generation_) {
    auto shown = std::make_shared<NaturalField>(*field_);
    if (paired) shown->singularities = std::move(*paired);  // else: all of them
    shown_ = std::move(shown);
    shown_scale_ = pairing_scale_;
    ++version_;
  }
  const bool pairing_current =
      pairing_.requested() && pairing_field_ == field_generation_ && pairing_scale_ == scale_;
  if (field_ && field_mesh_ == mesh_ && doc.mesh && (!shown_ || shown_scale_ != scale_) &&
      !pairing_current) {
    pairing_field_ = field_generation_;
    pairing_scale_ = scale_;
    const std::shared_ptr<const TriMesh> mesh = doc.mesh;
    const std::shared_ptr<const NaturalField> field = field_;
    const double radius = scale_ * field->bbox_diagonal;
    pairing_.start(++pairing_requests_, [mesh, field, radius] {
      return cancel_close_pairs(*mesh, field->singularities, radius);
    });
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

void FieldHints::set_scale(double fraction) {
  scale_ = std::isfinite(fraction) ? std::clamp(fraction, 0.0, kMaxScale) : kDefaultScale;
}

int FieldHints::count(int index) const {
  const NaturalField* f = field();
  if (!f) return 0;
  int n = 0;
  for (const auto& s : f->singularities) n += s.index == index;
  return n;
}

}  // namespace qs::app
