#include "jobs/nesting/Shapes.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "core/Polygon2.h"
#include "jobs/nesting/ConvexPieces.h"

namespace rotafab::jobs::nesting {
namespace {

// The distance from (x, y) to the polygon's boundary.
double distanceToBoundary(const Path& polygon, double x, double y) {
  double best = std::numeric_limits<double>::max();
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const IntPoint& a = polygon[j];
    const IntPoint& b = polygon[i];
    const double dx = static_cast<double>(b.X - a.X), dy = static_cast<double>(b.Y - a.Y);
    const double length2 = dx * dx + dy * dy;
    double t = length2 > 0 ? ((x - a.X) * dx + (y - a.Y) * dy) / length2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double ex = x - (a.X + t * dx), ey = y - (a.Y + t * dy);
    best = std::min(best, ex * ex + ey * ey);
  }
  return std::sqrt(best);
}

// The points of a (steps + 1) x (steps + 1) grid over the polygon's box that
// lie strictly inside it, with their distance to its boundary.
std::vector<std::pair<IntPoint, double>> gridInside(const Path& polygon, int steps) {
  const auto [minX, minY, maxX, maxY] = boxOf(polygon);
  std::vector<std::pair<IntPoint, double>> inside;
  for (int i = 0; i <= steps; ++i) {
    for (int j = 0; j <= steps; ++j) {
      const IntPoint p{minX + (maxX - minX) * i / steps, minY + (maxY - minY) * j / steps};
      if (ClipperLib::PointInPolygon(p, polygon) != 1) continue;
      inside.emplace_back(p, distanceToBoundary(polygon, static_cast<double>(p.X), static_cast<double>(p.Y)));
    }
  }
  return inside;
}

}  // namespace

std::pair<cInt, std::vector<IntPoint>> clearDiscs(const Path& polygon, cInt radiusStep, int maxDiscs) {
  const auto [minX, minY, maxX, maxY] = boxOf(polygon);
  constexpr int kSteps = 24;
  const auto inside = gridInside(polygon, kSteps);
  IntPoint best{(minX + maxX) / 2, (minY + maxY) / 2};
  double bestDistance = -1;
  for (const auto& [p, d] : inside) {
    if (d > bestDistance) bestDistance = d, best = p;
  }
  auto consider = [&](cInt x, cInt y) {
    if (ClipperLib::PointInPolygon({x, y}, polygon) != 1) return;
    const double d = distanceToBoundary(polygon, static_cast<double>(x), static_cast<double>(y));
    if (d > bestDistance) bestDistance = d, best = {x, y};
  };
  for (double step = std::max(maxX - minX, maxY - minY) / (2.0 * kSteps); step >= 1; step /= 2) {
    const IntPoint at = best;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) consider(at.X + std::llround(dx * step), at.Y + std::llround(dy * step));
    }
  }
  const cInt radius = static_cast<cInt>(std::max(0.0, bestDistance - 1)) / radiusStep * radiusStep;
  if (radius <= 0) return {0, {}};
  std::vector<IntPoint> centres{best};
  while (static_cast<int>(centres.size()) < maxDiscs) {
    double farthest = 0;
    IntPoint next{0, 0};
    for (const auto& [p, d] : inside) {
      if (d < static_cast<double>(radius)) continue;
      double nearest = std::numeric_limits<double>::max();
      for (const IntPoint& c : centres) {
        nearest = std::min(nearest, std::hypot(static_cast<double>(p.X - c.X), static_cast<double>(p.Y - c.Y)));
      }
      if (nearest > farthest) farthest = nearest, next = p;
    }
    if (farthest < static_cast<double>(radius)) break;
    centres.push_back(next);
  }
  return {radius, centres};
}

// The poles of a polygon (see Shape::poles): on a grid of points inside
// it, greedily the one with the largest disc clear of the boundary and of
// the discs so far, while that is at least a tenth of the first's radius.
std::vector<Shape::Pole> polesOf(const Path& polygon, size_t most) {
  // Grid points and the largest disc at each clear of the boundary and of the poles so far.
  auto inside = gridInside(polygon, 32);
  std::vector<Shape::Pole> poles;
  while (poles.size() < most && !inside.empty()) {
    const auto best = std::max_element(inside.begin(), inside.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    if (best->second < 1 || (!poles.empty() && best->second < 0.1 * poles.front().radius)) break;
    const Shape::Pole pole{best->first, best->second};
    poles.push_back(pole);
    for (auto& [p, room] : inside) {
      const double apart =
          std::hypot(static_cast<double>(p.X - pole.centre.X), static_cast<double>(p.Y - pole.centre.Y)) - pole.radius;
      room = std::min(room, apart);
    }
  }
  // Too thin for the grid: one small pole at a point inside, so that
  // containment is still found (failing that, on a vertex: never empty).
  if (poles.empty()) {
    for (size_t i = 0; i < polygon.size() && poles.empty(); ++i) {
      const IntPoint& a = polygon[i];
      const IntPoint& b = polygon[(i + 1) % polygon.size()];
      const IntPoint& c = polygon[(i + 2) % polygon.size()];
      const IntPoint mid{(a.X + b.X + c.X) / 3, (a.Y + b.Y + c.Y) / 3};
      if (ClipperLib::PointInPolygon(mid, polygon) == 1) poles.push_back({mid, 1.0});
    }
  }
  if (poles.empty()) poles.push_back({polygon.front(), 1.0});
  return poles;
}

}  // namespace rotafab::jobs::nesting
