#include "core/pipeline/pipeline.h"

#include <cstdio>
#include <sstream>

#include "core/base/atomic_file.h"
#include "core/base/errors.h"

namespace qs {

Pipeline::Pipeline(TriMesh mesh, Layout layout, PipelineOptions options)
    : mesh_(std::move(mesh)), layout_(std::move(layout)), options_(std::move(options)) {
  validation_ = validate_layout(mesh_, layout_);
  if (!validation_.valid()) {
    std::ostringstream ss;
    ss << "invalid layout: " << validation_.errors() << " error(s)";
    for (const auto& issue : validation_.issues)
      if (issue.severity == IssueSeverity::Error) ss << "\n  " << format_issue(issue);
    throw InvalidInputError(ss.str());
  }
  topology_ = build_topology(mesh_, layout_);
  geometry_ = build_geometry(mesh_);
}

Pipeline::~Pipeline() = default;

const CrossField& Pipeline::compute_field() {
  if (!field_solver_) {
    field_solver_ =
        std::make_unique<CrossFieldSolver>(mesh_, geometry_, layout_, topology_, options_.field);
    return field_solver_->field();
  }
  return field_solver_->solve(geometry_);
}

const CrossField* Pipeline::field() const {
  return field_solver_ ? &field_solver_->field() : nullptr;
}

std::vector<Singularity> Pipeline::singularities() const {
  std::vector<Singularity> out;
  if (!field_solver_) return out;
  const auto idx = field_quarter_indices(geometry_, field_solver_->field().theta);
  for (int v = 0; v < static_cast<int>(idx.size()); ++v)
    if (idx[v] != 0) out.push_back({v, idx[v]});
  return out;
}

void write_field_txt(const GeometryCache& geometry, const std::vector<double>& theta,
                     const std::string& path) {
  write_file_atomic(path, [&](std::ostream& out) {
    char line[96];
    for (int f = 0; f < geometry.n_faces; ++f) {
      const Vec3 d = geometry.direction_in_face(f, theta[f]);
      std::snprintf(line, sizeof line, "%.9g %.9g %.9g\n", d[0], d[1], d[2]);
      out << line;
    }
  });
}

}  // namespace qs
