#pragma once
// Plane polygons, as the panels, parts and sheets all use them: a polygon is
// its corners in order, not closed (the first point is not repeated).

#include <Eigen/Core>
#include <vector>

namespace rotafab::core {

using Point2 = Eigen::Vector2d;
using Polygon2 = std::vector<Point2>;

// The z of the cross product: positive when b lies counter-clockwise of a.
inline double cross(const Point2& a, const Point2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Positive when o, a, b turn counter-clockwise (a left turn at a), zero when in line.
inline double turn(const Point2& o, const Point2& a, const Point2& b) { return cross(a - o, b - o); }

// Signed area (positive counter-clockwise).
double signedArea(const Polygon2& polygon);

// The distance from `p` to the segment ab (to a when a == b).
double distanceToSegment(const Point2& p, const Point2& a, const Point2& b);

// The distance from `p` to the nearest side of a closed polygon.
double distanceToOutline(const Polygon2& polygon, const Point2& p);

// Whether `p` is inside a closed polygon (even-odd).
bool insidePolygon(const Polygon2& polygon, const Point2& p);

// Whether segments ab and cd cross at a point inside both (touching and
// collinear overlaps excluded: pieces of a panel meet along shared sides and
// at shared corners).
bool properlyCross(const Point2& a, const Point2& b, const Point2& c, const Point2& d);

// Whether a closed outline crosses itself (two sides that are not neighbours properly cross).
bool crossesItself(const Polygon2& outline);

// Whether two closed outlines cross (a side of one properly crosses a side of the other).
bool outlinesCross(const Polygon2& a, const Polygon2& b);

// The polyline (`closed`: the polygon) with only the corners that the
// Douglas-Peucker rule keeps (Douglas and Peucker 1973, "Algorithms for the
// reduction of the number of points required to represent a digitized line
// or its caricature"): every dropped corner lies within `tolerance` of the
// side that replaces it, and so the two lines are within `tolerance` of
// each other everywhere. The ends of an open line are kept, and a closed
// line keeps at least three corners.
std::vector<Point2> simplifiedLine(const std::vector<Point2>& points, double tolerance, bool closed);

}  // namespace rotafab::core
