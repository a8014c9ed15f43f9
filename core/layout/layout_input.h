// Reading a layout for the pipeline (docs/design.md, "Working mesh"): a layout that sits on the
// input triangulation (nodes on vertices, arcs as edge paths) is used on the input mesh as it
// is; a layout with nodes at other surface points or arcs given as surface polylines is
// discretized onto a working mesh refined from the input (embed_layout), whose triangulation the
// whole pipeline then uses. The input surface as a point set never changes.
#pragma once

#include <string>

#include "core/layout/embed.h"
#include "core/layout/layout.h"
#include "core/mesh/mesh.h"

namespace qs {

//! A layout and the mesh its indices refer to.
struct SurfaceLayout {
  TriMesh mesh;   //!< the input mesh, or the working mesh's triangulation (on_working_mesh)
  Layout layout;  //!< node vertices and arc paths index `mesh`
  bool on_working_mesh = false;
  int input_vertices = 0;  //!< the input mesh's sizes
  int input_faces = 0;
  EmbedStats embed;  //!< counters of the discretization (zero on the input mesh)
};

//! True when \p layout cannot sit on the input triangulation as given: a node has only a `point`
//! that is not exactly at a mesh vertex (two zero barycentrics), or an arc has `points` and no
//! `path`.
bool layout_needs_working_mesh(const Layout& layout);

//! Reads the layout file \p path (once) for \p input, which it takes over (the result's mesh).
//! When layout_needs_working_mesh is false, the layout is resolved on \p input as load_layout
//! does (points snapped to vertices, arcs routed). Otherwise the
//! layout is checked on \p input (check_layout_on_mesh, no snapping) and discretized onto a new
//! working mesh (embed_layout with \p options): the result's mesh is the working mesh, its nodes
//! are working-mesh vertices (their `point`s dropped: the vertex is at the point, or within the
//! snap distance when another node's vertex is there) and its arcs edge paths.
//! \throw InvalidInputError (message starts with \p path) for an unreadable or malformed file,
//! references outside \p input, or a layout that cannot be embedded (listing the nodes and
//! arcs involved).
SurfaceLayout load_layout_on_surface(const std::string& path, TriMesh input,
                                     const EmbedOptions& options = {});

}  // namespace qs
