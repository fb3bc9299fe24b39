#include "jobs/Part.h"

#include <fmt/format.h>
#include <clipper.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace rotafab::jobs {
namespace {

constexpr double kClipperUnits = 1e5;  // 1/100000 in

}  // namespace

Polygon2 offsetPolygon(const Polygon2& polygon, double distance) {
  ClipperLib::Path path;
  for (const Point2& p : polygon) {
    path.push_back({static_cast<ClipperLib::cInt>(std::llround(p.x() * kClipperUnits)),
                    static_cast<ClipperLib::cInt>(std::llround(p.y() * kClipperUnits))});
  }
  if (ClipperLib::Area(path) < 0) std::reverse(path.begin(), path.end());
  // Round joins traced to within 1/10000 in.
  ClipperLib::ClipperOffset offset(2.0, 1e-4 * kClipperUnits);
  offset.AddPath(path, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  offset.Execute(out, distance * kClipperUnits);
  if (out.empty()) throw std::invalid_argument(fmt::format("an offset of {} in leaves nothing", distance));
  const auto& largest = *std::max_element(out.begin(), out.end(), [](const auto& a, const auto& b) {
    return std::abs(ClipperLib::Area(a)) < std::abs(ClipperLib::Area(b));
  });
  Polygon2 result;
  for (const auto& p : largest) result.emplace_back(p.X / kClipperUnits, p.Y / kClipperUnits);
  if (polygonArea(result) < 0) std::reverse(result.begin(), result.end());
  return result;
}

Part compensateKerf(const Part& part, double kerf) {
  Part cut = part;
  if (kerf <= 0) return cut;
  cut.outline = offsetPolygon(part.outline, kerf / 2);
  for (size_t h = 0; h < part.holes.size(); ++h) {
    try {
      cut.holes[h] = offsetPolygon(part.holes[h], -kerf / 2);
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument(fmt::format("{}: hole {} is narrower than the kerf ({} in)", part.name, h + 1, kerf));
    }
  }
  for (size_t c = 0; c < part.circles.size(); ++c) {
    cut.circles[c].radius -= kerf / 2;
    // (Less than the sheets' 0.0001 in left is no hole a file can give.)
    if (!(cut.circles[c].radius >= 1e-4)) {
      throw std::invalid_argument(
          fmt::format("{}: hole {} is narrower than the kerf ({} in)", part.name, part.holes.size() + c + 1, kerf));
    }
  }
  return cut;
}

}  // namespace rotafab::jobs
