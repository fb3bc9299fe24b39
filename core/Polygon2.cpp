#include "core/Polygon2.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace rotafab::core {

double signedArea(const Polygon2& polygon) {
  double twice = 0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Point2& a = polygon[i];
    const Point2& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return twice / 2;
}

namespace {

double squaredDistanceToSegment(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double length = ab.squaredNorm();
  const double t = length > 0 ? std::clamp((p - a).dot(ab) / length, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

}  // namespace

double distanceToSegment(const Point2& p, const Point2& a, const Point2& b) {
  return std::sqrt(squaredDistanceToSegment(p, a, b));
}

double distanceToOutline(const Polygon2& polygon, const Point2& p) {
  // One square root for the nearest side, not one per side.
  const size_t n = polygon.size();
  if (n == 0) return std::numeric_limits<double>::max();
  double nearest = std::numeric_limits<double>::max();
  for (size_t i = 0; i < n; ++i) {
    nearest = std::min(nearest, squaredDistanceToSegment(p, polygon[i], polygon[i + 1 < n ? i + 1 : 0]));
  }
  return std::sqrt(nearest);
}

bool insidePolygon(const Polygon2& polygon, const Point2& p) {
  bool in = false;
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Point2& a = polygon[i];
    const Point2& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      in = !in;
    }
  }
  return in;
}

bool properlyCross(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const double d1 = cross(b - a, c - a), d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c), d4 = cross(d - c, b - c);
  const double scale = 1e-12 * std::max((b - a).squaredNorm(), (d - c).squaredNorm());
  return ((d1 > scale && d2 < -scale) || (d1 < -scale && d2 > scale)) &&
         ((d3 > scale && d4 < -scale) || (d3 < -scale && d4 > scale));
}

bool crossesItself(const Polygon2& o) {
  // Each side's extent along x first: most pairs of sides lie apart there,
  // and comparing two numbers is cheaper than four cross products.
  const size_t n = o.size();
  std::vector<std::pair<double, double>> spans(n);
  for (size_t i = 0; i < n; ++i) {
    const double x0 = o[i].x(), x1 = o[(i + 1) % n].x();
    spans[i] = {std::min(x0, x1), std::max(x0, x1)};
  }
  for (size_t a = 0; a < n; ++a) {
    for (size_t b = a + 2; b < n; ++b) {
      if (a == 0 && b + 1 == n) continue;
      if (spans[a].second < spans[b].first || spans[b].second < spans[a].first) continue;
      if (properlyCross(o[a], o[(a + 1) % n], o[b], o[(b + 1) % n])) return true;
    }
  }
  return false;
}

bool outlinesCross(const Polygon2& a, const Polygon2& b) {
  for (size_t i = 0; i < a.size(); ++i) {
    for (size_t j = 0; j < b.size(); ++j) {
      if (properlyCross(a[i], a[(i + 1) % a.size()], b[j], b[(j + 1) % b.size()])) return true;
    }
  }
  return false;
}

std::vector<Point2> simplifiedLine(const std::vector<Point2>& points, double tolerance, bool closed) {
  const size_t n = points.size();
  if (n < (closed ? 4u : 3u)) return points;
  std::vector<char> kept(n, 0);
  // A closed line is split at its first corner and the corner farthest
  // from it; each half is an open line between kept corners.
  size_t far = 0;
  if (closed) {
    for (size_t i = 1; i < n; ++i) {
      if ((points[i] - points[0]).squaredNorm() > (points[far] - points[0]).squaredNorm()) far = i;
    }
  }
  std::vector<std::pair<size_t, size_t>> runs;  // (first, last) of runs to simplify; last may be n: corner 0 again
  kept[0] = 1;
  if (closed && far > 0) {
    kept[far] = 1;
    runs.emplace_back(0, far);
    runs.emplace_back(far, n);
  } else {
    kept[n - 1] = 1;
    runs.emplace_back(0, n - 1);
  }
  while (!runs.empty()) {
    const auto [first, last] = runs.back();
    runs.pop_back();
    const Point2& a = points[first];
    const Point2& b = points[last % n];
    double farthest = -1;
    size_t at = first;
    for (size_t i = first + 1; i < last; ++i) {
      const double d = distanceToSegment(points[i], a, b);
      if (d > farthest) farthest = d, at = i;
    }
    if (farthest > tolerance) {
      kept[at] = 1;
      runs.emplace_back(first, at);
      runs.emplace_back(at, last);
    }
  }
  // Sized exactly: a large job's sheets keep every simplified line at once.
  std::vector<Point2> out;
  out.reserve(static_cast<size_t>(std::count(kept.begin(), kept.end(), 1)));
  for (size_t i = 0; i < n; ++i) {
    if (kept[i]) out.push_back(points[i]);
  }
  // A closed line of two corners has no area: such a line is given back whole.
  if (closed && out.size() < 3) return points;
  return out;
}

}  // namespace rotafab::core
