// Field hints (GL-free): the natural cross field of the bare mesh (core/field/natural_field.h)
// and its singularities, shown before Run as faint crosses and markers where irregular nodes
// belong. Computed off the UI thread at the solver threads' priority, once per mesh (cached
// while the mesh stays open).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

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
  //! The field of the document's mesh as shown: its singularities at the hint scale (see
  //! set_scale). Null until computed (or when it failed).
  const NaturalField* field() const {
    return shown_ && field_mesh_ == mesh_ ? shown_.get() : nullptr;
  }
  //! The field as computed, with every singularity; null until computed.
  const NaturalField* raw_field() const {
    return field_ && field_mesh_ == mesh_ ? field_.get() : nullptr;
  }
  //! Hint scale, a fraction of the mesh's bounding-box diagonal: singularities of opposite
  //! index closer than that along the surface cancel in field() (cancel_close_pairs), as a
  //! layout with patches of that size places no irregular nodes for them. 0 shows every
  //! singularity. Clamped to [0, kMaxScale]; a not-a-number gives kDefaultScale. The pairing
  //! runs off the UI thread: field() shows the previous scale until it is done.
  void set_scale(double fraction);
  double scale() const { return scale_; }
  static constexpr double kMaxScale = 0.5;
  static constexpr double kDefaultScale = 0.05;
  bool computing() const { return task_.running(); }
  const std::string& error() const { return error_; }
  //! Shown singularities of index +1 (valence 3) and -1 (valence 5), and others.
  int count(int index) const;
  //! Bumped whenever field() changes.
  std::uint64_t version() const { return version_; }

 private:
  std::uint64_t mesh_ = ~0ull;                 //!< mesh version of the document
  std::uint64_t field_mesh_ = ~0ull;           //!< mesh version the cached field belongs to
  std::shared_ptr<const NaturalField> field_;  //!< as computed
  std::shared_ptr<const NaturalField> shown_;  //!< field_ with its singularities at scale_
  double scale_ = kDefaultScale;
  double shown_scale_ = -1.0;  //!< the scale shown_ was made with (-1: none)
  BackgroundTask<std::vector<FieldSingularity>> pairing_;
  std::uint64_t field_generation_ = 0;  //!< bumped whenever field_ is replaced
  std::uint64_t pairing_field_ = 0;     //!< field_generation_ of the latest pairing request
  double pairing_scale_ = -1.0;         //!< its scale
  std::uint64_t pairing_requests_ = 0;
  std::string error_;
  std::uint64_t version_ = 0;
  BackgroundTask<std::shared_ptr<const NaturalField>> task_;
};

}  // namespace qs::app
