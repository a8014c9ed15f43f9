// Symmetric node optimization (docs/design.md, "Symmetric optimization"): the mirror pairs of a
// layout's nodes about a plane, the node optimizer's step targets made mirror images of each
// other (pairs) or points of the plane (nodes on the plane), and the measure of how symmetric a
// layout's node positions are.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/layout/layout.h"
#include "core/layout/symmetry.h"
#include "core/mesh/closest_point.h"
#include "core/mesh/mesh.h"
#include "core/mesh/surface_point.h"
#include "core/nodeopt/geodesic.h"
#include "core/nodeopt/optimizer.h"

namespace qs {

//! What the node optimizer keeps symmetric (NodeOptOptions::Moves::symmetry).
struct NodeSymmetry {
  MirrorPlane plane;
  //! Per layout node index: the index of its mirror node (itself for a node on the plane).
  //! Size #nodes, every entry >= 0 and mutual (SymmetryPairs::node_mirror of a symmetric
  //! layout).
  std::vector<int> node_mirror;
};

//! The symmetry of \p layout on \p mesh about \p plane: its node pairs (find_mirror_pairs,
//! which also pairs the arcs). \throw InvalidInputError from find_mirror_pairs, naming the first
//! node (else arc) without a mirror, when the layout is not symmetric.
std::shared_ptr<const NodeSymmetry> make_node_symmetry(const TriMesh& mesh, const Layout& layout,
                                                       const MirrorPlane& plane,
                                                       const SymmetryPairOptions& options = {});

//! \p options with what moves single nodes turned off when options.moves.symmetry is set: the
//! hop polish (polish.enabled, with its cone sweep before the descent), sliding along curves
//! (moves.slide_on_curves: nodes on the boundary or a feature curve stay) and the separation of
//! crowded nodes (moves.separate_crowded_nodes). Unchanged without symmetry.
NodeOptOptions symmetric_node_options(const NodeOptOptions& options);

//! A node's target in one symmetric descent step.
struct SymmetricTarget {
  bool moves = false;  //!< the node goes to `point` in this step
  SurfacePoint point;  //!< on the optimizer's original mesh
  Vec3 position{0, 0, 0};
};

//! The step of a node to its symmetric target as a geodesic trace's end (the node optimizer
//! carries a node to its trace's end); nullopt when the node does not move.
std::optional<GeodesicTrace> symmetric_trace(const SymmetricTarget& target);

//! The symmetric steps of one node optimization: the closest-point tree of its original mesh
//! and the symmetry.
class SymmetricStepper {
 public:
  //! \p original: the optimizer's original mesh (positions every relocation lies on; kept by
  //! reference, it must outlive the stepper), \p layout its layout. \throw InvalidInputError when
  //! symmetry.node_mirror does not have one mutual entry per node of \p layout.
  SymmetricStepper(const TriMesh& original, const Layout& layout,
                   std::shared_ptr<const NodeSymmetry> symmetry);

  //! The targets of one descent step, per layout node index. \p anchors: per node, its current
  //! surface point on the original mesh; \p movable: the indices of the nodes that may move;
  //! \p propose(i): the step's own target for movable[i] (nullopt: it does not move by itself).
  //! The proposals (the anchor for the other nodes) go through symmetrize_targets with the
  //! nodes that may not move fixed; a node moves when its target is not its anchor (beyond
  //! rounding), also when only its mirror proposed a step (the pair's midpoint moves both) or
  //! when the start was only nearly symmetric. No node moves when none proposes a step and the
  //! anchors are symmetric.
  std::vector<SymmetricTarget> targets(
      const std::vector<SurfacePoint>& anchors, const std::vector<int>& movable,
      const std::function<std::optional<SurfacePoint>(std::size_t)>& propose) const;

  //! After a trial (\p after_mesh, \p after: the state \p before_mesh, \p before with the nodes
  //! whose `moves` is set carried towards their targets as far as the relocation allowed): the
  //! pairs whose two nodes did not end as mirror images (one reached its target, the other did
  //! not) and the plane nodes that left the plane without reaching their target lose `moves`.
  //! Node positions are their vertices'; both layouts have the nodes of the stepper's layout.
  //! Returns true when a flag changed: the trial must be built again (each call that returns
  //! true clears at least one flag, so a loop of rebuilds ends).
  bool hold_unmatched(const TriMesh& before_mesh, const Layout& before, const TriMesh& after_mesh,
                      const Layout& after, std::vector<SymmetricTarget>& targets) const;

  const NodeSymmetry& symmetry() const { return *symmetry_; }

 private:
  const TriMesh& original_;
  std::shared_ptr<const NodeSymmetry> symmetry_;
  ClosestPointTree tree_;
  double tolerance_;  // positions that agree within this are the same (mesh length units)
};

//! How symmetric the node positions of a layout are.
struct NodeSymmetryMeasure {
  int pairs = 0;        //!< mirror pairs of two different nodes
  int plane_nodes = 0;  //!< nodes that are their own mirror
  //! Largest distance between a pair's first node's reflection and its second node, and largest
  //! distance of a plane node from the plane, as fractions of the bounding-box diagonal.
  double max_pair_error = 0;
  double max_plane_error = 0;
};

//! Measures \p symmetry on the node positions (their vertices) of \p layout on \p mesh.
//! \throw InvalidInputError when node_mirror does not have one entry per node, or a node's
//! vertex is out of range.
NodeSymmetryMeasure measure_node_symmetry(const TriMesh& mesh, const Layout& layout,
                                          const NodeSymmetry& symmetry);

}  // namespace qs
