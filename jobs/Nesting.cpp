#include "jobs/Nesting.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>

#include "core/Polygon2.h"
#include "jobs/RowLayout.h"
#include "jobs/nesting/SequenceSearch.h"
#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs {

using namespace nesting;

int quarterTurns(double degrees) {
  const double quarters = degrees / 90.0;
  if (std::abs(quarters - std::round(quarters)) >= 1e-12) return -1;
  return static_cast<int>(((std::llround(quarters) % 4) + 4) % 4);
}

Point2 rotatedPoint(const Point2& p, double degrees) {
  // Quarter turns exactly, so that 90-degree layouts stay on the grid.
  double c = std::cos(degrees * std::numbers::pi / 180.0), s = std::sin(degrees * std::numbers::pi / 180.0);
  if (const int k = quarterTurns(degrees); k >= 0) {
    static constexpr int kCos[] = {1, 0, -1, 0}, kSin[] = {0, 1, 0, -1};
    c = kCos[k];
    s = kSin[k];
  }
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

std::pair<Point2, Point2> rotatedBox(const Polygon2& outline, double degrees) {
  Point2 low = Point2::Constant(std::numeric_limits<double>::max()), high = -low;
  for (const Point2& p : outline) {
    const Point2 q = rotatedPoint(p, degrees);
    low = low.cwiseMin(q), high = high.cwiseMax(q);
  }
  return {low, high};
}

double polygonArea(const Polygon2& polygon) { return core::signedArea(polygon); }

int sheetsTheAreaNeeds(const std::vector<NestingPart>& parts, const NestingOptions& options) {
  double area = 0;
  for (const NestingPart& part : parts) area += std::abs(polygonArea(part.outline));
  return std::max(1, static_cast<int>(std::ceil(area / (options.width * options.height) - 1e-9)));
}

Polygon2 placedOutline(const NestingPart& part, const PartPlacement& placement) {
  Polygon2 out = rotated(part.outline, placement.rotation);
  for (Point2& p : out) p += Point2(placement.x, placement.y);
  return out;
}

void checkNestingParts(const std::vector<NestingPart>& parts) {
  for (const auto& part : parts) {
    if (part.outline.size() < 3 || std::abs(polygonArea(part.outline)) <= 0) {
      throw std::invalid_argument(fmt::format("{}: the outline is not a polygon with area", part.name));
    }
    if (part.rotations.empty()) throw std::invalid_argument(fmt::format("{}: no allowed rotation", part.name));
  }
}

namespace {

// When the budget runs out in the first layout, the parts it has not
// reached are laid out in rows by their boxes (RowLayout.h, linear in the
// parts) on sheets of their own after its last: a valid layout when the
// budget says, on more sheets, and a note that says so.
NestingResult withTheRestInRows(const std::vector<NestingPart>& parts, const NestingOptions& options,
                                const nesting::FirstLayout& first, nesting::SharedProgress& progress) {
  std::vector<NestingPart> rest;
  for (size_t i = first.placed; i < first.sequence.size(); ++i) rest.push_back(parts[first.sequence[i]]);
  NestingResult inRows = rowLayout(rest, options);
  NestingResult result = first.result;
  for (PartPlacement placement : inRows.placements) {
    placement.part = first.sequence[first.placed + static_cast<size_t>(placement.part)];
    placement.sheet += first.result.sheets;
    result.placements.push_back(placement);
  }
  result.sheets += inRows.sheets;
  result.evaluations = 1;
  result.inRows = static_cast<int>(rest.size());
  const auto cost = nesting::layoutCost(result, parts);
  progress.improved(cost, {"nesting", "first layout", parts.size(), parts.size(), cost.first, cost.second});
  return result;
}

}  // namespace

int anyAngleTurns(size_t parts) {
  // Measured on the bunny's 3,660 panels (the README's first command): 24
  // turns, 88,000 part-turns, a first layout of 4 s and one sheet fewer than
  // quarter turns, and more turns no fewer sheets; the shapes of more part-turns
  // take more memory (48 turns: 816 MB) for nothing.
  constexpr size_t kMostPartTurns = 90'000;
  constexpr size_t kMostTurns = 24;
  if (parts <= nesting::kMostPartsForNoFitPolygons) return 4;
  return static_cast<int>(std::clamp<size_t>(kMostPartTurns / parts / 4 * 4, 4, kMostTurns));
}

NestingResult nest(const std::vector<NestingPart>& given, const NestingOptions& options,
                   const core::WorkContext& context) {
  checkNestingParts(given);
  std::vector<NestingPart> turnedEvenly;
  if (const int turns = anyAngleTurns(given.size()); options.anyAngle && turns > 4) {
    turnedEvenly = given;
    for (NestingPart& part : turnedEvenly) {
      // (A part allowed fewer than the four quarter turns keeps its own.)
      if (part.rotations != std::vector<double>{0.0, 90.0, 180.0, 270.0}) continue;
      part.rotations.clear();
      for (int k = 0; k < turns; ++k) part.rotations.push_back(360.0 * k / turns);
    }
  }
  const std::vector<NestingPart>& parts = turnedEvenly.empty() ? given : turnedEvenly;
  SharedProgress progress(context, std::chrono::steady_clock::now(), options.seconds);
  PartShapes shapes(parts, options, context);
  // Searches side by side, one per thread of the executor unless the options
  // say how many, each on its own course; the best layout wins (on a tie,
  // the lowest seed's). Strict order has nothing to search, nor has the
  // window order on a job too large for the sequence search.
  const bool nothingToSearch =
      options.order == OrderMode::Strict ||
      ((options.order == OrderMode::Window || options.order == OrderMode::Kits) && !shapes.forNoFitPolygons());
  const unsigned searches = nothingToSearch || parts.size() < 2 ? 1u
                            : options.threads > 0               ? static_cast<unsigned>(options.threads)
                                                                : context.executor().concurrency();
  const FirstLayout first = firstLayout(shapes, progress, context);
  NestingResult best;
  if (first.placed < parts.size()) {
    best = withTheRestInRows(parts, options, first, progress);
  } else {
    shapes.buildAll(context);
    std::vector<NestingResult> results(searches);
    context.executor().parallelFor(searches, [&](size_t search) {
      results[search] = searchLayout(shapes, first, static_cast<unsigned>(search), progress, context);
    });
    size_t winner = 0;
    int evaluations = 0;
    for (size_t i = 0; i < results.size(); ++i) {
      evaluations += results[i].evaluations;
      if (layoutCost(results[i], parts) < layoutCost(results[winner], parts)) winner = i;
    }
    best = std::move(results[winner]);
    best.evaluations = evaluations;
    if (nothingToSearch || parts.size() < 2) {
      best.stopped = options.order == OrderMode::Strict || parts.size() < 2 ? "nothing to search" : "too many parts";
    }
  }
  if (best.stopped.empty()) best.stopped = "time budget";
  for (const auto& part : parts) best.partArea += std::abs(polygonArea(part.outline));
  return best;
}

bool inKits(const std::vector<NestingPart>& parts, const NestingResult& result) {
  const int n = static_cast<int>(parts.size()), sheets = result.sheets;
  if (n == 0) return true;
  std::vector<int> lowest(static_cast<size_t>(sheets) + 1, n), highest(static_cast<size_t>(sheets) + 1, -1);
  for (const PartPlacement& placement : result.placements) {
    const int order = parts[placement.part].order, sheet = placement.sheet;
    // Step order + 1, due by its fair share's sheet, one sheet of slack.
    const int share = static_cast<int>((static_cast<long long>(order + 1) * sheets + n - 1) / n);
    if (sheet > share + 1 || (order == 0 && sheet != 1)) return false;
    lowest[static_cast<size_t>(sheet)] = std::min(lowest[static_cast<size_t>(sheet)], order);
    highest[static_cast<size_t>(sheet)] = std::max(highest[static_cast<size_t>(sheet)], order);
  }
  for (int k = 1; k < sheets; ++k) {
    if (highest[static_cast<size_t>(k)] > lowest[static_cast<size_t>(k) + 1]) return false;
  }
  return true;
}

std::string inRowsNote(const NestingResult& result) {
  if (result.inRows <= 0) return "";
  const size_t total = result.placements.size(), nested = total - static_cast<size_t>(result.inRows);
  const int firstInRows = result.placements[nested].sheet;
  const std::string sheets = firstInRows == result.sheets ? fmt::format("sheet {}", firstInRows)
                                                          : fmt::format("sheets {}-{}", firstInRows, result.sheets);
  return nested == 0 ? fmt::format(
                           "the time budget ran out before the first layout began: the {} parts are laid out "
                           "in rows by their boxes, on more sheets; a longer --time nests them",
                           total)
                     : fmt::format(
                           "the time budget ran out in the first layout after {} of {} parts: the other {} are "
                           "laid out in rows by their boxes, on {}; a longer --time nests them all",
                           nested, total, result.inRows, sheets);
}

std::vector<std::string> layoutProblems(const std::vector<NestingPart>& parts, const NestingResult& result,
                                        const NestingOptions& options, double tolerance,
                                        const core::Cancellation* cancellation) {
  std::vector<std::string> problems;
  struct Checked {
    int part;
    Path path;
    Box box;
  };
  std::map<int, std::vector<Checked>> bySheet;
  const double reach = std::max(0.0, (options.spacing - tolerance) / 2);
  for (const auto& placement : result.placements) {
    const Polygon2 outline = placedOutline(parts[placement.part], placement);
    for (const Point2& p : outline) {
      const bool inside = p.x() >= -tolerance && p.y() >= -tolerance && p.y() <= options.height + tolerance &&
                          (options.strip || p.x() <= options.width + tolerance);
      if (!inside) {
        problems.push_back(fmt::format("sheet {}: {} leaves the usable area at ({:.4f}, {:.4f})", placement.sheet,
                                       parts[placement.part].name, p.x(), p.y()));
        break;
      }
    }
    Path path = toPath(outline);
    if (ClipperLib::Area(path) < 0) std::reverse(path.begin(), path.end());
    if (reach > 0) path = grown(path, reach, ClipperLib::jtRound);
    const Box box = boxOf(path);
    bySheet[placement.sheet].push_back({placement.part, std::move(path), box});
  }
  for (const auto& [sheet, shapes] : bySheet) {
    for (size_t a = 0; a < shapes.size(); ++a) {
      if (cancellation) cancellation->check();
      for (size_t b = a + 1; b < shapes.size(); ++b) {
        // Shapes whose boxes are apart have nothing in common.
        const Box &boxA = shapes[a].box, &boxB = shapes[b].box;
        if (boxA[2] <= boxB[0] || boxB[2] <= boxA[0] || boxA[3] <= boxB[1] || boxB[3] <= boxA[1]) continue;
        ClipperLib::Clipper clipper;
        clipper.AddPath(shapes[a].path, ClipperLib::ptSubject, true);
        clipper.AddPath(shapes[b].path, ClipperLib::ptClip, true);
        Paths common;
        clipper.Execute(ClipperLib::ctIntersection, common, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
        double area = 0;
        for (const Path& p : common) area += std::abs(ClipperLib::Area(p));
        if (area > 1.0) {  // more than 1e-8 square inches
          problems.push_back(fmt::format("sheet {}: {} and {} overlap or are nearer than {} ({:.3g} sq in in common)",
                                         sheet, parts[shapes[a].part].name, parts[shapes[b].part].name, options.spacing,
                                         area / (kScale * kScale)));
        }
      }
    }
  }
  return problems;
}

}  // namespace rotafab::jobs
