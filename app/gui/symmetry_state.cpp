#include "app/gui/symmetry_state.h"

#include <cmath>
#include <cstdio>

namespace qs::app {

namespace {

// \p v for display: 0 when below 1e-9 of \p scale (rounding noise), never "-0".
double shown(double v, double scale) {
  return std::abs(v) < 1e-9 * scale ? 0.0 : v + 0.0;
}

// A normal component rounded to the 3 decimals shown, never "-0.000".
double component(double v) {
  return std::round(v * 1000.0) / 1000.0 + 0.0;
}

}  // namespace

void SymmetryState::enable(SymmetryAxis axis) {
  if (enabled_ && axis_ == axis) return;
  enabled_ = true;
  axis_ = axis;
  ++version_;
}

void SymmetryState::disable() {
  if (!enabled_) return;
  enabled_ = false;
  ++version_;
}

void SymmetryState::poll(const Document& doc) {
  std::optional<Result> result;
  std::string error;
  if (task_.poll(result, error)) {
    have_ = task_.key();
    error_ = error;
    if (result) {
      fit_ = result->fit;
      mirror_ = result->mirror;
    } else {
      fit_.reset();
      mirror_.reset();
    }
    ++version_;
  }
  if (!enabled_ || !doc.mesh) return;
  const std::uint64_t key = doc.mesh_version * 8 + std::uint64_t(axis_);
  if (key == wanted_) return;
  wanted_ = key;
  if (have_ != key) {
    // The old plane belongs to another mesh or axis: plain edits until the new one is ready.
    mirror_.reset();
    fit_.reset();
    error_.clear();
    ++version_;
  }
  const std::shared_ptr<const TriMesh> mesh = doc.mesh;
  const SymmetryAxis axis = axis_;
  task_.start(key, [mesh, axis] {
    auto tree = std::make_shared<const ClosestPointTree>(*mesh);
    Result r;
    r.fit = mirror_plane(*mesh, *tree, axis);
    r.mirror = make_mirror(*mesh, r.fit.plane, tree);
    return r;
  });
}

std::string SymmetryState::description() const {
  if (!enabled_) return {};
  if (!error_.empty()) return "no mirror plane: " + error_;
  if (!fit_) return axis_ == SymmetryAxis::Auto ? "fitting the mirror plane..." : "preparing...";
  const MirrorPlane& p = fit_->plane;
  const double h = mirror_ ? mirror_->snap : 1.0;  // the mean edge length
  char text[160];
  if (axis_ == SymmetryAxis::Auto)
    std::snprintf(text, sizeof(text),
                  "n = (%.3f, %.3f, %.3f), offset %.4g; residual %.2g of the diagonal",
                  component(p.normal[0]), component(p.normal[1]), component(p.normal[2]),
                  shown(p.offset, h), fit_->relative);
  else
    std::snprintf(text, sizeof(text), "%s = %.4g; residual %.2g of the diagonal", to_string(axis_),
                  shown(p.offset, h), fit_->relative);
  return text;
}

}  // namespace qs::app
