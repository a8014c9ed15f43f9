// Triangulation of the polygons of a mesh file, keeping their orientation.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "core/mesh/mesh.h"

namespace qs {

//! Vector area of a polygon (Newell's method): half the sum of the cross products of
//! consecutive corners taken from the first one. Its direction is the polygon's normal (by the
//! right-hand rule over the corner order), its norm the area of a planar polygon (for a
//! non-planar one, the area of its projection onto the plane across that normal).
//! \param face   vertex indices into \p points, in order (at least 3; not checked).
Vec3 polygon_vector_area(std::span<const int> face, const std::vector<Vec3>& points);

//! Splits a polygon into face.size() - 2 triangles (vertex indices, each in the polygon's
//! order) that keep its orientation and tile it: seen along the polygon's normal
//! (polygon_vector_area), every triangle turns the same way as the polygon, and their areas
//! in the polygon's plane sum to the polygon's area.
//! - When fans from a corner qualify (every triangle turns the right way), the fan whose worst
//!   triangle has the largest smallest angle is used (ties: the first such corner).
//! - Otherwise (a concave polygon that no corner sees whole, such as a U) ears are clipped in
//!   the polygon's plane, each time the ear whose triangle has the largest smallest angle
//!   (ties: the lowest corner position in \p face).
//! Coordinates are projected along the normal, so slightly non-planar polygons work too.
//! \return the triangles, or an empty list when there is no such triangulation: a coordinate
//!         is not finite, the vector area is zero, or the outline crosses or touches itself
//!         in the polygon's plane.
std::vector<std::array<int, 3>> triangulate_polygon(std::span<const int> face,
                                                    const std::vector<Vec3>& points);

}  // namespace qs
