// Layout JSON (interfaces.md §1): reading with precise errors, writing (atomically).
#pragma once

#include <cstdint>
#include <string>

#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! Largest layout file load_layout reads (256 MiB; far above any layout the pipeline writes).
constexpr std::uintmax_t kMaxLayoutFileBytes = std::uintmax_t{256} << 20;

//! Parses layout JSON text (interfaces.md §1). Structural problems throw InvalidInputError
//! naming the file (\p source_name), the JSON location and the problem, e.g.
//! "layout.json: malformed JSON at line 3, column 7: ..." or
//! "layout.json: arcs[3].path[2]: expected an integer vertex index, got string".
//! Semantic problems (unknown or duplicate ids, broken paths, indices past the mesh) are left
//! to validate_layout; the values are stored as given.
//!
//! Rules:
//! - A leading UTF-8 byte-order mark is skipped.
//! - "format": "quadsketch-layout" and "version": 1 are required; "nodes" and "arcs" are
//!   required arrays; "mesh", "features", "patches" are optional; unknown fields are ignored.
//! - Ids, node/face/vertex indices and counts are integers >= 0 (integral numbers like 17.0
//!   are accepted); coordinates are finite numbers.
//! - A node needs "vertex" or "point". Both are stored when both are given (as written for
//!   snapped and output nodes); load_layout requires the point to snap to that vertex. A node
//!   with only "point" has vertex = -1 until load_layout snaps it.
//! - An arc needs "from", "to" (an id, or null for a dangling arc: to = -1) and exactly one of
//!   "path" (vertex indices) or "points" (at least one surface point).
//! - Output fields (node position/point/valence, arc label "u"|"v"/polyline/samples, patches
//!   with optional size) are read too, so that parse(layout_to_json(x)) == x.
//! \throw InvalidInputError as above.
Layout parse_layout_json(const std::string& text, const std::string& source_name = "<layout>");

//! Reads and parses a layout file (parse_layout_json), without resolving it on a mesh.
//! Only a regular file of at most kMaxLayoutFileBytes is read (read_input_file).
//! \throw InvalidInputError (message starts with \p path) as load_layout.
Layout read_layout_file(const std::string& path);

//! The checks of load_layout on \p mesh: the "mesh" block, node vertices in range, every surface
//! point (node points, arc points, samples), and a node's vertex and point that disagree. With
//! \p snap_points, a node with only a point gets the vertex it snaps to (snap_to_vertex).
//! \throw InvalidInputError (message starts with \p path) listing every problem with its id.
void check_layout_on_mesh(const std::string& path, Layout& layout, const TriMesh& mesh,
                          bool snap_points);

//! What load_layout does after reading: check_layout_on_mesh with snapping, then route_layout,
//! on \p layout read from \p path (named in errors). \throw InvalidInputError as load_layout.
void resolve_layout(const std::string& path, Layout& layout, const TriMesh& mesh);

//! Reads a layout file and resolves it on \p mesh: checks the optional "mesh" block (vertex
//! and face counts must match), node vertices (in range), every surface point (node points,
//! arc points and samples: face in range, finite barycentrics >= -1e-9 summing to 1 within
//! 1e-6), snaps node `point`s without a `vertex` (snap_to_vertex), refuses nodes whose `point`
//! snaps to another vertex than their `vertex`, then routes arcs given by
//! `points` (route_layout). Vertex indices inside paths and feature edges are not checked
//! here (validate_layout reports them with their ids).
//! Only a regular file of at most kMaxLayoutFileBytes is read (read_input_file).
//! \throw InvalidInputError (message starts with \p path) on unreadable/malformed files
//!        (missing, a directory, FIFO or device, larger than the limit, not JSON), a
//!        "mesh" block that does not match, bad node vertices or points, or a vertex and a point
//!        that disagree (all listed, with node and arc ids), or arcs that cannot be routed.
Layout load_layout(const std::string& path, const TriMesh& mesh);

//! Serializes a layout as pretty JSON with a stable key order (format, version, mesh, nodes,
//! arcs, features, patches; one node/arc/patch per line) that parse_layout_json reads back
//! exactly (doubles are printed in shortest round-trip form). "mesh" holds \p mesh's counts,
//! else the layout's counts when known. Nodes are written with "vertex" (when >= 0) and their
//! "point" when they have one; arcs with "path", or with "points" when the path is empty (a
//! routed arc's points are dropped: its path supersedes them). Out-of-range indices are
//! written as they are. \throw QsError if a coordinate is not finite (JSON cannot hold it).
std::string layout_to_json(const Layout& layout, const TriMesh* mesh = nullptr);

//! Writes layout_to_json atomically.
void save_layout(const Layout& layout, const std::string& path, const TriMesh* mesh = nullptr);

}  // namespace qs
