#include "core/Polygon2.h"

#include <algorithm>
#include <limits>

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

double distanceToSegment(const Point2& p, const Point2& a, const Point2& b) {
  const Point2 ab = b - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double distanceToOutline(const Polygon2& polygon, const Point2& p) {
  double nearest = std::numeric_limits<double>::max();
  for (size_t i = 0; i < polygon.size(); ++i) {
    nearest = std::min(nearest, distanceToSegment(p, polygon[i], polygon[(i + 1) % polygon.size()]));
  }
  return nearest;
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
  for (size_t a = 0; a < o.size(); ++a) {
    for (size_t b = a + 2; b < o.size(); ++b) {
      if (a == 0 && b + 1 == o.size()) continue;
      if (properlyCross(o[a], o[a + 1], o[b], o[(b + 1) % o.size()])) return true;
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

}  // namespace rotafab::core
