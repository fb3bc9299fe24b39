#pragma once
// Unfolding a strip of triangles into the plane (dissertation IV.3, eq.
// 4.18-4.26, for the weaving panels; V.4 unfolds the edge bands the same
// way): the triangles are laid down one by one in strip order, each
// keeping its three side lengths and going on the far side of the side it
// shares with the one laid before it (the first on the far side of its
// first side from a given point). Where eq. 4.22-4.26 place the new corner
// from the angle at a shared corner and the length of one side, it is placed
// here from the lengths of its two sides to the shared side's corners: the
// same point, without the arccos, whose rounding grows near 0 and 180
// degrees. The unfolding is an isometry of each triangle, so lengths and
// areas are kept; a strip can still overlap itself in the plane when it
// curls (the callers check).

#include <array>
#include <vector>

#include "core/Polygon2.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

using core::Point2;

// `points`: the strip's corners in space. `triangles`: in the order of
// unfolding, each sharing a side (two corners) with the one before it; the
// first's corners but one must be placed already. `flat`: the corners in
// the plane, as many as `points`; `placed`: which of them are (the first
// side's two, on entry); both are completed. `away`: a point of the plane
// the first triangle must not go towards. Throws std::invalid_argument
// when a side to unfold from has zero length.
void unfoldStrip(const std::vector<Point3>& points, const std::vector<std::array<int, 3>>& triangles,
                 std::vector<Point2>& flat, std::vector<char>& placed, Point2 away);

}  // namespace rotafab::geometry
