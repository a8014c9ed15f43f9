#include "core/import/perturb.h"

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "core/base/errors.h"
#include "core/layout/validate.h"

namespace qs {

namespace {

// Moves node n to one of the vertices options.rings edge rings away (NodeShifter's candidates,
// tried in a random order).
bool move_node(NodeShifter& shifter, int n, const PerturbLayoutOptions& options,
               std::mt19937& rng) {
  std::vector<int> candidates = shifter.ring_candidates(n, options.rings);
  // Fisher–Yates with our own index draws: std::shuffle's use of the engine is not specified,
  // and the same seed must give the same result everywhere.
  for (size_t i = candidates.size(); i > 1; --i) {
    const size_t j = rng() % i;
    std::swap(candidates[i - 1], candidates[j]);
  }
  const int attempts = std::min<int>(options.max_attempts, static_cast<int>(candidates.size()));
  for (int k = 0; k < attempts; ++k) {
    if (shifter.try_move(n, candidates[k])) return true;
  }
  return false;
}

// Moves the unpinned nodes one at a time, in layout order.
PerturbResult perturb_nodes(const TriMesh& mesh, const Layout& input,
                            const PerturbLayoutOptions& options) {
  PerturbResult result;
  NodeShifter shifter(mesh, input);
  std::mt19937 rng(options.seed);
  const Layout& layout = shifter.layout();
  for (size_t n = 0; n < layout.nodes.size(); ++n) {
    const int id = layout.nodes[n].id;
    const std::vector<int>& arcs = shifter.node_arcs(static_cast<int>(n));
    bool pinned = layout.nodes[n].pinned;
    bool loop = false;
    for (int a : arcs) {
      pinned = pinned || layout.arcs[a].pinned;
      loop = loop || (!layout.arcs[a].dangling() && layout.arcs[a].from == layout.arcs[a].to);
    }
    if (pinned) {
      result.pinned_nodes.push_back(id);
    } else if (loop || arcs.empty() || !move_node(shifter, static_cast<int>(n), options, rng)) {
      result.stuck_nodes.push_back(id);
    } else {
      result.moved_nodes.push_back(id);
    }
  }
  result.layout = shifter.take_layout();
  return result;
}

}  // namespace

PerturbResult perturb_layout(const TriMesh& mesh, const Layout& layout,
                             const PerturbLayoutOptions& options) {
  if (options.rings < 1) {
    throw InvalidInputError("rings must be at least 1 (got " + std::to_string(options.rings) + ")");
  }
  const ValidationResult before = validate_layout(mesh, layout);
  if (!before.valid()) {
    std::string msg =
        "cannot perturb an invalid layout (" + std::to_string(before.errors()) + " error(s)):";
    int shown = 0;
    for (const auto& issue : before.issues) {
      if (issue.severity != IssueSeverity::Error) continue;
      if (++shown > 12) break;
      msg += "\n  " + format_issue(issue);
    }
    throw InvalidInputError(msg);
  }
  PerturbResult result = perturb_nodes(mesh, layout, options);
  const ValidationResult after = validate_layout(mesh, result.layout);
  if (!after.valid()) {
    std::string msg = "perturb produced an invalid layout (internal error):";
    for (const auto& issue : after.issues)
      if (issue.severity == IssueSeverity::Error) msg += "\n  " + format_issue(issue);
    throw QsError(msg);
  }
  return result;
}

}  // namespace qs
