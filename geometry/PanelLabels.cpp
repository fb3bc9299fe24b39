#include "geometry/PanelLabels.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/FastenerHoles.h"

namespace rotafab::geometry {

std::vector<Point2> TextBox::corners() const {
  const Point2 along(std::cos(angle), std::sin(angle)), up(-along.y(), along.x());
  return {origin, origin + width * along, origin + width * along + height * up, origin + height * up};
}

double TextBox::distanceTo(const Point2& p) const {
  const Point2 along(std::cos(angle), std::sin(angle)), up(-along.y(), along.x());
  const Point2 local((p - origin).dot(along), (p - origin).dot(up));
  const double dx = std::max({0.0, -local.x(), local.x() - width});
  const double dy = std::max({0.0, -local.y(), local.y() - height});
  return std::hypot(dx, dy);
}

namespace {

// Points along the box's sides, every `step` or closer.
std::vector<Point2> perimeter(const TextBox& box, double step) {
  const auto corners = box.corners();
  std::vector<Point2> points;
  for (size_t i = 0; i < 4; ++i) {
    const Point2 a = corners[i], b = corners[(i + 1) % 4];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int j = 0; j < n; ++j) points.push_back(a + (b - a) * (static_cast<double>(j) / n));
  }
  return points;
}

bool boxesApart(const TextBox& a, const TextBox& b, double gap) {
  for (const Point2& p : perimeter(a, gap)) {
    if (b.distanceTo(p) < gap) return false;
  }
  for (const Point2& p : perimeter(b, gap)) {
    if (a.distanceTo(p) < gap) return false;
  }
  return true;
}

}  // namespace

std::optional<TextBox> fitText(const HersheyFont& font, const std::string& text, double angle,
                               const std::vector<Point2>& region, const std::vector<Point2>& outline,
                               const std::vector<Circle>& holes, const std::vector<TextBox>& taken,
                               const std::vector<Point2>& candidates) {
  const Point2 along(std::cos(angle), std::sin(angle)), up(-along.y(), along.x());
  // Each candidate's room, whatever the height (worked out when first
  // needed): a box centred there needs half its height and the gap between
  // its centre and the outline.
  std::vector<double> room(candidates.size(), std::numeric_limits<double>::quiet_NaN());
  const auto roomAt = [&](size_t c) {
    if (std::isnan(room[c])) {
      const Point2& centre = candidates[c];
      room[c] = insidePolygon(region, centre) && insidePolygon(outline, centre) ? distanceToOutline(outline, centre)
                                                                                : -1.0;
    }
    return room[c];
  };
  for (double height = kLargestLabel; height >= kSmallestLabel - 1e-12; height *= 0.85) {
    const double width = font.advance(text, height);
    const double gap = std::max(kLabelGap, height / 4);
    for (size_t c = 0; c < candidates.size(); ++c) {
      if (roomAt(c) < height / 2 + gap) continue;
      const Point2& centre = candidates[c];
      TextBox box{centre - width / 2 * along - height / 2 * up, angle, width, height};
      // The cheap tests first: holes, the corners, then the other labels and the whole perimeter.
      const auto clear = [&](const Point2& p) {
        return insidePolygon(region, p) && insidePolygon(outline, p) && distanceToOutline(outline, p) >= gap;
      };
      bool fits = true;
      for (size_t i = 0; fits && i < holes.size(); ++i) fits = box.distanceTo(holes[i].centre) >= holes[i].radius + gap;
      for (const Point2& corner : box.corners()) fits = fits && clear(corner);
      for (size_t i = 0; fits && i < taken.size(); ++i) fits = boxesApart(box, taken[i], gap);
      if (!fits) continue;
      for (const Point2& p : perimeter(box, gap)) {
        if (!clear(p)) {
          fits = false;
          break;
        }
      }
      if (fits) return box;
    }
  }
  return std::nullopt;
}

}  // namespace rotafab::geometry
