// Layout validation: every problem is reported as data, with the ids involved.
#pragma once

#include <string>
#include <vector>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

enum class IssueSeverity { Error, Warning };

struct LayoutIssue {
  IssueSeverity severity = IssueSeverity::Error;
  std::string code;     //!< stable machine-readable kind, e.g. "arc_crossing", "patch_valence"
  std::string message;  //!< human-readable, names the ids
  std::vector<int> node_ids;
  std::vector<int> arc_ids;
  std::vector<int> vertices;     //!< mesh vertices where the problem is (for highlighting)
  std::vector<int> patch_faces;  //!< a face of the offending patch, if any
  //! > 0: this entry is the summary of that many further issues of the same code and severity
  //! that are not listed (validate_layout lists kMaxListedIssuesPerCode per code); its id
  //! lists are empty.
  int omitted = 0;
};

//! validate_layout lists at most this many issues of each code, then one summary entry
//! ("… and K more of the same kind", LayoutIssue::omitted = K), so that a layout with
//! hundreds of thousands of problems is reported in bounded memory.
inline constexpr int kMaxListedIssuesPerCode = 20;

struct ValidationResult {
  std::vector<LayoutIssue> issues;
  bool valid() const;    //!< no Error issue
  int errors() const;    //!< Error issues, a summary entry counting as the issues it stands for
  int warnings() const;  //!< the same for Warning issues
};

//! Checks a layout against a mesh (docs/interfaces.md §1; docs/design.md, "Layout model"): ids,
//! paths, disjointness, dangling ends, patch disks, patch valences, Euler characteristic,
//! connectivity, high-valence warnings. Lists at most kMaxListedIssuesPerCode issues per code
//! (the first ones found), each further one counted in a summary entry at the end.
//! Never throws for bad layouts.
ValidationResult validate_layout(const TriMesh& mesh, const Layout& layout);

//! One line per issue: "error [arc_crossing] arcs 3 and 7 share mesh edge (12, 13)"; a summary
//! entry: "error [arc_crossing] … and 12 more of the same kind".
std::string format_issue(const LayoutIssue& issue);

//! Validates a layout that this library produced (an import, a transfer) and throws
//! InvalidInputError "<what> is not a valid layout (N error(s)):" listing the first 12 errors,
//! one per line; returns quietly when it is valid.
void require_valid_layout(const TriMesh& mesh, const Layout& layout, const std::string& what);

}  // namespace qs
