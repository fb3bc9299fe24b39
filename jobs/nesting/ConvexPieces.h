#pragma once
// Convex pieces of a simple polygon, and the Minkowski sum of two convex
// polygons, on Clipper's integer grid. The nester builds no-fit polygons from
// them: the no-fit polygon of two concave shapes is the union of the sums of
// their convex pieces, and each such sum takes time linear in the pieces'
// sizes, where Clipper's MinkowskiSum unions one quadrilateral per pair of
// edges (200 star panels took minutes that way).

#include <clipper.hpp>

#include <optional>
#include <vector>

namespace rotafab::jobs::nesting {

// Convex polygons (counter-clockwise, no three consecutive points collinear)
// whose union is `polygon` and whose interiors are disjoint: ear-clipping
// triangulation, then Hertel-Mehlhorn merging of triangles across diagonals
// while the merged piece stays convex (at most four times the optimal count).
// `polygon` must be simple; either orientation. Returns nothing when it is not
// (no ear can be found), so that the caller can fall back to a general method.
std::optional<std::vector<ClipperLib::Path>> convexPieces(const ClipperLib::Path& polygon);

// The Minkowski sum of two convex counter-clockwise polygons: their edges
// merged by angle, in time linear in their sizes. Counter-clockwise.
ClipperLib::Path convexMinkowskiSum(const ClipperLib::Path& a, const ClipperLib::Path& b);

}  // namespace rotafab::jobs::nesting
