// Field hints (GL-free): the natural cross field of the bare mesh (core/field/natural_field.h)
// and its singularities, shown before Run as faint crosses and markers where irregular nodes
// belong. Computed off the UI thread at the solver threads' priority, once per mesh (cached
// while the mesh stays open).
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "app/gui/background_task.h"
#include "app/gui/document.h"
#include "core/field/natural_field.h"

namespace qs::app {

class FieldHints {
 public:
  //! Shown (the View panel's checkbox); the field is computed when first shown for a mesh.
  bool enabled = false;

  //! Once per frame: starts the computation for the document's mesh when shown and not cached,
  //! picks up a finished one. \p nice: the solver threads' nice value (0: unchanged).
  void poll(const Document& doc, int nice);
  //! The field of the document's mesh, null until computed (or when it failed).
  const NaturalField* field() const {
    return field_ && field_mesh_ == mesh_ ? field_.get() : nullptr;
  }
  bool computing() const { return task_.running(); }
  const std::string& error() const { return error_; }
  //! Singularities of index +1 (valence 3) and -1 (valence 5), and others.
  int count(int index) const;
  //! Bumped whenever field() changes.
  std::uint64_t version() const { return version_; }

 private:
  std::uint64_t mesh_ = ~0ull;        //!< mesh version of the document
  std::uint64_t field_mesh_ = ~0ull;  //!< mesh version the cached field belongs to
  std::shared_ptr<const NaturalField> field_;
  std::string error_;
  std::uint64_t version_ = 0;
  BackgroundTask<std::shared_ptr<const NaturalField>> task_;
};

}  // namespace qs::app
