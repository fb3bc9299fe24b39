#include "geometry/PanelLabels.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "geometry/FastenerHoles.h"

namespace rotafab::geometry {

std::vector<Point2> TextBox::corners() const {
  const Point2 up(-along.y(), along.x());
  return {origin, origin + width * along, origin + width * along + height * up, origin + height * up};
}

double TextBox::distanceTo(const Point2& p) const {
  const Point2 up(-along.y(), along.x());
  const Point2 local((p - origin).dot(along), (p - origin).dot(up));
  const double dx = std::max({0.0, -local.x(), local.x() - width});
  const double dy = std::max({0.0, -local.y(), local.y() - height});
  return std::sqrt(dx * dx + dy * dy);
}

namespace {

// Whether two boxes keep `gap` apart: separated along one of their four
// axes once one is grown by the gap (a little stricter than the true
// distance near the corners, which only costs a smaller label there).
bool boxesApart(const TextBox& a, const TextBox& b, double gap) {
  const auto ca = a.corners(), cb = b.corners();
  for (const TextBox* box : {&a, &b}) {
    for (const Point2& axis : {box->along, Point2(-box->along.y(), box->along.x())}) {
      double aLow = std::numeric_limits<double>::max(), aHigh = -aLow, bLow = aLow, bHigh = -aLow;
      for (const Point2& p : ca) aLow = std::min(aLow, p.dot(axis)), aHigh = std::max(aHigh, p.dot(axis));
      for (const Point2& p : cb) bLow = std::min(bLow, p.dot(axis)), bHigh = std::max(bHigh, p.dot(axis));
      if (aHigh + gap <= bLow || bHigh + gap <= aLow) return true;
    }
  }
  return false;
}

std::optional<TextBox> fitTextAlong(const HersheyFont& font, const std::string& text, double angle,
                                    const std::vector<Point2>& region, const std::vector<Point2>& outline,
                                    const std::vector<Circle>& holes, const std::vector<TextBox>& taken,
                                    const std::vector<Point2>& candidates, double largest) {
  const Point2 along(std::cos(angle), std::sin(angle)), up(-along.y(), along.x());
  // Only the outline's sides within the largest gap of the region can come
  // near a box inside it (and the region lies inside the outline).
  Point2 low = region.front(), high = region.front();
  for (const Point2& p : region) low = low.cwiseMin(p), high = high.cwiseMax(p);
  const double reach = std::max(kLabelGap, kLargestLabel / 4);
  low -= Point2(reach, reach), high += Point2(reach, reach);
  std::vector<std::pair<Point2, Point2>> sides;
  for (size_t i = 0; i < outline.size(); ++i) {
    const Point2& a = outline[i];
    const Point2& b = outline[(i + 1) % outline.size()];
    if (std::max(a.x(), b.x()) < low.x() || std::min(a.x(), b.x()) > high.x() || std::max(a.y(), b.y()) < low.y() ||
        std::min(a.y(), b.y()) > high.y()) {
      continue;
    }
    sides.emplace_back(a, b);
  }
  const auto distanceToSides = [&](const Point2& p) {
    double nearest = std::numeric_limits<double>::max();
    for (const auto& [a, b] : sides) {
      const Point2 ab = b - a;
      const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
      nearest = std::min(nearest, (a + t * ab - p).squaredNorm());
    }
    return std::sqrt(nearest);
  };
  // Each candidate's room, whatever the height: a box centred there needs
  // half its height and the gap (at least a quarter of the height) between
  // its centre and the outline, so no box is taller than the most room / 0.75.
  // Found as needed: once one candidate has room for the largest label, the
  // others' is wanted only if it does not fit there.
  std::vector<double> room(candidates.size(), std::numeric_limits<double>::quiet_NaN());
  const auto roomAt = [&](size_t c) {
    if (std::isnan(room[c])) room[c] = insidePolygon(region, candidates[c]) ? distanceToSides(candidates[c]) : -1.0;
    return room[c];
  };
  double most = 0;
  for (size_t c = 0; c < candidates.size() && most < 0.75 * largest; ++c) most = std::max(most, roomAt(c));
  // Clear of the outline by `gap`: a point near a candidate centre is at
  // least the centre's room less their distance from the sides (the
  // triangle inequality), which spares most points their own distance.
  const auto clear = [&](const Point2& p, double gap, size_t c) {
    return insidePolygon(region, p) &&
           (roomAt(c) - (p - candidates[c]).norm() >= gap + 1e-9 || distanceToSides(p) >= gap);
  };
  // The whole box, its corners inside the region already: inside it (no
  // side of the region across a side of the box) and `gap` or more from
  // every side of the outline near it, exactly (a side's nearest point to
  // a rectangle it does not cross is one of its ends or nearest one of the
  // rectangle's corners).
  const auto insideAndClear = [&](const TextBox& box, double gap) {
    const std::vector<Point2> corners = box.corners();
    for (size_t i = 0; i < region.size(); ++i) {
      const Point2& a = region[i];
      const Point2& b = region[(i + 1) % region.size()];
      for (size_t k = 0; k < 4; ++k) {
        if (core::properlyCross(a, b, corners[k], corners[(k + 1) % 4])) return false;
      }
    }
    for (const auto& [a, b] : sides) {
      if (box.distanceTo(a) < gap || box.distanceTo(b) < gap) return false;
      for (const Point2& corner : corners) {
        if (core::distanceToSegment(corner, a, b) < gap) return false;
      }
      for (size_t k = 0; k < 4; ++k) {
        if (core::properlyCross(a, b, corners[k], corners[(k + 1) % 4])) return false;
      }
    }
    return true;
  };
  // The region's extent along the text and across it: a box longer or
  // taller than that cannot fit anywhere. (Not with the gaps: the gap is
  // kept from the cut outline, and the region's side may be a fold.)
  double alongLow = std::numeric_limits<double>::max(), alongHigh = -alongLow, upLow = alongLow, upHigh = -alongLow;
  for (const Point2& p : region) {
    alongLow = std::min(alongLow, p.dot(along)), alongHigh = std::max(alongHigh, p.dot(along));
    upLow = std::min(upLow, p.dot(up)), upHigh = std::max(upHigh, p.dot(up));
  }
  for (double height = std::min(largest, most / 0.75); height >= kSmallestLabel - 1e-12; height *= 0.85) {
    const double width = font.advance(text, height);
    const double gap = std::max(kLabelGap, height / 4);
    if (width > alongHigh - alongLow || height > upHigh - upLow) continue;
    for (size_t c = 0; c < candidates.size(); ++c) {
      if (roomAt(c) < height / 2 + gap) continue;
      const Point2& centre = candidates[c];
      TextBox box{centre - width / 2 * along - height / 2 * up, angle, width, height, along};
      // The cheap tests first: holes, the corners, then the other labels and the whole box.
      bool fits = true;
      for (size_t i = 0; fits && i < holes.size(); ++i) fits = box.distanceTo(holes[i].centre) >= holes[i].radius + gap;
      for (const Point2& corner : box.corners()) fits = fits && clear(corner, gap, c);
      for (size_t i = 0; fits && i < taken.size(); ++i) fits = boxesApart(box, taken[i], gap);
      if (fits && insideAndClear(box, gap)) return box;
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<TextBox> fitText(const HersheyFont& font, const std::string& text, const std::vector<double>& angles,
                               const std::vector<Point2>& region, const std::vector<Point2>& outline,
                               const std::vector<Circle>& holes, const std::vector<TextBox>& taken,
                               const std::vector<Point2>& candidates, double largest) {
  for (const double angle : angles) {
    if (auto box = fitTextAlong(font, text, angle, region, outline, holes, taken, candidates, largest)) return box;
  }
  return std::nullopt;
}

std::vector<double> alongThenAcross(double angle) { return {angle, angle - std::numbers::pi / 2}; }

std::optional<std::string> unetchedLabelsWarning(const std::vector<std::vector<std::string>>& unfittedOf,
                                                 const std::string& strip, core::LengthUnit unit) {
  std::vector<std::string> unfitted;
  for (const auto& some : unfittedOf) unfitted.insert(unfitted.end(), some.begin(), some.end());
  if (unfitted.empty()) return std::nullopt;
  std::string some;
  for (size_t i = 0; i < unfitted.size() && i < 3; ++i) some += (i ? ", " : "") + unfitted[i];
  return fmt::format("{} label{} not etched, too large for {} {} even at {}: {}{}", unfitted.size(),
                     unfitted.size() == 1 ? " is" : "s are", unfitted.size() == 1 ? "its" : "their", strip,
                     unit(kSmallestLabel, 3), some, unfitted.size() > 3 ? ", ..." : "");
}

}  // namespace rotafab::geometry
