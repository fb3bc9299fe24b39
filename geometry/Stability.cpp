#include "geometry/Stability.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rotafab::geometry {
namespace {

using Ground = Eigen::Vector2d;  // a point seen from above

struct Frame {
  int up, a, b;  // (a, b, up) is right-handed, so (a, b) turns counter-clockwise seen from above
  explicit Frame(int axis) : up(axis), a((axis + 1) % 3), b((axis + 2) % 3) {}
  [[nodiscard]] Ground ground(const Point3& p) const { return {p[a], p[b]}; }
  [[nodiscard]] Point3 lift(const Ground& g, double height) const {
    Point3 p;
    p[a] = g.x();
    p[b] = g.y();
    p[up] = height;
    return p;
  }
};

using core::turn;

// Andrew's monotone chain: the hull's corners counter-clockwise, no three in line.
std::vector<Ground> convexHull(std::vector<Ground> points) {
  std::sort(points.begin(), points.end(),
            [](const Ground& p, const Ground& q) { return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y()); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;
  std::vector<Ground> hull(2 * points.size());
  size_t k = 0;
  for (const Ground& p : points) {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

// Positive inside the footprint (the distance to its outline), negative
// outside; a footprint of one or two points has no inside.
double signedMargin(const std::vector<Ground>& hull, const Ground& p) {
  bool inside = hull.size() >= 3;
  for (size_t i = 0; i < hull.size() && inside; ++i) inside = turn(hull[i], hull[(i + 1) % hull.size()], p) > 0;
  const double nearest = core::distanceToOutline(hull, p);
  return inside ? nearest : -nearest;
}

// Two points of the structure above its centre of mass from which it hangs
// as it was built. Hung from two strings it turns about the line through
// them until its centre of mass is below that line, and each string pulls
// up only if the centre of mass, seen from above, lies between the two: so
// the pair whose segment, seen from above, passes nearest the centre of mass,
// and of those near the nearest the pair whose lower point is highest above
// it (a steadier hang, and strings that reach it from above), a tenth of
// their distance apart counted to it.
std::vector<Point3> hangPoints(const std::vector<Point3>& points, const Point3& center, const Frame& frame) {
  std::vector<const Point3*> above;
  for (const Point3& p : points) {
    if (p[frame.up] > center[frame.up]) above.push_back(&p);
  }
  if (above.empty()) {  // a flat structure: its highest point, twice
    const Point3& top = *std::max_element(points.begin(), points.end(),
                                          [&](const Point3& p, const Point3& q) { return p[frame.up] < q[frame.up]; });
    return {top, top};
  }
  // Every pair of a few hundred points spread over those above is enough.
  constexpr size_t kMostCandidates = 400;
  if (above.size() > kMostCandidates) {
    std::vector<const Point3*> spread;
    for (size_t i = 0; i < kMostCandidates; ++i) spread.push_back(above[i * above.size() / kMostCandidates]);
    above = std::move(spread);
  }
  const Ground c = frame.ground(center);
  double width = 0;
  for (const Point3* p : above) width = std::max(width, (frame.ground(*p) - c).norm());
  double nearest = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < above.size(); ++i) {
    for (size_t j = i + 1; j < above.size(); ++j) {
      nearest = std::min(nearest, core::distanceToSegment(c, frame.ground(*above[i]), frame.ground(*above[j])));
    }
  }
  const double nearEnough = nearest + 0.01 * width;
  std::pair<const Point3*, const Point3*> best{above.front(), above.front()};
  double bestScore = -std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < above.size(); ++i) {
    for (size_t j = i + 1; j < above.size(); ++j) {
      const Ground p = frame.ground(*above[i]), q = frame.ground(*above[j]);
      if (core::distanceToSegment(c, p, q) > nearEnough) continue;
      const double score = std::min((*above[i])[frame.up], (*above[j])[frame.up]) + 0.1 * (p - q).norm();
      if (score > bestScore) {
        bestScore = score;
        best = {above[i], above[j]};
      }
    }
  }
  return {*best.first, *best.second};
}

}  // namespace

Stability structureStability(const Structure& structure, const StabilityOptions& options) {
  if (options.up < 0 || options.up > 2) throw std::invalid_argument("the up axis must be x, y or z");
  const Frame frame(options.up);
  int holes = 0;
  for (const Panel& panel : structure.panels) {
    holes += static_cast<int>(panel.holes.size());
    for (const PanelPiece& piece : panel.pieces) holes += static_cast<int>(piece.holes.size());
  }
  const double gramsPerHole =
      holes > 0 ? structure.fasteners * options.gramsPerFastener / holes : 0.0;  // each fastener fills two holes
  const bool massKnown = options.gramsPerSquareInch > 0;

  // Each panel's weight sits at its surface's centroid: the area-weighted
  // mean of its fan triangles' centroids.
  double total = 0;
  Point3 moment = Point3::Zero();
  std::vector<Point3> points;
  for (const Panel& panel : structure.panels) {
    double surfaceArea = 0;
    Point3 surfaceMoment = Point3::Zero();
    for (const auto& polygon : panel.surface) {
      for (size_t i = 1; i + 1 < polygon.size(); ++i) {
        const double area = 0.5 * (polygon[i] - polygon[0]).cross(polygon[i + 1] - polygon[0]).norm();
        surfaceArea += area;
        surfaceMoment += area * (polygon[0] + polygon[i] + polygon[i + 1]) / 3;
      }
      points.insert(points.end(), polygon.begin(), polygon.end());
    }
    if (!(surfaceArea > 0)) continue;
    double pieces = 0;
    int panelHoles = static_cast<int>(panel.holes.size());
    for (const PanelPiece& piece : panel.pieces) {
      pieces += piece.area;
      panelHoles += static_cast<int>(piece.holes.size());
    }
    const double weight = massKnown ? (panel.area + pieces) * options.gramsPerSquareInch + panelHoles * gramsPerHole
                                    : panel.area + pieces;
    total += weight;
    moment += weight * surfaceMoment / surfaceArea;
  }
  if (points.empty() || !(total > 0)) throw std::invalid_argument("the structure has no panel surface to weigh");

  Stability result;
  result.centerOfMass = moment / total;
  if (massKnown) result.massKg = total / 1000;

  double lowest = std::numeric_limits<double>::infinity(), highest = -lowest;
  for (const Point3& p : points) {
    lowest = std::min(lowest, p[frame.up]);
    highest = std::max(highest, p[frame.up]);
  }
  const double tolerance = std::max(kGroundToleranceInches, kGroundToleranceShare * (highest - lowest));
  std::vector<Ground> contacts;
  for (const Point3& p : points) {
    if (p[frame.up] <= lowest + tolerance) contacts.push_back(frame.ground(p));
  }
  const std::vector<Ground> hull = convexHull(contacts);
  for (const Ground& g : hull) result.footprint.push_back(frame.lift(g, lowest));
  result.margin = signedMargin(hull, frame.ground(result.centerOfMass));
  result.stands = result.margin > 0;
  if (!result.stands) result.hangPoints = hangPoints(points, result.centerOfMass, frame);
  return result;
}

}  // namespace rotafab::geometry
