// Mirrored sketching in the editor (GL-free): whether it is on, the axis (x, y, z through the
// mesh's bounding-box centre, or fitted), and the mirror plane of the open mesh with its
// residual. The plane and its closest-point tree are computed off the UI thread (a fit takes
// seconds on a large mesh); until they are ready, edits are plain.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "app/gui/background_task.h"
#include "app/gui/document.h"
#include "app/gui/sketch_edits.h"

namespace qs::app {

class SymmetryState {
 public:
  //! Mirrored sketching on, about the plane of \p axis.
  void enable(SymmetryAxis axis);
  void disable();
  bool enabled() const { return enabled_; }
  SymmetryAxis axis() const { return axis_; }

  //! Once per frame: starts computing the plane for the document's mesh when it is needed and
  //! picks up a finished one.
  void poll(const Document& doc);
  //! The mirror for the sketch edits: null while off, computing, or without a mesh.
  const Mirror* mirror() const { return enabled_ && mirror_ ? &*mirror_ : nullptr; }
  //! The plane and its residual (while on and ready).
  const std::optional<SymmetryFit>& fit() const { return fit_; }
  bool computing() const { return enabled_ && task_.running(); }
  //! Why the plane could not be computed ("" when it could).
  const std::string& error() const { return error_; }
  //! "x = 0 (residual 1.2e-17 of the diagonal)", "fitting the mirror plane…", or "".
  std::string description() const;
  //! Bumped whenever mirror() changes (the scene redraws the plane).
  std::uint64_t version() const { return version_; }

 private:
  struct Result {
    SymmetryFit fit;
    Mirror mirror;
  };
  bool enabled_ = false;
  SymmetryAxis axis_ = SymmetryAxis::X;
  std::uint64_t wanted_ = ~0ull;  //!< key of the plane wanted (mesh version, axis)
  std::uint64_t have_ = ~0ull;    //!< key of the plane held
  std::optional<Mirror> mirror_;
  std::optional<SymmetryFit> fit_;
  std::string error_;
  std::uint64_t version_ = 0;
  BackgroundTask<Result> task_;
};

}  // namespace qs::app
