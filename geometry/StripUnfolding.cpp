#include "geometry/StripUnfolding.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rotafab::geometry {
namespace {

using core::cross;

// The point at distances `fromP` and `fromQ` from p and q, on the other side
// of the line pq from `away`.
Point2 apex(const Point2& p, const Point2& q, double fromP, double fromQ, const Point2& away) {
  const Point2 base = q - p;
  const double length = base.norm();
  if (!(length > 0)) throw std::invalid_argument("a side of the strip has zero length");
  const Point2 along = base / length, normal(-along.y(), along.x());
  const double x = (fromP * fromP - fromQ * fromQ + length * length) / (2 * length);
  const double h = std::sqrt(std::max(0.0, fromP * fromP - x * x));
  const double side = cross(base, away - p) > 0 ? -1.0 : 1.0;
  return p + x * along + side * h * normal;
}

}  // namespace

void unfoldStrip(const std::vector<Point3>& points, const std::vector<std::array<int, 3>>& triangles,
                 std::vector<Point2>& flat, std::vector<char>& placed, Point2 away) {
  std::array<int, 3> previous{-1, -1, -1};
  for (const std::array<int, 3>& t : triangles) {
    int fresh = -1;
    std::vector<int> shared;
    for (int i : t) {
      if (placed[i]) {
        shared.push_back(i);
      } else {
        fresh = i;
      }
    }
    // The corner of the triangle before that is not on the shared side: the new one goes on the other side.
    if (previous[0] >= 0) {
      for (int i : previous) {
        if (i != shared[0] && i != shared[1]) away = flat[i];
      }
    }
    const int p = shared[0], q = shared[1];
    flat[fresh] = apex(flat[p], flat[q], (points[fresh] - points[p]).norm(), (points[fresh] - points[q]).norm(), away);
    placed[fresh] = 1;
    previous = t;
  }
}

}  // namespace rotafab::geometry
