#include "bench/Libnest2dBaseline.h"

// libnest2d 5.0 is header-only and configured by macros that its CMake package
// puts on Libnest2D::libnest2d_headeronly. Without LIBNEST2D_THREADING_std its
// parallel loop (__parallel::enumerate) compiles to nothing, every no-fit
// polygon stays empty, and the placer throws "Error while merging geometries!"
// at the second part; without the other two the backend or the optimizer is
// missing. Refuse to build rather than misbehave.
#if !defined(LIBNEST2D_GEOMETRIES_clipper) || !defined(LIBNEST2D_OPTIMIZER_nlopt) || !defined(LIBNEST2D_THREADING_std)
#error "libnest2d needs LIBNEST2D_GEOMETRIES_clipper, LIBNEST2D_OPTIMIZER_nlopt and LIBNEST2D_THREADING_std"
#endif

// boost::geometry (libnest2d's Clipper backend) reaches a Boost 1.74 header that
// announces its own deprecation with a #pragma message in every build.
#ifndef BOOST_ALLOW_DEPRECATED_HEADERS
#define BOOST_ALLOW_DEPRECATED_HEADERS
#endif

#include <libnest2d/common.hpp>

// libnest2d 5.0 predates C++20: there, `Radians != Radians` (in _Item::rotation)
// becomes ambiguous between the reversed Degrees/Radians operator== candidates.
// Exact-match operators, declared before the headers that compare, do what
// C++17 did: compare the angles as doubles.
namespace libnest2d {
inline bool operator==(const Radians& a, const Radians& b) { return double(a) == double(b); }
inline bool operator!=(const Radians& a, const Radians& b) { return !(a == b); }
}  // namespace libnest2d

#include <fmt/format.h>
#include <clipper.hpp>
#include <libnest2d/libnest2d.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <numbers>

namespace rotafab::bench {

namespace {

using ClipperLib::cInt;
using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;
using jobs::Point2;
using jobs::Polygon2;

// libnest2d works on Clipper's integer grid; this is the nester's grid too
// (1/10000 in), which keeps libnest2d's 64-bit products of coordinates (areas,
// no-fit polygon edge sorting) far from overflow. Its MM_IN_COORDS (1e6 per mm)
// only serves its mm() helper.
constexpr double kScale = 1e4;
constexpr double kTolerance = 1e-3;  // inches, as jobs::layoutProblems

// libnest2d's defaults but two. The pile of each sheet is aligned to the
// bottom-left corner, which leaves one remnant (the default centres it). The
// search for a part's place is serial: the parallel one starts a thread per
// starting point and took twice as long on 2 cores (200 stars: 12.8 s against
// 5.8 s) for the same layout. Accuracy 0.3, 0.65 (the default) and 1.0 gave
// the same sheet counts on the benchmark's instances.
constexpr float kAccuracy = 0.65f;
constexpr bool kParallel = false;

cInt toInt(double inches) { return static_cast<cInt>(std::llround(inches * kScale)); }

// Twice the signed area of (a, b, c): exact, coordinates stay far below 2^31.
cInt cross(const IntPoint& a, const IntPoint& b, const IntPoint& c) {
  return (b.X - a.X) * (c.Y - a.Y) - (b.Y - a.Y) * (c.X - a.X);
}

// The convex hull on the integer grid (monotone chain), clockwise and closed
// (first point repeated): the form libnest2d's Clipper backend declares to
// boost::geometry and builds its own rectangles in. Only the growing by half
// the spacing (a Clipper offset) brings other input to that form; without
// spacing, a counter-clockwise part has a negative area and is dropped as
// unpackable, and an unclosed one loses its last edge in the no-fit polygon.
// Collinear points are dropped: a zero-length edge divides by zero in
// libnest2d's edge sort. Empty when the outline has no area.
Path clockwiseHull(const Polygon2& outline) {
  Path points;
  for (const Point2& p : outline) points.push_back({toInt(p.x()), toInt(p.y())});
  std::sort(points.begin(), points.end(),
            [](const IntPoint& a, const IntPoint& b) { return a.X != b.X ? a.X < b.X : a.Y < b.Y; });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return {};
  Path hull(2 * points.size());
  size_t k = 0;
  for (const IntPoint& p : points) {  // lower chain, counter-clockwise
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0) --k;
    hull[k++] = p;
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k);  // counter-clockwise and closed: the last point is the first
  if (hull.size() < 4) return {};
  std::reverse(hull.begin(), hull.end());
  return hull;
}

double normalizedDegrees(double degrees) {
  double d = std::fmod(degrees, 360.0);
  if (d < 0) d += 360.0;
  return d > 360.0 - 1e-9 ? 0.0 : d;
}

bool containsAngle(const std::vector<double>& degrees, double angle) {
  return std::any_of(degrees.begin(), degrees.end(), [&](double d) {
    const double diff = std::abs(normalizedDegrees(d) - normalizedDegrees(angle));
    return std::min(diff, 360.0 - diff) < 1e-6;
  });
}

// The rotations every part allows, in [0, 360): libnest2d's placer takes one
// set for all parts, and this one never turns a part to a forbidden angle.
std::vector<double> commonRotations(const std::vector<jobs::NestingPart>& parts) {
  std::vector<double> common;
  for (double r : parts.front().rotations) {
    if (containsAngle(common, r)) continue;
    const bool everywhere = std::all_of(
        parts.begin(), parts.end(), [&](const jobs::NestingPart& part) { return containsAngle(part.rotations, r); });
    if (everywhere) common.push_back(normalizedDegrees(r));
  }
  return common;
}

double intersectionArea(const Path& a, const Path& b) {
  ClipperLib::Clipper clipper;
  clipper.AddPath(a, ClipperLib::ptSubject, true);
  clipper.AddPath(b, ClipperLib::ptClip, true);
  Paths common;
  clipper.Execute(ClipperLib::ctIntersection, common, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  double area = 0;
  for (const Path& p : common) area += std::abs(ClipperLib::Area(p));
  return area;
}

struct Placed {
  int part = 0;
  Path hull;   // on the sheet, grid units
  Path grown;  // grown by half the spacing (less the tolerance): two must not overlap
  cInt minX = 0, minY = 0, maxX = 0, maxY = 0;
};

// The first problem with libnest2d's layout, or empty: every part on a sheet,
// at an allowed rotation, its hull inside the usable area and keeping the
// spacing from every other hull on the sheet.
std::string layoutProblem(const std::vector<jobs::NestingPart>& parts, const std::vector<Path>& hulls,
                          const std::vector<libnest2d::Item>& items, const std::vector<double>& rotations, int sheets,
                          const jobs::NestingOptions& options) {
  const double reach = std::max(0.0, (options.spacing - kTolerance) / 2);
  std::vector<std::vector<Placed>> bySheet(sheets);
  for (size_t i = 0; i < items.size(); ++i) {
    const libnest2d::Item& item = items[i];
    const jobs::NestingPart& part = parts[i];
    if (item.binId() < 0 || item.binId() >= sheets) {
      // libnest2d drops a part that does not fit an empty sheet unturned.
      return fmt::format("libnest2d left {} off every sheet", part.name);
    }
    const double degrees = double(item.rotation()) * 180.0 / std::numbers::pi;
    auto allowed = std::find_if(rotations.begin(), rotations.end(), [&](double r) {
      const double diff = std::abs(r - normalizedDegrees(degrees));
      return std::min(diff, 360.0 - diff) < 1e-6;
    });
    if (allowed == rotations.end()) return fmt::format("{} is turned by {:.6f} degrees", part.name, degrees);
    // The hull as the nester would place the part: turned about its own origin
    // (exactly, for quarter turns), then moved by libnest2d's translation.
    const Point2 shift(item.translation().X / kScale, item.translation().Y / kScale);
    Placed placed;
    placed.part = static_cast<int>(i);
    for (size_t v = 0; v + 1 < hulls[i].size(); ++v) {  // the closing point is the first
      const Point2 p = jobs::rotatedPoint(Point2(hulls[i][v].X / kScale, hulls[i][v].Y / kScale), *allowed) + shift;
      if (p.x() < -kTolerance || p.y() < -kTolerance || p.x() > options.width + kTolerance ||
          p.y() > options.height + kTolerance) {
        return fmt::format("sheet {}: {} leaves the usable area at ({:.4f}, {:.4f})", item.binId() + 1, part.name,
                           p.x(), p.y());
      }
      placed.hull.push_back({toInt(p.x()), toInt(p.y())});
    }
    if (reach > 0) {
      ClipperLib::ClipperOffset grower;
      grower.AddPath(placed.hull, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
      Paths out;
      grower.Execute(out, reach * kScale);
      placed.grown = out.empty() ? placed.hull : out.front();  // a convex polygon grows into one
    } else {
      placed.grown = placed.hull;
    }
    placed.minX = placed.maxX = placed.grown.front().X;
    placed.minY = placed.maxY = placed.grown.front().Y;
    for (const IntPoint& p : placed.grown) {
      placed.minX = std::min(placed.minX, p.X);
      placed.maxX = std::max(placed.maxX, p.X);
      placed.minY = std::min(placed.minY, p.Y);
      placed.maxY = std::max(placed.maxY, p.Y);
    }
    bySheet[item.binId()].push_back(std::move(placed));
  }
  for (int sheet = 0; sheet < sheets; ++sheet) {
    const std::vector<Placed>& on = bySheet[sheet];
    for (size_t a = 0; a < on.size(); ++a) {
      for (size_t b = a + 1; b < on.size(); ++b) {
        if (on[a].maxX < on[b].minX || on[b].maxX < on[a].minX || on[a].maxY < on[b].minY || on[b].maxY < on[a].minY) {
          continue;  // bounding boxes apart: nothing in common
        }
        if (intersectionArea(on[a].grown, on[b].grown) <= 1.0) continue;  // touching: at most 1e-8 sq in
        const double overlap = intersectionArea(on[a].hull, on[b].hull) / (kScale * kScale);
        return overlap > 1e-8 ? fmt::format("sheet {}: the hulls of {} and {} overlap ({:.3g} sq in)", sheet + 1,
                                            parts[on[a].part].name, parts[on[b].part].name, overlap)
                              : fmt::format("sheet {}: the hulls of {} and {} are nearer than {} in", sheet + 1,
                                            parts[on[a].part].name, parts[on[b].part].name, options.spacing);
      }
    }
  }
  return {};
}

}  // namespace

Libnest2dResult nestWithLibnest2d(const std::vector<jobs::NestingPart>& parts, const jobs::NestingOptions& options) {
  Libnest2dResult result;
  auto fail = [&](std::string problem) {
    result.valid = false;
    result.problem = std::move(problem);
    return result;
  };
  if (options.strip) return fail("libnest2d baseline: strip mode is not supported");
  if (parts.empty()) return result;
  const std::vector<double> rotations = commonRotations(parts);
  if (rotations.empty()) return fail("libnest2d baseline: the parts have no rotation in common");

  const auto start = std::chrono::steady_clock::now();
  std::vector<Path> hulls;
  std::vector<libnest2d::Item> items;
  hulls.reserve(parts.size());
  items.reserve(parts.size());
  for (const jobs::NestingPart& part : parts) {
    hulls.push_back(clockwiseHull(part.outline));
    if (hulls.back().empty()) return fail(fmt::format("{}: the outline is not a polygon with area", part.name));
    items.emplace_back(hulls.back());
  }

  // libnest2d keeps parts apart by growing each by half the distance (rounded
  // up) and keeping the grown parts inside the bin; the bin grows by the same
  // amount so that the parts themselves may reach the edge of the usable area,
  // as in our nester.
  const cInt distance = toInt(options.spacing);
  const cInt half = (distance + 1) / 2;
  const libnest2d::Box bin(libnest2d::Point(-half, -half),
                           libnest2d::Point(toInt(options.width) + half, toInt(options.height) + half));
  libnest2d::NestConfig<libnest2d::NfpPlacer, libnest2d::FirstFitSelection> config;
  config.placer_config.rotations.clear();
  for (double r : rotations) config.placer_config.rotations.emplace_back(r * std::numbers::pi / 180.0);
  config.placer_config.alignment = libnest2d::NfpPlacer::Config::Alignment::BOTTOM_LEFT;
  config.placer_config.accuracy = kAccuracy;
  config.placer_config.parallel = kParallel;
  config.placer_config.explore_holes = false;  // hulls have none

  size_t sheets = 0;
  try {
    sheets = libnest2d::nest<libnest2d::NfpPlacer, libnest2d::FirstFitSelection>(items, bin, distance, config);
  } catch (const std::exception& e) {
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return fail(fmt::format("libnest2d threw: {}", e.what()));
  }
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.sheets = static_cast<int>(sheets);
  result.sheetArea.assign(sheets, 0.0);
  for (size_t i = 0; i < parts.size(); ++i) {  // a part without a sheet is reported by the check
    if (items[i].binId() >= 0 && items[i].binId() < result.sheets) {
      result.sheetArea[items[i].binId()] += std::abs(jobs::polygonArea(parts[i].outline));
    }
  }
  try {  // Clipper throws on coordinates out of its range
    std::string problem = layoutProblem(parts, hulls, items, rotations, result.sheets, options);
    if (!problem.empty()) return fail(std::move(problem));
  } catch (const std::exception& e) {
    return fail(fmt::format("checking libnest2d's layout: {}", e.what()));
  }
  return result;
}

}  // namespace rotafab::bench
