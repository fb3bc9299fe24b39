#include "jobs/Nesting.h"
#include "geometry/PanelUnfolding.h"

#include "jobs/CellCover.h"
#include "jobs/ConvexPieces.h"

#include <fmt/format.h>
#include <clipper.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>
#include <stdexcept>
#include <thread>
#include <tuple>

namespace rotafab::jobs {
namespace {

using ClipperLib::cInt;
using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;

// Clipper works on integers: 1/10000 in (2.5 um) is far below a laser's kerf.
constexpr double kScale = 1e4;
// Outlines are simplified for nesting after being grown by this much, so the
// simplified shape still contains the true one.
constexpr double kSimplifyTolerance = 0.002;
// Poles per shape for the compaction's overlap proxy.
constexpr size_t kMostPoles = 12;
// Grid units by which each of two grown shapes may reach into the other in
// the compaction (see Shape::core): together far below layoutProblems'
// tolerance of 1e-3 in (10 units).
constexpr ClipperLib::cInt kCollisionSlack = 3;
// The compaction's sampled moves (Packer::sampledMove), with sparrow's
// settings: places drawn near the part and anywhere, how many of the best
// are refined, and how far apart (a share of the part's smaller side) two
// must be to count as two.
constexpr int kNearSamples = 25, kFarSamples = 50;
constexpr size_t kDescents = 3;
constexpr double kDistinctShare = 0.05;
// Its separation (Packer::separate): rounds without progress before a
// strike, strikes before it gives up, how fast the weight of a pair that no
// longer overlaps fades back to 1, and the most a weight can grow to.
constexpr int kStaleRounds = 50, kStrikes = 3;
constexpr double kWeightFade = 0.95, kHeaviest = 1e9;
// Its overlap proxy (Packer::proxy): poles that reach into each other by
// less than this share of the larger shape's diameter (or are apart) count
// by a decaying amount instead of their depth.
constexpr double kDecayShare = 0.01;
constexpr double kNoLimit = std::numeric_limits<double>::max();

cInt toInt(double value) { return static_cast<cInt>(std::llround(value * kScale)); }

Path toPath(const Polygon2& polygon) {
  Path path;
  path.reserve(polygon.size());
  for (const Point2& p : polygon) path.push_back({toInt(p.x()), toInt(p.y())});
  return path;
}

Polygon2 rotated(const Polygon2& polygon, double degrees) {
  Polygon2 out;
  out.reserve(polygon.size());
  for (const Point2& p : polygon) out.push_back(rotatedPoint(p, degrees));
  return out;
}

// The largest path of an offset; an outward offset of a simple polygon has one.
// The boundary is grown too, as a line: a needle or slit in the outline (a
// cut out and back along one line) encloses no area, and growing the polygon
// alone would drop it, though the laser cuts it and neighbours must keep clear.
// The piece of largest area, or `otherwise` when there is none.
Path largestOf(const Paths& pieces, const Path& otherwise) {
  if (pieces.empty()) return otherwise;
  return *std::max_element(pieces.begin(), pieces.end(), [](const Path& a, const Path& b) {
    return std::abs(ClipperLib::Area(a)) < std::abs(ClipperLib::Area(b));
  });
}

Path grown(const Path& path, double by, ClipperLib::JoinType join) {
  ClipperLib::ClipperOffset offset(2.0, 0.25 * kScale * 0.001);
  offset.AddPath(path, join, ClipperLib::etClosedPolygon);
  offset.AddPath(path, ClipperLib::jtRound, ClipperLib::etClosedLine);
  Paths out;
  offset.Execute(out, by * kScale);
  return largestOf(out, path);
}

// One part in one rotation: its outline grown by half the spacing (for no-fit
// polygons) and the extent of its true outline (for the bed's inner-fit rectangle).
struct Shape {
  Path grown;
  Path negated;  // -grown, the pattern of the Minkowski sums
  // Convex pieces of `grown` and of `negated`; empty when the decomposition
  // failed, and then the no-fit polygons come from Clipper's MinkowskiSum.
  std::vector<Path> pieces, negatedPieces;
  std::vector<Box> pieceBoxes, negatedPieceBoxes;
  // Discs of one radius inside `grown`, the largest the shape holds first,
  // then spread over it: wherever the shape can go, each disc's centre is
  // clear of every placed shape by the radius (see Sheet::room). No discs
  // when the shape is too thin to hold one of the radius step.
  std::vector<IntPoint> centres;
  cInt radius = 0;
  // Poles, as sparrow calls them: discs inside `grown`, the largest first,
  // each the largest in what the earlier ones leave uncovered. The
  // compaction's overlap proxy (Packer::proxy) weighs how deep two shapes'
  // poles reach into each other.
  struct Pole {
    IntPoint centre;
    double radius;
  };
  std::vector<Pole> poles;
  double diameter = 0;  // of `grown`'s box
  double size = 0;      // the square root of `grown`'s area
  // `grown` shrunk by kCollisionSlack: the compaction's collision test asks
  // whether two cores overlap, so that shapes placed touching, with no-fit
  // polygon vertices rounded to the grid, are not taken for colliding. Only
  // the largest piece is kept: a part would need a neck under about 6
  // units (0.0006 in) wide to be cut in two, and the final layoutProblems
  // check would still refuse any overlap there.
  Path core;
  Box coreBox{};
  cInt grownMinX = 0, grownMinY = 0, grownMaxX = 0, grownMaxY = 0;
  cInt minX = 0, minY = 0, maxX = 0, maxY = 0;
  double rotation = 0;
};

Box boxOf(const Path& path) {
  Box box{std::numeric_limits<cInt>::max(), std::numeric_limits<cInt>::max(), std::numeric_limits<cInt>::min(),
          std::numeric_limits<cInt>::min()};
  for (const IntPoint& p : path) {
    box[0] = std::min(box[0], p.X), box[1] = std::min(box[1], p.Y);
    box[2] = std::max(box[2], p.X), box[3] = std::max(box[3], p.Y);
  }
  return box;
}

// The distance from (x, y) to the polygon's boundary.
double distanceToBoundary(const Path& polygon, double x, double y) {
  double best = std::numeric_limits<double>::max();
  for (size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const IntPoint& a = polygon[j];
    const IntPoint& b = polygon[i];
    const double dx = static_cast<double>(b.X - a.X), dy = static_cast<double>(b.Y - a.Y);
    const double length2 = dx * dx + dy * dy;
    double t = length2 > 0 ? ((x - a.X) * dx + (y - a.Y) * dy) / length2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double ex = x - (a.X + t * dx), ey = y - (a.Y + t * dy);
    best = std::min(best, ex * ex + ey * ey);
  }
  return std::sqrt(best);
}

// The sizes of the sheet's `room` machinery, in proportion to the area's
// height (instances come in any unit): on the 17.5 in high bed, disc radii are
// rounded down to 1/20 in so that parts of similar size share the room
// regions, cells are 1/4 in, and Clipper's round joins keep within 1/100 in.
struct RoomScale {
  cInt radiusStep, cell;
  double arcTolerance;
};

RoomScale roomScaleFor(cInt height) {
  const cInt h = std::max<cInt>(height, 3500);
  return {h / 350, h / 70, static_cast<double>(h) / 17500};
}

// The points of a (steps + 1) x (steps + 1) grid over the polygon's box that
// lie strictly inside it, with their distance to its boundary.
std::vector<std::pair<IntPoint, double>> gridInside(const Path& polygon, int steps) {
  const auto [minX, minY, maxX, maxY] = boxOf(polygon);
  std::vector<std::pair<IntPoint, double>> inside;
  for (int i = 0; i <= steps; ++i) {
    for (int j = 0; j <= steps; ++j) {
      const IntPoint p{minX + (maxX - minX) * i / steps, minY + (maxY - minY) * j / steps};
      if (ClipperLib::PointInPolygon(p, polygon) != 1) continue;
      inside.emplace_back(p, distanceToBoundary(polygon, static_cast<double>(p.X), static_cast<double>(p.Y)));
    }
  }
  return inside;
}

// Discs of one radius inside a polygon. The largest: a grid search for the
// point farthest from the boundary, refined around the best point, its radius
// the distance from there rounded down to `radiusStep`. Then up to
// `maxDiscs - 1` more of that radius, each at the grid point with room for it
// that is farthest from the centres so far, while that is at least a radius
// away. Every radius is a true distance to the boundary, so every disc is inside.
std::pair<cInt, std::vector<IntPoint>> clearDiscs(const Path& polygon, cInt radiusStep, int maxDiscs = 5) {
  const auto [minX, minY, maxX, maxY] = boxOf(polygon);
  constexpr int kSteps = 24;
  const auto inside = gridInside(polygon, kSteps);
  IntPoint best{(minX + maxX) / 2, (minY + maxY) / 2};
  double bestDistance = -1;
  for (const auto& [p, d] : inside) {
    if (d > bestDistance) bestDistance = d, best = p;
  }
  auto consider = [&](cInt x, cInt y) {
    if (ClipperLib::PointInPolygon({x, y}, polygon) != 1) return;
    const double d = distanceToBoundary(polygon, static_cast<double>(x), static_cast<double>(y));
    if (d > bestDistance) bestDistance = d, best = {x, y};
  };
  for (double step = std::max(maxX - minX, maxY - minY) / (2.0 * kSteps); step >= 1; step /= 2) {
    const IntPoint at = best;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) consider(at.X + std::llround(dx * step), at.Y + std::llround(dy * step));
    }
  }
  const cInt radius = static_cast<cInt>(std::max(0.0, bestDistance - 1)) / radiusStep * radiusStep;
  if (radius <= 0) return {0, {}};
  std::vector<IntPoint> centres{best};
  while (static_cast<int>(centres.size()) < maxDiscs) {
    double farthest = 0;
    IntPoint next{0, 0};
    for (const auto& [p, d] : inside) {
      if (d < static_cast<double>(radius)) continue;
      double nearest = std::numeric_limits<double>::max();
      for (const IntPoint& c : centres) {
        nearest = std::min(nearest, std::hypot(static_cast<double>(p.X - c.X), static_cast<double>(p.Y - c.Y)));
      }
      if (nearest > farthest) farthest = nearest, next = p;
    }
    if (farthest < static_cast<double>(radius)) break;
    centres.push_back(next);
  }
  return {radius, centres};
}

// The poles of a polygon (see Shape::poles): on a grid of points inside
// it, greedily the one with the largest disc clear of the boundary and of
// the discs so far, while that is at least a tenth of the first's radius.
std::vector<Shape::Pole> polesOf(const Path& polygon, size_t most) {
  // Grid points and the largest disc at each clear of the boundary and of the poles so far.
  auto inside = gridInside(polygon, 32);
  std::vector<Shape::Pole> poles;
  while (poles.size() < most && !inside.empty()) {
    const auto best = std::max_element(inside.begin(), inside.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    if (best->second < 1 || (!poles.empty() && best->second < 0.1 * poles.front().radius)) break;
    const Shape::Pole pole{best->first, best->second};
    poles.push_back(pole);
    for (auto& [p, room] : inside) {
      const double apart =
          std::hypot(static_cast<double>(p.X - pole.centre.X), static_cast<double>(p.Y - pole.centre.Y)) - pole.radius;
      room = std::min(room, apart);
    }
  }
  // Too thin for the grid: one small pole at a point inside, so that
  // containment is still found (failing that, on a vertex: never empty).
  if (poles.empty()) {
    for (size_t i = 0; i < polygon.size() && poles.empty(); ++i) {
      const IntPoint& a = polygon[i];
      const IntPoint& b = polygon[(i + 1) % polygon.size()];
      const IntPoint& c = polygon[(i + 2) % polygon.size()];
      const IntPoint mid{(a.X + b.X + c.X) / 3, (a.Y + b.Y + c.Y) / 3};
      if (ClipperLib::PointInPolygon(mid, polygon) == 1) poles.push_back({mid, 1.0});
    }
  }
  if (poles.empty()) poles.push_back({polygon.front(), 1.0});
  return poles;
}

Shape makeShape(const Polygon2& outline, double rotation, double spacing, cInt radiusStep) {
  Shape shape;
  shape.rotation = rotation;
  Path path = toPath(rotated(outline, rotation));
  if (ClipperLib::Area(path) < 0) std::reverse(path.begin(), path.end());
  std::tie(shape.minX, shape.minY, shape.maxX, shape.maxY) = std::tuple_cat(boxOf(path));
  shape.grown = grown(path, spacing / 2 + kSimplifyTolerance, ClipperLib::jtMiter);
  ClipperLib::CleanPolygon(shape.grown, kSimplifyTolerance * kScale);
  if (ClipperLib::Area(shape.grown) < 0) std::reverse(shape.grown.begin(), shape.grown.end());
  for (const IntPoint& p : shape.grown) shape.negated.push_back({-p.X, -p.Y});
  std::tie(shape.grownMinX, shape.grownMinY, shape.grownMaxX, shape.grownMaxY) = std::tuple_cat(boxOf(shape.grown));
  std::tie(shape.radius, shape.centres) = clearDiscs(shape.grown, radiusStep);
  shape.poles = polesOf(shape.grown, kMostPoles);
  shape.diameter = std::hypot(static_cast<double>(shape.grownMaxX - shape.grownMinX),
                              static_cast<double>(shape.grownMaxY - shape.grownMinY));
  shape.size = std::sqrt(std::abs(ClipperLib::Area(shape.grown)));
  ClipperLib::ClipperOffset shrink(2.0);
  shrink.AddPath(shape.grown, ClipperLib::jtMiter, ClipperLib::etClosedPolygon);
  Paths cores;
  shrink.Execute(cores, -static_cast<double>(kCollisionSlack));
  shape.core = largestOf(cores, shape.grown);
  if (ClipperLib::Area(shape.core) < 0) std::reverse(shape.core.begin(), shape.core.end());
  shape.coreBox = boxOf(shape.core);
  if (auto pieces = convexPieces(shape.grown)) {
    shape.pieces = std::move(*pieces);
    for (const Path& piece : shape.pieces) {
      Path negated;  // a half turn keeps the piece counter-clockwise
      for (const IntPoint& p : piece) negated.push_back({-p.X, -p.Y});
      shape.negatedPieces.push_back(std::move(negated));
    }
    for (const Path& piece : shape.pieces) shape.pieceBoxes.push_back(boxOf(piece));
    for (const Path& piece : shape.negatedPieces) shape.negatedPieceBoxes.push_back(boxOf(piece));
  }
  return shape;
}

// The union of many overlapping regions, two at a time up a balanced tree:
// Clipper unites a few large overlapping regions much faster than very many
// small ones at once (27 x 27 convex sums of two wavy strips: 2.6 ms against 59 ms).
Paths unionOf(std::vector<Paths> regions) {
  if (regions.empty()) return {};
  for (size_t step = 1; step < regions.size(); step *= 2) {
    for (size_t i = 0; i + step < regions.size(); i += 2 * step) {
      ClipperLib::Clipper clipper;
      clipper.AddPaths(regions[i], ClipperLib::ptSubject, true);
      clipper.AddPaths(regions[i + step], ClipperLib::ptClip, true);
      clipper.Execute(ClipperLib::ctUnion, regions[i], ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      regions[i + step].clear();
    }
  }
  if (regions.size() == 1) {  // one region: still resolve its own overlaps
    ClipperLib::Clipper clipper;
    clipper.AddPaths(regions[0], ClipperLib::ptSubject, true);
    clipper.Execute(ClipperLib::ctUnion, regions[0], ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  }
  return std::move(regions[0]);
}

Path translatedPath(const Path& path, IntPoint by) {
  Path out;
  out.reserve(path.size());
  for (const IntPoint& p : path) out.push_back({p.X + by.X, p.Y + by.Y});
  return out;
}

struct PlacedShape {
  int part;
  int shape;  // index into the part's shapes
  IntPoint at;
};

// A bed (or the strip) being filled.
struct Sheet {
  std::vector<PlacedShape> parts;
  Paths occupied;  // the union of the placed grown shapes
  double freeArea = 0;
  // Radius -> the centres of discs of that radius clear of `occupied` and on
  // the area: a shape holding such a disc can only go where its disc's centre
  // is in this region, so only the no-fit polygons near it matter.
  struct Room {
    Paths centres;  // the region
    size_t upTo;    // of `parts`, those kept clear of; the later ones are taken out when next asked for
    CellCover cover;
  };
  std::map<cInt, Room> room;
};

// How often a long first layout says how far it has got.
constexpr std::chrono::seconds kProgressEvery{5};

// The room regions are eroded by this much less than the radius: Clipper's
// round joins put their vertices on the arcs (so their chords only add to the
// region), and the grid rounds by a unit.
constexpr cInt kRoomSlack = 4;

// Strip compaction: the first shortening (2%), the least (0.1%), and tries
// per shortening before it is halved (docs/PERFORMANCE.md).
constexpr double kFirstShrink = 0.02, kLeastShrink = 0.001;
constexpr int kTriesPerShrink = 5;
// The kept no-fit polygons are dropped when they hold this many points (16 bytes each).
constexpr size_t kMostSharedPoints = 8'000'000;

// Places parts one by one, bottom-left on the vertices of the feasible region.
class Packer {
 public:
  Packer(const std::vector<NestingPart>& parts, const NestingOptions& options)
      : parts_(parts), options_(options), roomScale_(roomScaleFor(toInt(options.height))) {
    shapes_.resize(parts.size());
    for (size_t i = 0; i < parts.size(); ++i) {
      for (double rotation : parts[i].rotations)
        shapes_[i].push_back(makeShape(parts[i].outline, rotation, options.spacing, roomScale_.radiusStep));
    }
    for (const auto& shapes : shapes_) area_.push_back(std::abs(ClipperLib::Area(shapes.front().grown)));
    std::map<std::vector<cInt>, int> classes;
    for (const auto& shapes : shapes_) {
      classOf_.emplace_back();
      for (const Shape& shape : shapes) {
        std::vector<cInt> key;
        for (const IntPoint& p : shape.grown) key.insert(key.end(), {p.X, p.Y});
        const auto [it, added] = classes.emplace(std::move(key), static_cast<int>(classSize_.size()));
        if (added) classSize_.push_back(0);
        ++classSize_[it->second];
        classOf_.back().push_back(it->second);
      }
    }
    for (const auto& shapes : shapes_) {
      quarterOf_.emplace_back();
      shapeAtQuarter_.push_back({-1, -1, -1, -1});
      for (size_t k = 0; k < shapes.size(); ++k) {
        const double quarters = shapes[k].rotation / 90.0;
        int quarter = -1;
        if (std::abs(quarters - std::round(quarters)) < 1e-12) {
          quarter = static_cast<int>(((std::llround(quarters) % 4) + 4) % 4);
          if (shapeAtQuarter_.back()[quarter] < 0) shapeAtQuarter_.back()[quarter] = static_cast<int>(k);
        }
        quarterOf_.back().push_back(quarter);
      }
      const auto& at = shapeAtQuarter_.back();
      firstQuarter_.push_back(
          static_cast<int>(std::find_if(at.begin(), at.end(), [](int k) { return k >= 0; }) - at.begin()));
    }
    width_ = options.strip ? stripBound() : toInt(options.width);
    height_ = toInt(options.height);
    // Wider than what two grown shapes overhang their beds (spacing / 2 and
    // the simplification each, with mitres), in any unit.
    if (!options.strip) pitch_ = width_ + 2 * toInt(options.spacing) + toInt(1.0);
    for (size_t i = 0; i < parts.size(); ++i) {
      const bool fits = std::any_of(shapes_[i].begin(), shapes_[i].end(), [&](const Shape& s) {
        return s.maxX - s.minX <= width_ && s.maxY - s.minY <= height_;
      });
      if (!fits) {
        throw std::invalid_argument(fmt::format(
            "{} ({:.4g} x {:.4g}) does not fit the usable area of {:.4g} x {:.4g} in any allowed rotation",
            parts[i].name, extentOf(i).x(), extentOf(i).y(), options.strip ? 0.0 : options.width, options.height));
      }
    }
  }

  // Lays out the parts in `sequence`; returns placements in cutting order.
  // `policy` Strict fills only the last sheet; otherwise first fit over all sheets.
  //
  // `unchanged`: how many leading parts of `sequence` are those of the last
  // accepted sequence (see accept()); the layout resumes from the latest
  // checkpoint among them instead of starting over.
  // `shapeOf[part]`, when given and not negative, is the only rotation (index
  // into the part's rotations) tried for the part, unless it cannot go on an empty sheet.
  //
  // `until`: a trial layout is given up (nothing returned) once past it, so
  // that the search keeps to its time budget.
  std::optional<NestingResult> pack(
      const std::vector<int>& sequence, OrderMode policy, size_t unchanged = 0, const std::vector<int>& shapeOf = {},
      std::chrono::steady_clock::time_point until = std::chrono::steady_clock::time_point::max()) {
    PackState state;
    size_t start = 0;
    if (policy == acceptedPolicy_) {
      for (const auto& [at, snapshot] : accepted_) {
        if (at <= unchanged && at > start && at <= sequence.size()) start = at, state = snapshot;
      }
    }
    pending_.clear();
    pendingStart_ = start;
    pendingPolicy_ = policy;
    auto& [sheets, placed] = state;
    const double sheetArea = static_cast<double>(width_) * static_cast<double>(height_);
    auto nextReport = std::chrono::steady_clock::now() + kProgressEvery;
    for (size_t index = start; index < sequence.size(); ++index) {
      const auto now = std::chrono::steady_clock::now();
      if (now > until) return std::nullopt;
      if (onProgress && now > nextReport) {
        onProgress(index, sequence.size(), sheets.size());
        nextReport = now + kProgressEvery;
      }
      if (index > start && index % kCheckpointEvery == 0) {
        pending_.emplace_back(index, state);
        for (Sheet& sheet : pending_.back().second.sheets) sheet.room.clear();  // rebuilt on demand
      }
      const int part = sequence[index];
      const int only = shapeOf.empty() ? -1 : shapeOf[part];
      bool done = false;
      const int firstSheet = policy == OrderMode::Strict ? std::max(0, static_cast<int>(sheets.size()) - 1) : 0;
      for (int s = firstSheet; s < static_cast<int>(sheets.size()) && !done; ++s) {
        if (policy == OrderMode::Window && s + 1 < static_cast<int>(sheets.size())) {
          // Placed on sheet s, the part is cut after every part on sheets 0..s.
          int cutBefore = 0;
          for (int k = 0; k <= s; ++k) cutBefore += static_cast<int>(sheets[k].parts.size());
          if (parts_[part].order - cutBefore > options_.window) continue;
        }
        if (sheets[s].freeArea < area_[part]) continue;  // cannot hold it: skip the no-fit polygons
        if (auto spot = bestSpot(part, sheets[s], only)) {
          put(sheets[s], *spot);
          placed.emplace_back(s, *spot);
          done = true;
        }
      }
      if (!done && options_.strip && !sheets.empty()) {
        // The strip is one sheet: a fixed rotation that does not fit it gives way.
        if (auto spot = only >= 0 ? bestSpot(part, sheets.front(), -1) : std::nullopt) {
          put(sheets.front(), *spot);
          placed.emplace_back(0, *spot);
          done = true;
        } else {
          throw std::invalid_argument(fmt::format("{} does not fit the strip", parts_[part].name));
        }
      }
      if (!done) {
        sheets.emplace_back();
        sheets.back().freeArea = sheetArea;
        auto spot = bestSpot(part, sheets.back(), only);
        if (!spot && only >= 0) spot = bestSpot(part, sheets.back(), -1);
        if (!spot) throw std::invalid_argument(fmt::format("{} does not fit an empty sheet", parts_[part].name));
        put(sheets.back(), *spot);
        placed.emplace_back(static_cast<int>(sheets.size()) - 1, *spot);
      }
    }
    // Cutting order: sheet by sheet, each in the order its parts were placed.
    std::stable_sort(placed.begin(), placed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    lastLayout_.clear();
    for (auto [sheet, spot] : placed) {
      spot.at.X += sheet * pitch_;
      lastLayout_.push_back(spot);
    }
    return resultOf(placed, static_cast<int>(sheets.size()));
  }

  // Compaction by overlap minimisation, after the sequence search (in the
  // spirit of Umetani et al. 2009 and sparrow): shorten the strip a little by
  // taking out a slice, then move the parts apart (separate()) until nothing
  // overlaps (a shorter layout: keep it, shorten again) or it gives up (go
  // back; after a few such tries, shorten by less).
  // On beds, the beds lie side by side in one row (see pitch_) and the slice
  // comes out of the last bed: what it holds moves to the earlier beds, which
  // fill up, until the last bed is empty and one bed fewer is used.
  // `goOn` says whether the budget allows another move; `moves` counts them;
  // `shorter` hears of each better layout kept (beds, last bed's length in
  // inches). The layout is exact: a try succeeds only when no two grown
  // shapes reach into each other by more than kCollisionSlack each.
  NestingResult compact(std::mt19937& random, const std::function<bool()>& goOn, int& moves,
                        const std::function<void(int, double)>& shorter) {
    std::vector<PlacedShape> best = acceptedLayout_;
    cInt bestLength = lengthOf(best);
    double shrink = kFirstShrink;
    int failures = 0;
    while (goOn()) {
      // Down to the least shortening: start again from the first, at other
      // places, after a disruption (as sparrow does): two parts of different
      // shapes trade places, and the layout is kept if they can be moved
      // apart at the same length.
      if (shrink < kLeastShrink) {
        shrink = kFirstShrink;
        if (best.size() > 1) {
          std::vector<PlacedShape> trial = best;
          const size_t a = random() % trial.size(), b = random() % trial.size();
          if (a != b && classOf_[trial[a].part][trial[a].shape] != classOf_[trial[b].part][trial[b].shape]) {
            const IntPoint ca = centreOf(trial[a]), cb = centreOf(trial[b]);
            const auto lanes = lanesUpTo(bestLength);
            if (moveInto(trial[a], cb, lanes) && moveInto(trial[b], ca, lanes) &&
                separate(trial, lanes, random, goOn, moves)) {
              best = std::move(trial);
              bestLength = lengthOf(best);
            }
          }
        }
      }
      // In the strip, a share of its length; on beds, of a bed's, so that
      // the last bed empties in steps of the same size however full it is.
      const cInt lastStart = laneStartOf(bestLength);
      const cInt cut =
          std::max<cInt>(1, static_cast<cInt>(static_cast<double>(options_.strip ? bestLength : width_) * shrink));
      cInt target = bestLength - cut;
      if (target <= lastStart) {
        if (lastStart == 0) break;             // one bed, or the strip, as short as a part
        target = lastStart - pitch_ + width_;  // the last bed empties: the one before ends at its edge
      }
      // Take a slice out at a random place (as sparrow does): the parts right
      // of it move left, so the overlaps to resolve are somewhere else at
      // every try, not always at the end.
      const cInt at = std::uniform_int_distribution<cInt>(lastStart, bestLength)(random);
      const auto lanes = lanesUpTo(target);
      std::vector<PlacedShape> trial = best;
      bool fits = true;
      for (PlacedShape& s : trial) {
        if (centreOf(s).X > at) s.at.X -= cut;
        fits = fits && moveInto(s, centreOf(s), lanes);
      }
      if (!fits) break;  // a part is as long as the strip
      if (separate(trial, lanes, random, goOn, moves)) {
        best = std::move(trial);
        bestLength = lengthOf(best);
        failures = 0;
        shorter(bedsUsed(best), (bestLength - laneStartOf(bestLength)) / kScale);
      } else if (++failures == kTriesPerShrink) {
        shrink /= 2;
        failures = 0;
      }
    }
    acceptedLayout_ = best;
    // Back from the row of beds to each bed's own coordinates, in cutting
    // order: bed by bed, each in the order of the layout.
    // A bed in the middle that the moves emptied is left out.
    std::vector<std::pair<int, PlacedShape>> placed;
    for (PlacedShape s : best) {
      const int sheet = sheetOf(rightOf(s));
      s.at.X -= sheet * pitch_;
      placed.emplace_back(sheet, s);
    }
    std::stable_sort(placed.begin(), placed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    int sheets = 0;
    for (size_t i = 0; i < placed.size(); ++i) {
      const bool newBed = i == 0 || placed[i].first != placed[i - 1].first;
      if (newBed) ++sheets;
      placed[i].first = sheets - 1;
    }
    return resultOf(placed, std::max(sheets, 1));
  }

  int bedsUsed(const std::vector<PlacedShape>& layout) const {
    std::vector<int> beds;
    for (const PlacedShape& s : layout) beds.push_back(sheetOf(rightOf(s)));
    std::sort(beds.begin(), beds.end());
    return static_cast<int>(std::unique(beds.begin(), beds.end()) - beds.begin());
  }
  cInt rightOf(const PlacedShape& s) const { return s.at.X + shapes_[s.part][s.shape].maxX; }
  cInt lengthOf(const std::vector<PlacedShape>& layout) const {
    cInt length = 0;
    for (const PlacedShape& s : layout) length = std::max(length, rightOf(s));
    return length;
  }

  // The last pack() becomes the sequence later calls compare with: its
  // checkpoints, and the earlier ones it resumed from, are kept.
  void accept() {
    acceptedLayout_ = lastLayout_;
    std::erase_if(accepted_, [&](const auto& checkpoint) { return checkpoint.first > pendingStart_; });
    if (pendingPolicy_ != acceptedPolicy_) accepted_.clear();
    for (auto& checkpoint : pending_) accepted_.push_back(std::move(checkpoint));
    acceptedPolicy_ = pendingPolicy_;
    pending_.clear();
  }

  // Called every few seconds while pack() works: parts placed so far, of how many, on how many sheets.
  std::function<void(size_t, size_t, size_t)> onProgress;

 private:
  // The state of a layout part way through a sequence.
  struct PackState {
    std::vector<Sheet> sheets;
    std::vector<std::pair<int, PlacedShape>> placed;  // (sheet, shape) in placing order
  };
  static constexpr size_t kCheckpointEvery = 8;
  std::vector<PlacedShape> lastLayout_, acceptedLayout_;          // in cutting order
  std::vector<std::pair<size_t, PackState>> accepted_, pending_;  // (parts placed, state), ascending

  size_t pendingStart_ = 0;
  std::optional<OrderMode> acceptedPolicy_, pendingPolicy_;

  // The compaction lays the beds side by side in one row, bed s from
  // s * pitch_ on, a gap wider than any overhang of a grown shape between
  // two: a layout of many beds is then one layout. These give the x ranges
  // (lanes) of the beds in a row ending at `length` (in the strip: one),
  // and the bed that a part ending at `right` is on.
  using Lanes = std::vector<std::pair<cInt, cInt>>;
  Lanes lanesUpTo(cInt length) const {
    if (options_.strip) return {{0, length}};
    Lanes lanes;
    for (cInt start = 0; start < length; start += pitch_) lanes.emplace_back(start, std::min(start + width_, length));
    return lanes;
  }
  cInt laneStartOf(cInt right) const { return options_.strip ? 0 : (std::max<cInt>(right, 1) - 1) / pitch_ * pitch_; }
  int sheetOf(cInt right) const { return options_.strip ? 0 : static_cast<int>(laneStartOf(right) / pitch_); }

  IntPoint centreOf(const PlacedShape& p) const {
    const Shape& shape = shapes_[p.part][p.shape];
    return {p.at.X + (shape.minX + shape.maxX) / 2, p.at.Y + (shape.minY + shape.maxY) / 2};
  }

  // Puts `p`'s box centre at `centre`, or as near as its lane allows: the
  // last lane that starts left of `centre`, or the first before it that is
  // long enough for the part, in its rotation or else in the first other
  // that fits. False when none is.
  bool moveInto(PlacedShape& p, IntPoint centre, const Lanes& lanes) const {
    size_t lane = 0;
    while (lane + 1 < lanes.size() && lanes[lane + 1].first <= centre.X) ++lane;
    for (size_t l = lane + 1; l-- > 0;) {
      const auto [from, to] = lanes[l];
      for (int k = -1; k < static_cast<int>(shapes_[p.part].size()); ++k) {
        const int tried = k < 0 ? p.shape : k;
        const Shape& shape = shapes_[p.part][tried];
        if (to - from < shape.maxX - shape.minX || height_ < shape.maxY - shape.minY) continue;
        p.shape = tried;
        p.at.X = std::clamp(centre.X - (shape.minX + shape.maxX) / 2, from - shape.minX, to - shape.maxX);
        p.at.Y = std::clamp(centre.Y - (shape.minY + shape.maxY) / 2, -shape.minY, height_ - shape.maxY);
        return true;
      }
    }
    return false;
  }

  NestingResult resultOf(const std::vector<std::pair<int, PlacedShape>>& placed, int sheets) const {
    NestingResult result;
    result.sheets = sheets;
    cInt right = 0;
    for (const auto& [sheet, spot] : placed) {
      const Shape& shape = shapes_[spot.part][spot.shape];
      result.placements.push_back({spot.part, sheet + 1, spot.at.X / kScale, spot.at.Y / kScale, shape.rotation});
      right = std::max(right, spot.at.X + shape.maxX);
    }
    result.stripLength = right / kScale;
    return result;
  }

  // Moves the parts of `layout` (on the lanes) apart by guided local search,
  // as sparrow's separator does: every round, each overlapping part moves
  // to where its weighted overlap is least (sampledMove), and the pairs
  // still overlapping weigh more, the deeper the more (x1.2 to x2), while
  // the others fade back towards 1. The layout of least overlap so far is
  // kept. A round that does not beat it counts towards kStaleRounds, one
  // that beats it by 2% starts the count again; when the count is full,
  // the moves start again from that layout (a strike, the weights kept).
  // After kStrikes strikes in a row, each ending less than 2% below where
  // it began, the separation fails (false), as it does when the budget runs
  // out. True when nothing overlaps, checked exactly (apart()).
  bool separate(std::vector<PlacedShape>& layout, const Lanes& lanes, std::mt19937& random,
                const std::function<bool()>& goOn, int& moves) {
    const size_t n = layout.size();
    std::vector<double> weights(n * n, 1.0);
    // Whether each pair overlaps, kept from round to round: only the pairs
    // of a part that moved are checked again.
    std::vector<char> overlaps(n * n, 0), moved(n, 1);
    double leastLoss = kNoLimit, strikeLoss = kNoLimit;
    std::vector<PlacedShape> leastLayout;
    int stale = 0, strikes = 0;
    while (goOn()) {
      std::vector<std::pair<size_t, size_t>> pairs;
      for (size_t i = 0; i < n; ++i) {
        for (size_t j = i + 1; j < n; ++j) {
          if (moved[i] || moved[j]) overlaps[i * n + j] = colliding(layout[i], layout[j]);
          if (overlaps[i * n + j]) pairs.emplace_back(i, j);
        }
      }
      std::fill(moved.begin(), moved.end(), 0);
      if (pairs.empty()) return apart(layout);
      std::vector<double> depth;
      for (const auto& [i, j] : pairs) {
        const Shape& a = shapes_[layout[i].part][layout[i].shape];
        const Shape& b = shapes_[layout[j].part][layout[j].shape];
        depth.push_back(proxy(a, layout[i].at, b, layout[j].at));
      }
      const double loss = std::accumulate(depth.begin(), depth.end(), 0.0);
      if (leastLoss == kNoLimit) strikeLoss = loss;
      if (loss < leastLoss) {
        if (loss < 0.98 * leastLoss) stale = 0;
        leastLoss = loss, leastLayout = layout;
      } else if (++stale == kStaleRounds) {
        strikes = strikeLoss * 0.98 <= leastLoss ? strikes + 1 : 0;
        if (strikes == kStrikes) return false;
        strikeLoss = leastLoss, stale = 0;
        layout = leastLayout;
        std::fill(moved.begin(), moved.end(), 1);
        continue;
      }
      std::vector<char> grows(n * n, 0);
      const double deepest = *std::max_element(depth.begin(), depth.end());
      for (size_t p = 0; p < pairs.size(); ++p) {
        const auto [i, j] = pairs[p];
        const double grown = std::min(kHeaviest, weights[i * n + j] * (1.2 + 0.8 * depth[p] / deepest));
        weights[i * n + j] = weights[j * n + i] = grown;
        grows[i * n + j] = grows[j * n + i] = 1;
      }
      for (size_t k = 0; k < n * n; ++k) {
        if (!grows[k]) weights[k] = std::max(1.0, weights[k] * kWeightFade);
      }
      std::vector<size_t> overlapped;
      for (const auto& [i, j] : pairs) overlapped.push_back(i), overlapped.push_back(j);
      std::sort(overlapped.begin(), overlapped.end());
      overlapped.erase(std::unique(overlapped.begin(), overlapped.end()), overlapped.end());
      std::shuffle(overlapped.begin(), overlapped.end(), random);
      for (size_t i : overlapped) {
        if (!goOn()) return false;
        const PlacedShape before = layout[i];
        sampledMove(layout, i, lanes, weights, random);
        ++moves;
        moved[i] = layout[i].shape != before.shape || layout[i].at != before.at;
      }
    }
    return false;
  }

  // Whether two placed shapes collide: their cores (see Shape::core)
  // overlap, touching apart. An edge of one properly crosses an edge of the
  // other, or a point of one (a pole's centre, a vertex, the middle of an
  // edge) is strictly inside the other's core. The same both ways round.
  // Can miss overlaps whose every crossing is at a vertex or along a shared
  // line and that hold none of those points; apart() has the last word.
  bool colliding(const PlacedShape& a, const PlacedShape& b) const {
    return shapesColliding(shapes_[a.part][a.shape], a.at, shapes_[b.part][b.shape], b.at);
  }
  static bool shapesColliding(const Shape& sa, IntPoint atA, const Shape& sb, IntPoint atB) {
    // In b's frame; only edges that meet both cores' boxes can cross.
    const IntPoint shift{atA.X - atB.X, atA.Y - atB.Y};
    const Box window{std::max(sa.coreBox[0] + shift.X, sb.coreBox[0]), std::max(sa.coreBox[1] + shift.Y, sb.coreBox[1]),
                     std::min(sa.coreBox[2] + shift.X, sb.coreBox[2]),
                     std::min(sa.coreBox[3] + shift.Y, sb.coreBox[3])};
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
      if (inB({p.X + shift.X, p.Y + shift.Y}) || inB({(p.X + q.X) / 2 + shift.X, (p.Y + q.Y) / 2 + shift.Y}))
        return true;
    }
    for (size_t j = 0; j < pb.size(); ++j) {
      const IntPoint& r = pb[j];
      const IntPoint& t = pb[(j + 1) % pb.size()];
      if (inA(r) || inA({(r.X + t.X) / 2, (r.Y + t.Y) / 2})) return true;
    }
    return false;
  }

  // How much two colliding shapes overlap (sparrow's quantification): over
  // every pair of poles, how deep they reach into each other times the
  // smaller radius; pairs apart or barely in still count a little,
  // decaying with the distance, so that a collision the poles do not reach
  // still has a way out. The square root, scaled by the shapes' sizes,
  // keeps shallow and deep collisions comparable.
  static double proxy(const Shape& sa, IntPoint atA, const Shape& sb, IntPoint atB) {
    const double epsilon = kDecayShare * std::max(sa.diameter, sb.diameter);
    double sum = 0;
    for (const Shape::Pole& a : sa.poles) {
      const double ax = static_cast<double>(a.centre.X + atA.X), ay = static_cast<double>(a.centre.Y + atA.Y);
      for (const Shape::Pole& b : sb.poles) {
        const double dx = ax - static_cast<double>(b.centre.X + atB.X),
                     dy = ay - static_cast<double>(b.centre.Y + atB.Y);
        const double depth = a.radius + b.radius - std::sqrt(dx * dx + dy * dy);
        const double weighed = depth >= epsilon ? depth : epsilon * epsilon / (2 * epsilon - depth);
        sum += weighed * std::min(a.radius, b.radius);
      }
    }
    return std::sqrt(sum + epsilon * epsilon) * std::sqrt(sa.size * sb.size);
  }

  // The weighted overlap of layout[i] as shape `k` at `at` with the others,
  // given up (returning at least `enough`) once it reaches `enough`.
  double weightedOverlap(const std::vector<PlacedShape>& layout, size_t i, int k, IntPoint at,
                         const std::vector<double>& weights, double enough) const {
    const size_t n = layout.size();
    const Shape& moving = shapes_[layout[i].part][k];
    double total = 0;
    for (size_t j = 0; j < n && total < enough; ++j) {
      if (j == i) continue;
      const Shape& other = shapes_[layout[j].part][layout[j].shape];
      if (!shapesColliding(moving, at, other, layout[j].at)) continue;
      total += weights[i * n + j] * proxy(moving, at, other, layout[j].at);
    }
    return total;
  }

  // A place and rotation for a sampled move, and its weighted overlap.
  struct Sample {
    int shape;
    IntPoint at;
    double score;
  };

  // The compaction's move by sampling, as sparrow does: places drawn at
  // random near the part (within its own size) and anywhere on its bed or
  // another, in random rotations; the few best (and apart) refined by
  // coordinate descent, the best of them once more with finer steps. The
  // weighted overlap proxy decides. Each place costs a few microseconds,
  // no no-fit polygon: those of unique panels, built for each pair met,
  // held the moves to about 50 a second among 200 of them (3000 now).
  void sampledMove(std::vector<PlacedShape>& layout, size_t i, const Lanes& lanes, const std::vector<double>& weights,
                   std::mt19937& random) {
    const int part = layout[i].part;
    const Shape& current = shapes_[part][layout[i].shape];
    const IntPoint centre = centreOf(layout[i]);
    const cInt halfX = (current.maxX - current.minX) / 2, halfY = (current.maxY - current.minY) / 2;
    // Where shape k's reference point may be on `lane`: its inner-fit rectangle.
    const auto fitOn = [&](int k, size_t lane) {
      const Shape& s = shapes_[part][k];
      return Box{lanes[lane].first - s.minX, -s.minY, lanes[lane].second - s.maxX, height_ - s.maxY};
    };
    const auto laneOf = [&](int k, IntPoint at) {
      return std::min(static_cast<size_t>(sheetOf(at.X + shapes_[part][k].maxX)), lanes.size() - 1);
    };
    const size_t here = laneOf(layout[i].shape, layout[i].at);
    std::vector<Sample> best;  // the kDescents best, apart by kDistinctShare of minSize, best first
    const cInt minSize = std::max<cInt>(1, std::min(current.maxX - current.minX, current.maxY - current.minY));
    const auto bound = [&] { return best.size() < kDescents ? kNoLimit : best.back().score; };
    const auto report = [&](const Sample& sample) {
      for (auto it = best.begin(); it != best.end(); ++it) {
        if (std::abs(it->at.X - sample.at.X) + std::abs(it->at.Y - sample.at.Y) < minSize * kDistinctShare &&
            it->shape == sample.shape) {
          if (sample.score < it->score) *it = sample;
          std::sort(best.begin(), best.end(), [](const Sample& a, const Sample& b) { return a.score < b.score; });
          return;
        }
      }
      if (best.size() == kDescents && sample.score >= best.back().score) return;
      if (best.size() == kDescents) best.pop_back();
      best.insert(std::upper_bound(best.begin(), best.end(), sample,
                                   [](const Sample& a, const Sample& b) { return a.score < b.score; }),
                  sample);
    };
    const int rotations = static_cast<int>(shapes_[part].size());
    report(
        {layout[i].shape, layout[i].at, weightedOverlap(layout, i, layout[i].shape, layout[i].at, weights, kNoLimit)});
    if (best.front().score == 0) return;
    for (int sample = 0; sample < kNearSamples + kFarSamples; ++sample) {
      const int k = static_cast<int>(random() % rotations);
      const bool near = sample < kNearSamples;
      Box box = fitOn(k, near ? here : random() % lanes.size());
      if (near) {
        const Shape& s = shapes_[part][k];
        const cInt atX = centre.X - (s.minX + s.maxX) / 2, atY = centre.Y - (s.minY + s.maxY) / 2;
        box = {std::max(box[0], atX - halfX), std::max(box[1], atY - halfY), std::min(box[2], atX + halfX),
               std::min(box[3], atY + halfY)};
      }
      if (box[2] < box[0] || box[3] < box[1]) continue;
      const IntPoint p{std::uniform_int_distribution<cInt>(box[0], box[2])(random),
                       std::uniform_int_distribution<cInt>(box[1], box[3])(random)};
      report({k, p, weightedOverlap(layout, i, k, p, weights, bound())});
    }
    // Coordinate descent (sparrow's): two places, one step either way along
    // a random axis; a place no worse is taken; a better one lengthens the
    // step by a tenth, else it halves and the axis changes (on a diagonal,
    // each of its two steps by the square root of that).
    const auto descend = [&](Sample from, double firstShare, double lastShare) {
      const Box fit = fitOn(from.shape, laneOf(from.shape, from.at));
      // Steps never longer than the room to move in (a run of successes would grow them without end).
      const double widest = std::max<double>(1, fit[2] - fit[0]), tallest = std::max<double>(1, fit[3] - fit[1]);
      double stepX = std::min(widest, minSize * firstShare), stepY = std::min(tallest, minSize * firstShare);
      const double last = std::max(1.0, minSize * lastShare);
      int axis = static_cast<int>(random() % 4);
      while ((stepX >= last || stepY >= last) && from.score > 0) {
        static constexpr int kAxes[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
        const cInt dx = std::llround(kAxes[axis][0] * stepX), dy = std::llround(kAxes[axis][1] * stepY);
        bool better = false;
        if (dx != 0 || dy != 0) {  // a step rounded to nothing is a failed one
          Sample tried[2];
          for (int side = 0; side < 2; ++side) {
            const int sign = side ? -1 : 1;
            const IntPoint p{std::clamp(from.at.X + sign * dx, fit[0], fit[2]),
                             std::clamp(from.at.Y + sign * dy, fit[1], fit[3])};
            tried[side] = {from.shape, p, weightedOverlap(layout, i, from.shape, p, weights, from.score)};
          }
          const Sample& pick = tried[1].score < tried[0].score ? tried[1] : tried[0];
          better = pick.score < from.score;
          if (pick.score <= from.score) from = pick;
        }
        const double factor = better ? 1.1 : 0.5;
        if (axis != 1) stepX = std::min(widest, stepX * (axis == 0 ? factor : std::sqrt(factor)));
        if (axis != 0) stepY = std::min(tallest, stepY * (axis == 1 ? factor : std::sqrt(factor)));
        if (!better) axis = static_cast<int>(random() % 4);
      }
      return from;
    };
    for (const Sample& start : std::vector<Sample>(best)) report(descend(start, 0.25, 0.02));
    const Sample chosen = descend(best.front(), 0.01, 0.001);
    layout[i] = {part, chosen.shape, chosen.at};
  }

  // The exact check that ends a sampled separation: no two cores overlap
  // (colliding() misses overlaps whose every crossing is at a vertex).
  bool apart(const std::vector<PlacedShape>& layout) const {
    for (size_t i = 0; i < layout.size(); ++i) {
      const Shape& a = shapes_[layout[i].part][layout[i].shape];
      for (size_t j = i + 1; j < layout.size(); ++j) {
        const Shape& b = shapes_[layout[j].part][layout[j].shape];
        if (boxesApart(a, layout[i].at, b, layout[j].at)) continue;
        for (const Path& path : intersectionOf(a.core, layout[i].at, b.core, layout[j].at)) {
          if (std::abs(ClipperLib::Area(path)) > 1.0) return false;
        }
      }
    }
    return true;
  }

  Point2 extentOf(size_t part) const {
    const Shape& s = shapes_[part].front();
    return {(s.maxX - s.minX) / kScale, (s.maxY - s.minY) / kScale};
  }

  // A strip long enough for every part side by side.
  cInt stripBound() const {
    cInt total = 0;
    for (const auto& shapes : shapes_) {
      cInt longest = 0;
      for (const Shape& s : shapes) longest = std::max({longest, s.maxX - s.minX, s.maxY - s.minY});
      total += longest + toInt(options_.spacing) + 1;
    }
    return total;
  }

  // The no-fit polygon of a moving shape against a placed one (at the
  // origin): the reference positions where the two grown shapes overlap.
  // Built whole from convex pieces and kept for the two shapes' classes
  // (instances repeat items many times), up to kMostSharedPoints.
  const Paths& sharedNoFitPolygon(int movingPart, int movingShape, int placedPart, int placedShape) {
    const auto key = std::make_pair(classOf_[movingPart][movingShape], classOf_[placedPart][placedShape]);
    auto it = shared_.find(key);
    if (it == shared_.end()) {
      if (sharedPoints_ > kMostSharedPoints) shared_.clear(), sharedPoints_ = 0;  // bounded memory
      std::vector<Paths> sums;
      for (const Path& a : shapes_[placedPart][placedShape].pieces) {
        Paths sum;
        for (const Path& b : shapes_[movingPart][movingShape].negatedPieces) sum.push_back(convexMinkowskiSum(a, b));
        sums.push_back(std::move(sum));
      }
      it = shared_.emplace(key, unionOf(std::move(sums))).first;
      for (const Path& path : it->second) sharedPoints_ += path.size();
    }
    return it->second;
  }

  // The whole no-fit polygon of any two shapes, at the origin. Without
  // convex pieces: the Minkowski sum of the boundaries, plus the two cases
  // where one shape holds the other.
  const Paths& wholeNoFitPolygon(int movingPart, int movingShape, int placedPart, int placedShape) {
    if (!shapes_[placedPart][placedShape].pieces.empty() && !shapes_[movingPart][movingShape].pieces.empty()) {
      return sharedNoFitPolygon(movingPart, movingShape, placedPart, placedShape);
    }
    const auto key = std::make_tuple(movingPart, movingShape, placedPart, placedShape);
    auto it = wholes_.find(key);
    if (it == wholes_.end()) {
      const Shape& fixed = shapes_[placedPart][placedShape];
      const Shape& moving = shapes_[movingPart][movingShape];
      Paths whole;
      ClipperLib::MinkowskiSum(moving.negated, fixed.grown, whole, true);
      whole.push_back(translatedPath(fixed.grown, {-moving.grown[0].X, -moving.grown[0].Y}));
      whole.push_back(translatedPath(moving.negated, {fixed.grown[0].X, fixed.grown[0].Y}));
      it = wholes_.emplace(key, unionOf({std::move(whole)})).first;
    }
    return it->second;
  }

  // Turning two shapes together turns their no-fit polygon: one is kept for
  // the four quarter turns of a pair (a quarter of the work and memory for
  // the shapes with copies, which obstacles() meets again and again). `paths` is the no-fit
  // polygon of the moving shape turned back by `turns` quarter turns against
  // the placed part in its first quarter-turn rotation; turned by `turns`,
  // it is the one asked for. Turned outlines are exact on the grid, but the
  // grown shapes built from them may differ from turned grown shapes by up
  // to kSimplifyTolerance (where CleanPolygon starts); both still hold the
  // outline grown by half the spacing, so the final exact checks hold, and
  // a pair may only look a little more or less apart than it is.
  struct TurnedRegion {
    const Paths* paths;
    int turns;
  };
  TurnedRegion noFitPolygonOf(int movingPart, int movingShape, int placedPart, int placedShape) {
    const int movingQuarter = quarterOf_[movingPart][movingShape], placedQuarter = quarterOf_[placedPart][placedShape];
    if (movingQuarter >= 0 && placedQuarter >= 0) {
      const int first = firstQuarter_[placedPart];
      const int turns = (placedQuarter - first + 4) % 4;
      const int moving = shapeAtQuarter_[movingPart][(movingQuarter - turns + 4) % 4];
      if (moving >= 0) {
        return {&wholeNoFitPolygon(movingPart, moving, placedPart, shapeAtQuarter_[placedPart][first]), turns};
      }
    }
    return {&wholeNoFitPolygon(movingPart, movingShape, placedPart, placedShape), 0};
  }
  static IntPoint turned(IntPoint p, int turns) {
    for (int t = 0; t < turns % 4; ++t) p = {-p.Y, p.X};
    return p;
  }
  // The no-fit polygon for a placed part at `at`.
  static Paths placedRegion(const TurnedRegion& region, IntPoint at) {
    Paths out;
    out.reserve(region.paths->size());
    for (const Path& path : *region.paths) {
      Path& placed = out.emplace_back();
      placed.reserve(path.size());
      for (const IntPoint& p : path) {
        const IntPoint q = turned(p, region.turns);
        placed.push_back({q.X + at.X, q.Y + at.Y});
      }
    }
    return out;
  }

  void put(Sheet& sheet, const PlacedShape& spot) {
    sheet.parts.push_back(spot);
    sheet.freeArea -= area_[spot.part];
    ClipperLib::Clipper clipper;
    clipper.AddPaths(sheet.occupied, ClipperLib::ptSubject, true);
    clipper.AddPath(translatedPath(shapes_[spot.part][spot.shape].grown, spot.at), ClipperLib::ptClip, true);
    clipper.Execute(ClipperLib::ctUnion, sheet.occupied, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  }

  // Where the centre of a disc of `radius` can be: on the area (grown by what
  // a grown shape may overhang it) and clear of every placed shape.
  const CellCover& room(Sheet& sheet, cInt radius) {
    const Box bounds = roomBounds();
    auto it = sheet.room.find(radius);
    if (it != sheet.room.end()) {
      Sheet::Room& room = it->second;
      if (room.upTo < sheet.parts.size()) {
        // Eroding the free area after a part is placed takes the part, grown
        // by the erosion, out of the region: that, for the parts placed since,
        // instead of eroding the whole free area again (it was half the time
        // of a first layout of 600 panels).
        ClipperLib::ClipperOffset offset(2.0, roomScale_.arcTolerance);
        for (size_t i = room.upTo; i < sheet.parts.size(); ++i) {
          const PlacedShape& q = sheet.parts[i];
          offset.AddPath(translatedPath(shapes_[q.part][q.shape].grown, q.at), ClipperLib::jtRound,
                         ClipperLib::etClosedPolygon);
        }
        Paths taken;
        offset.Execute(taken, static_cast<double>(radius - kRoomSlack));
        ClipperLib::Clipper clipper;
        clipper.AddPaths(room.centres, ClipperLib::ptSubject, true);
        clipper.AddPaths(taken, ClipperLib::ptClip, true);
        clipper.Execute(ClipperLib::ctDifference, room.centres, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
        room.cover = CellCover(room.centres, bounds, roomScale_.cell);
        room.upTo = sheet.parts.size();
      }
      return room.cover;
    }
    Paths free{Path{{bounds[0], bounds[1]}, {bounds[2], bounds[1]}, {bounds[2], bounds[3]}, {bounds[0], bounds[3]}}};
    if (!sheet.occupied.empty()) {
      ClipperLib::Clipper clipper;
      clipper.AddPaths(free, ClipperLib::ptSubject, true);
      clipper.AddPaths(sheet.occupied, ClipperLib::ptClip, true);
      clipper.Execute(ClipperLib::ctDifference, free, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
    }
    ClipperLib::ClipperOffset offset(2.0, roomScale_.arcTolerance);
    offset.AddPaths(free, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
    Paths eroded;
    offset.Execute(eroded, -static_cast<double>(radius - kRoomSlack));
    CellCover cover(eroded, bounds, roomScale_.cell);
    return sheet.room.emplace(radius, Sheet::Room{std::move(eroded), sheet.parts.size(), std::move(cover)})
        .first->second.cover;
  }

  // The box that holds every room region: the area grown by what a grown shape may overhang it.
  Box roomBounds() const {
    const cInt overhang = toInt(options_.spacing / 2 + 2 * kSimplifyTolerance);
    return {-overhang, -overhang, width_ + overhang, height_ + overhang};
  }

  std::optional<PlacedShape> bestSpot(int part, Sheet& sheet, int only) {
    std::optional<PlacedShape> best;
    for (int k = 0; k < static_cast<int>(shapes_[part].size()); ++k) {
      if (only >= 0 && k != only) continue;
      const Shape& moving = shapes_[part][k];
      const CellCover* centres = moving.centres.empty() ? nullptr : &room(sheet, moving.radius);
      if (centres && centres->empty()) continue;  // no room for this rotation's discs
      // Inner-fit rectangle: reference positions keeping the true outline on the area.
      const cInt x0 = -moving.minX, y0 = -moving.minY;
      cInt x1 = width_ - moving.maxX, y1 = height_ - moving.maxY;
      if (x1 < x0 || y1 < y0) continue;
      // A part exactly as wide (or high) as the area has a one-line inner-fit
      // region, which Clipper would drop: give it one grid unit (1e-4 in).
      x1 = std::max(x1, x0 + 1);
      y1 = std::max(y1, y0 + 1);
      // A box of reference points might hold a feasible one only if, for
      // each disc, the disc's centres for it meet the room.
      const auto mightFit = [&](const Box& b) {
        if (!centres) return true;
        return std::all_of(moving.centres.begin(), moving.centres.end(), [&](const IntPoint& c) {
          return centres->meets({b[0] + c.X, b[1] + c.Y, b[2] + c.X, b[3] + c.Y});
        });
      };
      const IntPoint centre = centres ? moving.centres.front() : IntPoint{0, 0};
      // The reference points to search: the inner-fit rectangle, cut down to
      // the cells where the disc's centre has room. Every feasible point is
      // in them, so the feasible region is found whole.
      std::vector<Box> search;
      for (const Box& cells : centres ? centres->runs() : std::vector<Box>{{x0, y0, x1, y1}}) {
        Box b = cells;
        if (centres) {
          b = {std::max(x0, cells[0] - centre.X), std::max(y0, cells[1] - centre.Y), std::min(x1, cells[2] - centre.X),
               std::min(y1, cells[3] - centre.Y)};
          if (b[0] > b[2] || b[1] > b[3]) continue;
          // Like the inner-fit rectangle, never thinner than one grid unit.
          b[2] = std::max(b[2], b[0] + 1), b[3] = std::max(b[3], b[1] + 1);
        }
        search.push_back(b);
      }
      if (search.empty()) continue;
      // Bottom-left: nothing right of a point an earlier rotation found can
      // be better, so the no-fit polygons only matter up to there. (Searching
      // windows from the left, doubling, was measured slower: 14 s against 7 s
      // for 200 star panels.)
      cInt right = std::numeric_limits<cInt>::min();
      for (const Box& b : search) right = std::max(right, b[2]);
      if (best) right = std::min(right, rankOf(*best).first - rankOffset(moving).first);
      if (auto spot = bestLeftOf(part, k, sheet, search, right, mightFit, best)) best = spot;
    }
    return best;
  }

  // The bottom-left point for shape k of `part` among the search boxes' points
  // not right of `upTo`, better than `best`; nothing when there is none.
  template <typename MightFit>
  std::optional<PlacedShape> bestLeftOf(int part, int k, const Sheet& sheet, const std::vector<Box>& search, cInt upTo,
                                        const MightFit& mightFit, const std::optional<PlacedShape>& best) {
    const Shape& moving = shapes_[part][k];
    ClipperLib::Clipper clipper;
    bool any = false;
    for (const Box& b : search) {
      if (b[0] > upTo) continue;
      const cInt x1 = std::max(std::min(b[2], upTo), b[0] + 1);
      clipper.AddPath(Path{{b[0], b[1]}, {x1, b[1]}, {x1, b[3]}, {b[0], b[3]}}, ClipperLib::ptSubject, true);
      any = true;
    }
    if (!any) return std::nullopt;
    // A box of reference points matters only if it reaches left of `upTo` and might hold a feasible point.
    const auto matters = [&](const Box& b) { return b[0] <= upTo && mightFit(b); };
    clipper.AddPaths(obstacles(part, k, sheet.parts, matters), ClipperLib::ptClip, true);
    Paths feasible;
    clipper.Execute(ClipperLib::ctDifference, feasible, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
    std::vector<IntPoint> candidates;
    for (const Path& region : feasible) candidates.insert(candidates.end(), region.begin(), region.end());
    // Bottom-left: leftmost, then lowest; the first that an exact check
    // confirms, so that no rounding in the no-fit polygons can let parts overlap.
    std::sort(candidates.begin(), candidates.end(),
              [](const IntPoint& a, const IntPoint& b) { return a.X < b.X || (a.X == b.X && a.Y < b.Y); });
    for (const IntPoint& p : candidates) {
      if (best && rankOf({part, k, p}) >= rankOf(*best)) break;
      if (clear(moving, p, sheet.parts)) return PlacedShape{part, k, p};
    }
    return std::nullopt;
  }

  // The reference points where shape k of `part` would overlap one of
  // `others`: the union of their no-fit polygons, built only where a box of
  // reference points `matters`.
  template <typename Matters>
  Paths obstacles(int part, int k, const std::vector<PlacedShape>& others, const Matters& matters) {
    const Shape& moving = shapes_[part][k];
    std::vector<Paths> noFitPolygons;
    for (const PlacedShape& q : others) {
      const Shape& fixed = shapes_[q.part][q.shape];
      // The no-fit polygon lies in this box.
      if (!matters({q.at.X + fixed.grownMinX - moving.grownMaxX, q.at.Y + fixed.grownMinY - moving.grownMaxY,
                    q.at.X + fixed.grownMaxX - moving.grownMinX, q.at.Y + fixed.grownMaxY - moving.grownMinY})) {
        continue;
      }
      if (!fixed.pieces.empty() && !moving.pieces.empty()) {
        // The union over pairs of convex pieces of their linear-time sums is
        // the whole no-fit polygon, either shape inside the other included.
        // Only the part of it in boxes that matter is built. Each
        // pair's sums are united first, which Clipper does faster than one
        // union of everything.
        if (classSize_[classOf_[part][k]] > 1 && classSize_[classOf_[q.part][q.shape]] > 1) {
          // Both shapes have copies: this no-fit polygon will be met again.
          noFitPolygons.push_back(placedRegion(noFitPolygonOf(part, k, q.part, q.shape), q.at));
          continue;
        }
        std::vector<Paths> sums;  // one per piece of the placed shape
        for (size_t a = 0; a < fixed.pieces.size(); ++a) {
          const Box& fa = fixed.pieceBoxes[a];
          Paths sum;
          for (size_t b = 0; b < moving.negatedPieces.size(); ++b) {
            const Box& mb = moving.negatedPieceBoxes[b];
            if (!matters(
                    {q.at.X + fa[0] + mb[0], q.at.Y + fa[1] + mb[1], q.at.X + fa[2] + mb[2], q.at.Y + fa[3] + mb[3]})) {
              continue;
            }
            sum.push_back(translatedPath(convexMinkowskiSum(fixed.pieces[a], moving.negatedPieces[b]), q.at));
          }
          if (!sum.empty()) sums.push_back(std::move(sum));
        }
        if (!sums.empty()) noFitPolygons.push_back(unionOf(std::move(sums)));
        continue;
      }
      noFitPolygons.push_back(placedRegion(noFitPolygonOf(part, k, q.part, q.shape), q.at));
    }
    return unionOf(std::move(noFitPolygons));
  }

  // Bottom-left across rotations compares where the parts themselves would
  // be (the lower left corner of their box), not their reference points:
  // smaller is better. Measured on six ESICUP instances, 5 s each: this beat
  // reference points on four (dagli 80.4% against 76.4%) and lost on none;
  // the right edge instead of the left lost on two.
  static std::pair<cInt, cInt> rankOffset(const Shape& shape) { return {shape.minX, shape.minY}; }
  std::pair<cInt, cInt> rankOf(const PlacedShape& spot) const {
    const auto offset = rankOffset(shapes_[spot.part][spot.shape]);
    return {spot.at.X + offset.first, spot.at.Y + offset.second};
  }

  // Whether the grown shape at `at` keeps off every placed grown shape (touching allowed).
  bool clear(const Shape& moving, IntPoint at, const std::vector<PlacedShape>& sheet) const {
    for (const PlacedShape& q : sheet) {
      if (overlapping(overlap(moving, at, shapes_[q.part][q.shape], q.at), moving)) return false;
    }
    return true;
  }

  // Whether the boxes of two placed grown shapes are apart (touching counts as apart).
  static bool boxesApart(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) {
    return atA.X + a.grownMaxX <= atB.X + b.grownMinX || atB.X + b.grownMaxX <= atA.X + a.grownMinX ||
           atA.Y + a.grownMaxY <= atB.Y + b.grownMinY || atB.Y + b.grownMaxY <= atA.Y + a.grownMinY;
  }

  // What two placed grown shapes have in common (nothing when their boxes are apart).
  Paths common(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) const {
    if (boxesApart(a, atA, b, atB)) return {};
    return intersectionOf(a.grown, atA, b.grown, atB);
  }
  static Paths intersectionOf(const Path& a, IntPoint atA, const Path& b, IntPoint atB) {
    ClipperLib::Clipper clipper;
    clipper.AddPath(translatedPath(a, atA), ClipperLib::ptSubject, true);
    clipper.AddPath(translatedPath(b, atB), ClipperLib::ptClip, true);
    Paths out;
    clipper.Execute(ClipperLib::ctIntersection, out, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
    return out;
  }
  double overlap(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) const {
    double area = 0;
    for (const Path& c : common(a, atA, b, atB)) area += std::abs(ClipperLib::Area(c));
    return area;
  }
  // Whether an overlap is beyond rounding along the edges of `shape`.
  static bool overlapping(double area, const Shape& shape) {
    return area > 4.0 * static_cast<double>(shape.grown.size());
  }
  const std::vector<NestingPart>& parts_;
  const NestingOptions& options_;
  const RoomScale roomScale_;
  std::vector<std::vector<Shape>> shapes_;
  // Shapes that are exact copies share a class (one per part and rotation).
  std::vector<std::vector<int>> classOf_;
  std::vector<int> classSize_;
  // Each shape's rotation in quarter turns (0-3; -1 when it is not one), and
  // per part the shape at each quarter turn (-1: not allowed) and its first.
  std::vector<std::vector<int>> quarterOf_;
  std::vector<std::array<int, 4>> shapeAtQuarter_;
  std::vector<int> firstQuarter_;
  std::map<std::pair<int, int>, Paths> shared_;  // (moving class, placed class) -> no-fit polygon
  size_t sharedPoints_ = 0;
  std::map<std::tuple<int, int, int, int>, Paths> wholes_;  // no-fit polygons without convex pieces
  std::vector<double> area_;                                // each part's grown area, square grid units
  cInt width_ = 0, height_ = 0;
  cInt pitch_ = 0;  // beds side by side for the compaction (lanesUpTo()); 0 in the strip
};

// The share of the time budget (and of a cap on layouts) that the sequence
// search has in the strip; the compaction has the rest.
constexpr double kSequenceShare = 0.15;

// Smaller is better: fewer sheets, then less used of the last sheet (or a shorter strip).
std::pair<int, double> cost(const NestingResult& result, const std::vector<NestingPart>& parts) {
  if (result.sheets == 0) return {0, 0.0};
  double lastExtent = 0;
  for (const auto& p : result.placements) {
    if (p.sheet != result.sheets) continue;
    for (const Point2& v : placedOutline(parts[p.part], p)) lastExtent = std::max(lastExtent, v.x());
  }
  return {result.sheets, lastExtent};
}

}  // namespace

Point2 rotatedPoint(const Point2& p, double degrees) {
  // Quarter turns exactly, so that 90-degree layouts stay on the grid.
  double c = std::cos(degrees * std::numbers::pi / 180.0), s = std::sin(degrees * std::numbers::pi / 180.0);
  const double quarter = degrees / 90.0;
  if (std::abs(quarter - std::round(quarter)) < 1e-12) {
    static constexpr int kCos[] = {1, 0, -1, 0}, kSin[] = {0, 1, 0, -1};
    const int k = ((static_cast<int>(std::lround(quarter)) % 4) + 4) % 4;
    c = kCos[k];
    s = kSin[k];
  }
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

double polygonArea(const Polygon2& polygon) { return geometry::signedArea(polygon); }

Polygon2 placedOutline(const NestingPart& part, const PartPlacement& placement) {
  Polygon2 out = rotated(part.outline, placement.rotation);
  for (Point2& p : out) p += Point2(placement.x, placement.y);
  return out;
}

namespace {

// The progress lines of searches running side by side: remarks from the
// first search only, and an improvement only when it beats every search's
// best so far.
class SharedProgress {
 public:
  explicit SharedProgress(const std::function<void(const std::string&)>& out) : out_(out) {}
  void remark(unsigned search, const std::string& line) {
    const std::lock_guard lock(mutex_);
    if (out_ && search == 0) out_(line);
  }
  void improved(const std::pair<int, double>& cost, const std::string& line) {
    const std::lock_guard lock(mutex_);
    if (best_ && cost >= *best_) return;
    best_ = cost;
    if (out_) out_(line);
  }

 private:
  const std::function<void(const std::string&)>& out_;
  std::mutex mutex_;
  std::optional<std::pair<int, double>> best_;
};

// One search: the first layout, then the sequence search and, in the strip,
// the compaction, following the course `seed` sets.
NestingResult searchLayout(const std::vector<NestingPart>& parts, const NestingOptions& options, unsigned search,
                           SharedProgress& progress) {
  Packer packer(parts, options);
  // The first layout: assembly order, or for free order the largest parts first.
  std::vector<int> sequence(parts.size());
  std::iota(sequence.begin(), sequence.end(), 0);
  std::stable_sort(sequence.begin(), sequence.end(), [&](int a, int b) { return parts[a].order < parts[b].order; });
  if (options.order == OrderMode::Free) {
    std::stable_sort(sequence.begin(), sequence.end(), [&](int a, int b) {
      return std::abs(polygonArea(parts[a].outline)) > std::abs(polygonArea(parts[b].outline));
    });
  }
  // Window: start from the strict layout (nothing moves) and accept only
  // layouts in which no part is cut more than `window` places from its order.
  auto withinWindow = [&](const NestingResult& result) {
    if (options.order != OrderMode::Window) return true;
    for (size_t i = 0; i < result.placements.size(); ++i) {
      if (std::abs(static_cast<int>(i) - parts[result.placements[i].part].order) > options.window) return false;
    }
    return true;
  };
  std::vector<int> shapeOf(parts.size(), -1);  // forced rotations (index), -1: the best of all
  // The first layout can take many seconds (25 s for 100 long strips): say so.
  progress.remark(search, fmt::format("first layout of {} parts", parts.size()));
  packer.onProgress = [&](size_t placed, size_t of, size_t sheets) {
    progress.remark(search, fmt::format("first layout: {} of {} parts placed, {} sheet{}", placed, of, sheets,
                                        sheets == 1 ? "" : "s"));
  };
  NestingResult best = *packer.pack(sequence, options.order == OrderMode::Window ? OrderMode::Strict : options.order);
  packer.onProgress = nullptr;
  packer.accept();
  auto bestCost = cost(best, parts);
  progress.improved(bestCost, fmt::format("{} sheet{}, last sheet {:.2f} in long; improving for {} s", bestCost.first,
                                          bestCost.first == 1 ? "" : "s", bestCost.second, options.seconds));
  int evaluations = 1;
  // Improvement: swap two parts of the sequence (within the window when the
  // order is bounded), or fix or free one part's rotation, and keep the
  // change when the layout is no worse.
  // In free order, the sequence search has the first part of the budget and
  // the compaction the rest.
  const bool compaction = options.order == OrderMode::Free && parts.size() > 1;
  const double sequenceShare = compaction ? kSequenceShare : 1.0;
  const auto start = std::chrono::steady_clock::now();
  std::mt19937 random(options.seed + search);
  if (options.order != OrderMode::Strict && parts.size() > 1) {
    const auto deadline = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                      std::chrono::duration<double>(sequenceShare * options.seconds));
    const int lastEvaluation = static_cast<int>(std::ceil(sequenceShare * options.evaluations));
    while (std::chrono::steady_clock::now() < deadline && (options.evaluations <= 0 || evaluations < lastEvaluation)) {
      std::vector<int> trial = sequence, trialShapes = shapeOf;
      const size_t i = random() % trial.size();
      size_t j = i;
      const unsigned move = random() % 10;
      if (move < 3) {
        // Fix the part's rotation, or free it again.
        const int part = trial[i];
        const int choice = static_cast<int>(random() % (parts[part].rotations.size() + 1)) - 1;
        if (choice == trialShapes[part]) continue;
        trialShapes[part] = choice;
      } else {
        // Swap with a neighbour (small steps) or with any part.
        const long span = options.order == OrderMode::Window ? std::max(1, options.window)
                          : move < 6                         ? 3
                                                             : static_cast<long>(trial.size());
        j = std::clamp<long>(static_cast<long>(i) + static_cast<long>(random() % (2 * span + 1)) - span, 0,
                             static_cast<long>(trial.size()) - 1);
        if (i == j) continue;
        std::swap(trial[i], trial[j]);
      }
      // The parts before the first changed one are placed as before.
      // Without a cap on layouts, a trial that would end past the deadline is given up.
      auto packed = packer.pack(trial, options.order, std::min(i, j), trialShapes,
                                options.evaluations > 0 ? std::chrono::steady_clock::time_point::max() : deadline);
      if (!packed) break;
      NestingResult result = std::move(*packed);
      ++evaluations;
      const auto trialCost = cost(result, parts);
      if (trialCost <= bestCost && withinWindow(result)) {
        if (trialCost < bestCost) {
          progress.improved(trialCost, fmt::format("{} sheet{}, last sheet {:.2f} in long", trialCost.first,
                                                   trialCost.first == 1 ? "" : "s", trialCost.second));
        }
        best = std::move(result);
        bestCost = trialCost;
        sequence = std::move(trial);
        shapeOf = std::move(trialShapes);
        packer.accept();
      }
    }
  }
  if (compaction) {
    const auto deadline = start + std::chrono::duration<double>(options.seconds);
    const auto goOn = [&] {
      return std::chrono::steady_clock::now() < deadline &&
             (options.evaluations <= 0 || evaluations < options.evaluations);
    };
    // Progress while compacting: the layout so far (its exact check comes at the end).
    const auto shorter = [&](int sheets, double length) {
      progress.improved({sheets, length}, options.strip
                                              ? fmt::format("compacting: strip {:.2f} long", length)
                                              : fmt::format("compacting: {} sheet{}, last sheet {:.2f} in long", sheets,
                                                            sheets == 1 ? "" : "s", length));
    };
    NestingResult compacted = packer.compact(random, goOn, evaluations, shorter);
    // The compaction lets grown shapes reach into each other by a few grid
    // units; the layout is kept only if the true outlines keep the spacing
    // (within layoutProblems' tolerance).
    if (cost(compacted, parts) < cost(best, parts) && layoutProblems(parts, compacted, options).empty()) {
      best = std::move(compacted);
    }
  }
  best.evaluations = evaluations;
  return best;
}

}  // namespace

void checkNestingParts(const std::vector<NestingPart>& parts) {
  for (const auto& part : parts) {
    if (part.outline.size() < 3 || std::abs(polygonArea(part.outline)) <= 0) {
      throw std::invalid_argument(fmt::format("{}: the outline is not a polygon with area", part.name));
    }
    if (part.rotations.empty()) throw std::invalid_argument(fmt::format("{}: no allowed rotation", part.name));
  }
}

NestingResult nest(const std::vector<NestingPart>& parts, const NestingOptions& options) {
  checkNestingParts(parts);
  // Searches side by side, one per core, each on its own course; the best
  // layout wins (on a tie, the lowest seed's). Strict order has nothing to search.
  const unsigned searches = options.order == OrderMode::Strict || parts.size() < 2 ? 1u
                            : options.threads > 0 ? static_cast<unsigned>(options.threads)
                                                  : std::max(1u, std::thread::hardware_concurrency());
  SharedProgress progress(options.progress);
  std::vector<NestingResult> results(searches);
  std::vector<std::exception_ptr> errors(searches);
  std::vector<std::thread> threads;
  for (unsigned search = 1; search < searches; ++search) {
    threads.emplace_back([&, search] {
      try {
        results[search] = searchLayout(parts, options, search, progress);
      } catch (...) {
        errors[search] = std::current_exception();
      }
    });
  }
  try {
    results[0] = searchLayout(parts, options, 0, progress);
  } catch (...) {
    errors[0] = std::current_exception();
  }
  for (std::thread& thread : threads) thread.join();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
  size_t winner = 0;
  int evaluations = 0;
  for (size_t i = 0; i < results.size(); ++i) {
    evaluations += results[i].evaluations;
    if (cost(results[i], parts) < cost(results[winner], parts)) winner = i;
  }
  NestingResult best = std::move(results[winner]);
  best.evaluations = evaluations;
  for (const auto& part : parts) best.partArea += std::abs(polygonArea(part.outline));
  return best;
}

std::vector<std::string> layoutProblems(const std::vector<NestingPart>& parts, const NestingResult& result,
                                        const NestingOptions& options, double tolerance) {
  std::vector<std::string> problems;
  std::map<int, std::vector<std::pair<int, Path>>> bySheet;
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
    bySheet[placement.sheet].emplace_back(placement.part, reach > 0 ? grown(path, reach, ClipperLib::jtRound) : path);
  }
  for (const auto& [sheet, shapes] : bySheet) {
    for (size_t a = 0; a < shapes.size(); ++a) {
      for (size_t b = a + 1; b < shapes.size(); ++b) {
        ClipperLib::Clipper clipper;
        clipper.AddPath(shapes[a].second, ClipperLib::ptSubject, true);
        clipper.AddPath(shapes[b].second, ClipperLib::ptClip, true);
        Paths common;
        clipper.Execute(ClipperLib::ctIntersection, common, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
        double area = 0;
        for (const Path& p : common) area += std::abs(ClipperLib::Area(p));
        if (area > 1.0) {  // more than 1e-8 square inches
          problems.push_back(fmt::format("sheet {}: {} and {} overlap or are nearer than {} ({:.3g} sq in in common)",
                                         sheet, parts[shapes[a].first].name, parts[shapes[b].first].name,
                                         options.spacing, area / (kScale * kScale)));
        }
      }
    }
  }
  return problems;
}

}  // namespace rotafab::jobs
