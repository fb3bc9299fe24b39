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

bool boxesApart(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) {
  return atA.X + a.grownMaxX <= atB.X + b.grownMinX || atB.X + b.grownMaxX <= atA.X + a.grownMinX ||
         atA.Y + a.grownMaxY <= atB.Y + b.grownMinY || atB.Y + b.grownMaxY <= atA.Y + a.grownMinY;
}

bool coresColliding(const Shape& sa, IntPoint atA, const Shape& sb, IntPoint atB) {
  // In b's frame; only edges that meet both cores' boxes can cross.
  const IntPoint shift{atA.X - atB.X, atA.Y - atB.Y};
  const Box window{std::max(sa.coreBox[0] + shift.X, sb.coreBox[0]), std::max(sa.coreBox[1] + shift.Y, sb.coreBox[1]),
                   std::min(sa.coreBox[2] + shift.X, sb.coreBox[2]), std::min(sa.coreBox[3] + shift.Y, sb.coreBox[3])};
  if (window[0] >= window[2] || window[1] >= window[3]) return false;
  // Closed: an edge on the window's border (the edge that makes a core's
  // box) still counts.
  const auto meets = [](const Box& box, IntPoint p, IntPoint q) {
    return std::max(p.X, q.X) >= box[0] && std::min(p.X, q.X) <= box[2] && std::max(p.Y, q.Y) >= box[1] &&
           std::min(p.Y, q.Y) <= box[3];
  };
  const auto side = [](IntPoint o, IntPoint p, IntPoint q) {
    const cInt cross = (p.X - o.X) * (q.Y - o.Y) - (p.Y - o.Y) * (q.X - o.X);
    return (cross > 0) - (cross < 0);
  };
  std::array<std::pair<IntPoint, IntPoint>, 64> near;  // b's edges in the window (most shapes: all fit)
  size_t nearCount = 0;
  bool overflow = false;
  const Path& pb = sb.core;
  for (size_t j = 0; j < pb.size(); ++j) {
    const IntPoint& r = pb[j];
    const IntPoint& t = pb[(j + 1) % pb.size()];
    if (!meets(window, r, t)) continue;
    if (nearCount == near.size()) {
      overflow = true;
      break;
    }
    near[nearCount++] = {r, t};
  }
  const Path& pa = sa.core;
  for (size_t i = 0; i < pa.size(); ++i) {
    const IntPoint p{pa[i].X + shift.X, pa[i].Y + shift.Y};
    const IntPoint q{pa[(i + 1) % pa.size()].X + shift.X, pa[(i + 1) % pa.size()].Y + shift.Y};
    if (!meets(window, p, q)) continue;
    const Box edge{std::min(p.X, q.X), std::min(p.Y, q.Y), std::max(p.X, q.X), std::max(p.Y, q.Y)};
    const auto crosses = [&](IntPoint r, IntPoint t) {
      return meets(edge, r, t) && side(p, q, r) * side(p, q, t) < 0 && side(r, t, p) * side(r, t, q) < 0;
    };
    if (!overflow) {
      for (size_t j = 0; j < nearCount; ++j) {
        if (crosses(near[j].first, near[j].second)) return true;
      }
    } else {
      for (size_t j = 0; j < pb.size(); ++j) {
        if (crosses(pb[j], pb[(j + 1) % pb.size()])) return true;
      }
    }
  }
  // No crossing: one may still lie in the other, or their boundaries
  // meet only along shared lines and at vertices (parts pushed against
  // the same side of the strip, or two copies side by side). A point of
  // one strictly inside the other's core then gives it away: a pole's
  // centre, a vertex or the middle of an edge, in the window.
  const auto inWindow = [&](IntPoint c) {
    return c.X >= window[0] && c.X <= window[2] && c.Y >= window[1] && c.Y <= window[3];
  };
  // Points in b's frame: inside b's core, or (shifted back) inside a's.
  const auto inB = [&](IntPoint c) { return inWindow(c) && ClipperLib::PointInPolygon(c, pb) == 1; };
  const auto inA = [&](IntPoint c) {
    return inWindow(c) && ClipperLib::PointInPolygon({c.X - shift.X, c.Y - shift.Y}, pa) == 1;
  };
  // Only poles wider than the slack: their centres are inside their own core.
  for (const Shape::Pole& pole : sa.poles) {
    if (pole.radius > kCollisionSlack + 1 && inB({pole.centre.X + shift.X, pole.centre.Y + shift.Y})) return true;
  }
  for (const Shape::Pole& pole : sb.poles) {
    if (pole.radius > kCollisionSlack + 1 && inA(pole.centre)) return true;
  }
  // Middles rounded in each shape's own frame, so that both ways round test the same points.
  for (size_t i = 0; i < pa.size(); ++i) {
    const IntPoint& p = pa[i];
    const IntPoint& q = pa[(i + 1) % pa.size()];
    if (inB({p.X + shift.X, p.Y + shift.Y}) || inB({(p.X + q.X) / 2 + shift.X, (p.Y + q.Y) / 2 + shift.Y})) return true;
  }
  for (size_t j = 0; j < pb.size(); ++j) {
    const IntPoint& r = pb[j];
    const IntPoint& t = pb[(j + 1) % pb.size()];
    if (inA(r) || inA({(r.X + t.X) / 2, (r.Y + t.Y) / 2})) return true;
  }
  return false;
}

Paths intersectionOf(const Path& a, IntPoint atA, const Path& b, IntPoint atB) {
  ClipperLib::Clipper clipper;
  clipper.AddPath(translatedPath(a, atA), ClipperLib::ptSubject, true);
  clipper.AddPath(translatedPath(b, atB), ClipperLib::ptClip, true);
  Paths out;
  clipper.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  return out;
}

bool coresOverlap(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) {
  for (const Path& path : intersectionOf(a.core, atA, b.core, atB)) {
    if (std::abs(ClipperLib::Area(path)) > 1.0) return true;
  }
  return false;
}

}  // namespace rotafab::jobs::nesting
