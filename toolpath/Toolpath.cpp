#include "toolpath/Toolpath.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/Polygon2.h"

namespace rotafab::jobs {
namespace {

// The stages, in cutting order: etch, score, then the cuts deepest first.
// A cut's depth is how many closed cuts hold it: a part's holes (1) before
// its outline (0); a part nested in another's hole (2) and its holes (3)
// before that hole.
struct Stage {
  int rank;   // 0 etch, 1 score, 2 cuts
  int depth;  // cuts: the negated depth, so that the deepest sorts first
  auto operator<=>(const Stage&) const = default;
};

struct Candidate {
  std::vector<Point2> points;  // a closed path with its first point repeated at the end
  bool closed = false;
};

// Where a path is entered and left when it starts at its point `entry`
// (closed: any corner; open: either end, `entry` 0 or the last).
Point2 exitOf(const Candidate& c, size_t entry) {
  if (c.closed) return c.points[entry];
  return entry == 0 ? c.points.back() : c.points.front();
}

// The corner of `c` nearest `from` (open paths: the nearer end).
size_t nearestEntry(const Candidate& c, const Point2& from) {
  if (!c.closed)
    return (c.points.front() - from).squaredNorm() <= (c.points.back() - from).squaredNorm() ? 0 : c.points.size() - 1;
  size_t best = 0;
  for (size_t i = 0; i + 1 < c.points.size(); ++i) {
    if ((c.points[i] - from).squaredNorm() < (c.points[best] - from).squaredNorm()) best = i;
  }
  return best;
}

// The points of `c` burnt in order when entered at `entry`.
std::vector<Point2> burnOrder(const Candidate& c, size_t entry) {
  std::vector<Point2> out;
  if (!c.closed) {
    out = c.points;
    if (entry != 0) std::reverse(out.begin(), out.end());
    return out;
  }
  const size_t corners = c.points.size() - 1;
  for (size_t k = 0; k <= corners; ++k) out.push_back(c.points[(entry + k) % corners]);
  return out;
}

// Nearest neighbour from `from`, then 2-opt on the travel between the
// strokes (a reversed run turns its open strokes round). Returns the
// strokes' points in burning order; `from` ends where the last one ends.
std::vector<std::vector<Point2>> orderForTravel(const std::vector<Candidate>& candidates, Point2& from) {
  const size_t n = candidates.size();
  std::vector<size_t> order;
  std::vector<size_t> entry(n, 0);
  std::vector<char> done(n, 0);
  // Each path's box: no corner of a path is nearer than its box, so most
  // paths are passed over without looking at their corners.
  std::vector<std::array<double, 4>> boxes;
  for (const Candidate& c : candidates) {
    std::array<double, 4> box{c.points[0].x(), c.points[0].y(), c.points[0].x(), c.points[0].y()};
    for (const Point2& p : c.points) {
      box[0] = std::min(box[0], p.x()), box[1] = std::min(box[1], p.y());
      box[2] = std::max(box[2], p.x()), box[3] = std::max(box[3], p.y());
    }
    boxes.push_back(box);
  }
  // A grid of the boxes, so that each step looks at the paths near the head
  // rather than at every path left: cells about two paths' spacing wide,
  // searched in rings outwards until no nearer path can be further out.
  std::array<double, 4> all = boxes.empty() ? std::array<double, 4>{0, 0, 0, 0} : boxes[0];
  for (const auto& b : boxes) {
    all[0] = std::min(all[0], b[0]), all[1] = std::min(all[1], b[1]);
    all[2] = std::max(all[2], b[2]), all[3] = std::max(all[3], b[3]);
  }
  const double spanX = all[2] - all[0], spanY = all[3] - all[1];
  const double cell = std::max({2 * std::sqrt(spanX * spanY / static_cast<double>(std::max<size_t>(n, 1))),
                                std::max(spanX, spanY) / 1024, 1e-6});
  const int columns = static_cast<int>(spanX / cell) + 1, rows = static_cast<int>(spanY / cell) + 1;
  const auto column = [&](double x) { return std::clamp(static_cast<int>((x - all[0]) / cell), 0, columns - 1); };
  const auto row = [&](double y) { return std::clamp(static_cast<int>((y - all[1]) / cell), 0, rows - 1); };
  std::vector<std::vector<size_t>> cells(static_cast<size_t>(columns) * static_cast<size_t>(rows));
  for (size_t i = 0; i < n; ++i)
    for (int y = row(boxes[i][1]); y <= row(boxes[i][3]); ++y)
      for (int x = column(boxes[i][0]); x <= column(boxes[i][2]); ++x)
        cells[static_cast<size_t>(y) * static_cast<size_t>(columns) + static_cast<size_t>(x)].push_back(i);
  Point2 at = from;
  for (size_t step = 0; step < n; ++step) {
    size_t best = n;
    double bestDistance = std::numeric_limits<double>::max();
    const auto consider = [&](size_t i) {
      const auto& b = boxes[i];
      const double dx = std::max({b[0] - at.x(), 0.0, at.x() - b[2]}),
                   dy = std::max({b[1] - at.y(), 0.0, at.y() - b[3]});
      const double boxDistance = dx * dx + dy * dy;
      if (boxDistance > bestDistance || (boxDistance == bestDistance && i > best)) return;
      const size_t e = nearestEntry(candidates[i], at);
      const double d = (candidates[i].points[e] - at).squaredNorm();
      // (Ties to the lowest index, the order the paths were drawn in.)
      if (d < bestDistance || (d == bestDistance && i < best)) bestDistance = d, best = i, entry[i] = e;
    };
    const int cx = column(at.x()), cy = row(at.y());
    const int reach = std::max({cx, columns - 1 - cx, cy, rows - 1 - cy});
    for (int ring = 0; ring <= reach; ++ring) {
      for (int y = cy - ring; y <= cy + ring; ++y) {
        if (y < 0 || y >= rows) continue;
        const bool edge = y == cy - ring || y == cy + ring;
        for (int x = cx - ring; x <= cx + ring; x += edge ? 1 : 2 * std::max(ring, 1)) {
          if (x < 0 || x >= columns) continue;
          auto& here = cells[static_cast<size_t>(y) * static_cast<size_t>(columns) + static_cast<size_t>(x)];
          // Paths done leave their cells as they are met.
          std::erase_if(here, [&](size_t i) { return done[i] != 0; });
          for (size_t i : here) consider(i);
        }
      }
      // Every cell of the next ring is at least `ring` cells from the head
      // (less a hair, for the rounding of the cells' numbers).
      const double beyond = ring * cell * (1 - 1e-9);
      if (best < n && beyond * beyond > bestDistance) break;
    }
    done[best] = 1;
    order.push_back(best);
    at = exitOf(candidates[best], entry[best]);
  }
  // 2-opt over the open strokes' ends and the closed strokes' entries:
  // reversing order[i..j] also reverses each open stroke in it. A closed
  // stroke is entered and left at the same corner, so only the travel to
  // and from the run changes. Runs of at most kTwoOptReach strokes: after
  // the nearest neighbour, the crossings are local (a sheet of the bunny
  // has 1,500 label strokes, and every pair took seconds). Bounded in time
  // for very large sheets.
  constexpr size_t kTwoOptReach = 64;
  // Where each stroke in the order is entered and left, kept in step with
  // the order: a reversed run swaps each stroke's two (the same point for a
  // closed stroke).
  std::vector<Point2> in(n), leave(n);
  for (size_t k = 0; k < n; ++k) {
    in[k] = candidates[order[k]].points[entry[order[k]]];
    leave[k] = exitOf(candidates[order[k]], entry[order[k]]);
  }
  const auto started = std::chrono::steady_clock::now();
  // At most a few passes, so that the work per stroke is bounded.
  constexpr int kTwoOptPasses = 4;
  int passes = 0;
  for (bool improved = true; improved && n > 2 && passes < kTwoOptPasses; ++passes) {
    improved = false;
    for (size_t i = 0; i + 1 < n; ++i) {
      if (std::chrono::steady_clock::now() - started > std::chrono::seconds(2)) break;
      const Point2 before = i == 0 ? from : leave[i - 1];
      for (size_t j = i + 1; j < std::min(n, i + 1 + kTwoOptReach); ++j) {
        const bool last = j + 1 == n;
        // Reversed, the run is entered where stroke j is left now, and left
        // where stroke i is entered now. It is shorter only if one of those
        // two travels is shorter than the one it replaces: most pairs are
        // passed over on squared lengths, without a square root.
        const double intoNow = (in[i] - before).squaredNorm(), intoThen = (leave[j] - before).squaredNorm();
        const double onNow = last ? 0.0 : (in[j + 1] - leave[j]).squaredNorm();
        const double onThen = last ? 0.0 : (in[j + 1] - in[i]).squaredNorm();
        if (intoThen >= intoNow && onThen >= onNow) continue;
        const double now = std::sqrt(intoNow) + std::sqrt(onNow), then = std::sqrt(intoThen) + std::sqrt(onThen);
        if (then < now - 1e-9) {
          const auto first = static_cast<long>(i), end = static_cast<long>(j) + 1;
          std::reverse(order.begin() + first, order.begin() + end);
          std::reverse(in.begin() + first, in.begin() + end);
          std::reverse(leave.begin() + first, leave.begin() + end);
          for (size_t k = i; k <= j; ++k) {
            std::swap(in[k], leave[k]);
            const Candidate& c = candidates[order[k]];
            if (!c.closed) entry[order[k]] = entry[order[k]] == 0 ? c.points.size() - 1 : 0;
          }
          improved = true;
        }
      }
    }
  }
  std::vector<std::vector<Point2>> out;
  for (size_t k = 0; k < n; ++k) out.push_back(burnOrder(candidates[order[k]], entry[order[k]]));
  if (n > 0) from = out.back().back();
  return out;
}

// Its burn and travel lengths, and its time on a machine of `limits`.
void measure(Toolpath& toolpath, const MotionLimits& limits) {
  toolpath.burnLength = toolpath.travelLength = 0;
  Point2 head(0, 0);
  for (const ToolpathStroke& stroke : toolpath.strokes) {
    toolpath.travelLength += (stroke.points.front() - head).norm();
    for (size_t i = 1; i < stroke.points.size(); ++i)
      toolpath.burnLength += (stroke.points[i] - stroke.points[i - 1]).norm();
    head = stroke.points.back();
  }
  toolpath.travelLength += head.norm();
  toolpath.seconds = estimateSeconds(toolpath, limits);
}

}  // namespace

Toolpath planToolpath(const SheetDrawing& sheet, const profiles::MachineProfile& machine,
                      const profiles::MaterialProfile& material, const MotionLimits& limits) {
  Toolpath toolpath;
  toolpath.sheet = sheet.index;
  toolpath.width = sheet.width;
  toolpath.height = sheet.height;
  toolpath.framePower = machine.framePower;
  // A closed cut inside another closed cut is an inner cut (a hole, or a cut
  // in a hole of a part): its part is not yet free when it is cut.
  std::vector<const DrawnPath*> cuts;
  for (const DrawnPath& path : sheet.paths) {
    if (path.operation == Operation::Cut && path.closed) cuts.push_back(&path);
  }
  std::vector<std::array<double, 4>> boxes;
  for (const DrawnPath* path : cuts) {
    std::array<double, 4> box{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                              std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
    for (const Point2& p : path->points) {
      box[0] = std::min(box[0], p.x()), box[1] = std::min(box[1], p.y());
      box[2] = std::max(box[2], p.x()), box[3] = std::max(box[3], p.y());
    }
    boxes.push_back(box);
  }
  const auto depthOf = [&](const DrawnPath& path) {
    const Point2& p = path.points.front();
    int depth = 0;
    for (size_t k = 0; k < cuts.size(); ++k) {
      if (cuts[k] == &path) continue;
      const auto& b = boxes[k];
      if (p.x() < b[0] || p.x() > b[2] || p.y() < b[1] || p.y() > b[3]) continue;
      depth += core::insidePolygon(cuts[k]->points, p);
    }
    return depth;
  };
  std::map<Stage, std::vector<Candidate>> stages;
  for (const DrawnPath& path : sheet.paths) {
    if (path.operation == Operation::Outline) continue;  // the material's edge: drawn, never burnt
    const Stage stage = path.operation == Operation::Etch    ? Stage{0, 0}
                        : path.operation == Operation::Score ? Stage{1, 0}
                                                             : Stage{2, -depthOf(path)};
    Candidate c{path.points, path.closed};
    if (c.closed) c.points.push_back(c.points.front());
    stages[stage].push_back(std::move(c));
  }
  Point2 at(0, 0);
  for (auto& [stage, candidates] : stages) {
    const Operation operation = stage.rank == 0 ? Operation::Etch : stage.rank == 1 ? Operation::Score : Operation::Cut;
    const profiles::ColourSetting& setting = machine.settingFor(operation);
    const auto [power, speed, passes, minPower] = profiles::operationSettings(machine, material, operation);
    if (!(speed > 0) || passes < 1) {
      throw std::invalid_argument(fmt::format("{}: the {} setting ({}) has speed {}% and {} passes; nothing to run",
                                              machine.name, profiles::operationName(operation), setting.name, speed,
                                              passes));
    }
    const auto ordered = orderForTravel(candidates, at);
    for (int pass = 1; pass <= passes; ++pass) {
      for (const auto& points : ordered) {
        toolpath.strokes.push_back({operation, stage.rank == 2 && stage.depth < 0, std::clamp(power / 100, 0.0, 1.0),
                                    speed / 100 * limits.maxSpeed, pass, points, std::clamp(minPower / 100, 0.0, 1.0)});
      }
    }
  }
  measure(toolpath, limits);
  return toolpath;
}

Toolpath restOfSheet(const Toolpath& toolpath, size_t firstStroke, const MotionLimits& limits) {
  Toolpath rest = toolpath;
  rest.strokes.erase(rest.strokes.begin(),
                     rest.strokes.begin() + static_cast<std::ptrdiff_t>(std::min(firstStroke, rest.strokes.size())));
  measure(rest, limits);
  return rest;
}

MotionLimits profileMotion(const profiles::MachineProfile& profile) {
  MotionLimits limits;
  const bool grbl = profile.driver == "grbl";
  limits.perAxis = grbl;
  limits.junctionDeviation = grbl ? 0.01 / 25.4 : 0;  // GRBL's default $11
  if (profile.motion) {
    limits.maxSpeed = profile.motion->maxSpeed;
    limits.acceleration = profile.motion->acceleration;
    limits.junctionDeviation = profile.motion->junctionDeviation;
  }
  return limits;
}

std::vector<Move> toolpathMoves(const Toolpath& toolpath) {
  std::vector<Move> moves;
  for (const ToolpathStroke& stroke : toolpath.strokes) {
    moves.push_back({stroke.points.front(), 0, false});
    for (size_t i = 1; i < stroke.points.size(); ++i) moves.push_back({stroke.points[i], stroke.speed, false});
  }
  moves.push_back({Point2(0, 0), 0, true});
  return moves;
}

MotionTime toolpathTime(const Toolpath& toolpath, const MotionLimits& limits) {
  return plannedTime(Point2(0, 0), toolpathMoves(toolpath), limits.maxSpeed, limits.acceleration,
                     limits.junctionDeviation, limits.perAxis);
}

double estimateSeconds(const Toolpath& toolpath, const MotionLimits& limits) {
  return toolpathTime(toolpath, limits).seconds;
}

std::array<double, 4> toolpathBounds(const Toolpath& toolpath) {
  std::array<double, 4> box{std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                            std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest()};
  for (const ToolpathStroke& stroke : toolpath.strokes) {
    for (const Point2& p : stroke.points) {
      box[0] = std::min(box[0], p.x()), box[1] = std::min(box[1], p.y());
      box[2] = std::max(box[2], p.x()), box[3] = std::max(box[3], p.y());
    }
  }
  if (toolpath.strokes.empty()) box = {0, 0, 0, 0};
  return box;
}

}  // namespace rotafab::jobs
