#include "jobs/Nesting.h"

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
// Grid units (see Packer::penetrating).
constexpr double kRoundingDepth = 1.5;

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
Path grown(const Path& path, double by, ClipperLib::JoinType join) {
  ClipperLib::ClipperOffset offset(2.0, 0.25 * kScale * 0.001);
  offset.AddPath(path, join, ClipperLib::etClosedPolygon);
  offset.AddPath(path, ClipperLib::jtRound, ClipperLib::etClosedLine);
  Paths out;
  offset.Execute(out, by * kScale);
  if (out.empty()) return path;
  return *std::max_element(out.begin(), out.end(), [](const Path& a, const Path& b) {
    return std::abs(ClipperLib::Area(a)) < std::abs(ClipperLib::Area(b));
  });
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

// The square of the distance from (x, y) to the polygon's boundary (squares:
// the compaction asks this for every candidate place, and a square root per
// edge took a fifth of its time).
double squaredDistanceToBoundary(const Path& polygon, double x, double y) {
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
  return best;
}

double distanceToBoundary(const Path& polygon, double x, double y) {
  return std::sqrt(squaredDistanceToBoundary(polygon, x, y));
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

// Discs of one radius inside a polygon. The largest: a grid search for the
// point farthest from the boundary, refined around the best point, its radius
// the distance from there rounded down to `radiusStep`. Then up to
// `maxDiscs - 1` more of that radius, each at the grid point with room for it
// that is farthest from the centres so far, while that is at least a radius
// away. Every radius is a true distance to the boundary, so every disc is inside.
std::pair<cInt, std::vector<IntPoint>> clearDiscs(const Path& polygon, cInt radiusStep, int maxDiscs = 5) {
  const auto [minX, minY, maxX, maxY] = boxOf(polygon);
  std::vector<std::pair<IntPoint, double>> inside;  // grid points and their distance to the boundary
  IntPoint best{(minX + maxX) / 2, (minY + maxY) / 2};
  double bestDistance = -1;
  auto consider = [&](cInt x, cInt y) {
    if (ClipperLib::PointInPolygon({x, y}, polygon) != 1) return -1.0;
    const double d = distanceToBoundary(polygon, static_cast<double>(x), static_cast<double>(y));
    if (d > bestDistance) bestDistance = d, best = {x, y};
    return d;
  };
  constexpr int kSteps = 24;
  for (int i = 0; i <= kSteps; ++i) {
    for (int j = 0; j <= kSteps; ++j) {
      const IntPoint p{minX + (maxX - minX) * i / kSteps, minY + (maxY - minY) * j / kSteps};
      const double d = consider(p.X, p.Y);
      if (d > 0) inside.emplace_back(p, d);
    }
  }
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
  // is in this region, so only the no-fit polygons near it matter. Emptied
  // whenever a part is placed.
  std::map<cInt, CellCover> room;
};

// The room regions are eroded by this much less than the radius: Clipper's
// round joins put their vertices on the arcs (so their chords only add to the
// region), and the grid rounds by a unit.
constexpr cInt kRoomSlack = 4;

// Strip compaction: the first shortening (2%), the least (0.1%), rounds of
// moves per try, tries per shortening before it is halved, and the most
// candidate places weighed per move and rotation. One move in kGlobalEvery
// may take a part anywhere, the others keep it near where it is. The
// candidates include the corners of the places clear of all others but one,
// for the kMostSkipped heaviest. Chosen on jakobs2, shapes0, shapes1 and swim,
// two seeds each, 60 s (docs/PERFORMANCE.md).
constexpr double kFirstShrink = 0.02, kLeastShrink = 0.001;
constexpr int kRounds = 150, kTriesPerShrink = 5, kGlobalEvery = 4;
constexpr size_t kMostCandidates = 3000, kMostSkipped = 1;
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
    for (size_t index = start; index < sequence.size(); ++index) {
      if (std::chrono::steady_clock::now() > until) return std::nullopt;
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
  // overlaps (a shorter layout: keep it, shorten again) or the rounds run out
  // (go back; after a few such tries, shorten by less).
  // On beds, the beds lie side by side in one row (see pitch_) and the slice
  // comes out of the last bed: what it holds moves to the earlier beds, which
  // fill up, until the last bed is empty and one bed fewer is used.
  // `goOn` says whether the budget allows another move; `moves` counts them;
  // `shorter` hears of each better layout kept (beds, last bed's length in
  // inches). The layout is exact: a try succeeds only when no two grown
  // shapes overlap beyond rounding.
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
                separate(trial, lanes, kRounds, random, goOn, moves)) {
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
      if (separate(trial, lanes, kRounds, random, goOn, moves)) {
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

  // Moves the parts of `layout` (inside `length` x the height) apart by
  // guided local search: overlapping parts move one at a time to where they
  // overlap least, the pairs that keep overlapping weighing more at every
  // round, until nothing overlaps (true) or the rounds or the budget run out
  // (false). Moves stay near the part (within its own size) except one in
  // kGlobalEvery, which may go anywhere.
  bool separate(std::vector<PlacedShape>& layout, const Lanes& lanes, int rounds, std::mt19937& random,
                const std::function<bool()>& goOn, int& moves) {
    const size_t n = layout.size();
    std::vector<double> weights(n * n, 1.0);
    // Whether each pair overlaps, kept from round to round: only the pairs
    // of a part that moved are checked again (checking all pairs took a
    // third of the compaction's time).
    std::vector<char> overlaps(n * n, 0), moved(n, 1);
    for (int round = 0; round < rounds && goOn(); ++round) {
      std::vector<std::pair<size_t, size_t>> pairs;
      for (size_t i = 0; i < n; ++i) {
        for (size_t j = i + 1; j < n; ++j) {
          if (moved[i] || moved[j]) overlaps[i * n + j] = penetrating(layout[i], layout[j]);
          if (overlaps[i * n + j]) pairs.emplace_back(i, j);
        }
      }
      std::fill(moved.begin(), moved.end(), 0);
      if (pairs.empty()) return true;
      // Pairs that overlap now weigh more; old conflicts fade, so that they
      // do not pin parts that have since moved apart.
      for (double& w : weights) w = std::max(1.0, w * 0.95);
      for (const auto& [i, j] : pairs) weights[i * n + j] *= 1.4, weights[j * n + i] *= 1.4;
      std::vector<size_t> overlapped;
      for (const auto& [i, j] : pairs) overlapped.push_back(i), overlapped.push_back(j);
      std::sort(overlapped.begin(), overlapped.end());
      overlapped.erase(std::unique(overlapped.begin(), overlapped.end()), overlapped.end());
      std::shuffle(overlapped.begin(), overlapped.end(), random);
      for (size_t i : overlapped) {
        if (!goOn()) return false;
        const PlacedShape before = layout[i];
        moveToLeastPenetration(layout, i, lanes, weights, random, ++moves % kGlobalEvery != 0);
        moved[i] = layout[i].shape != before.shape || layout[i].at != before.at;
      }
    }
    return false;
  }

  // Moves layout[i] to the place and rotation, inside a strip of `length`,
  // where its weighted penetration into the others is least. Penetration
  // into part j at reference point p: 0 outside their no-fit polygon, else
  // the distance from p to its boundary. Candidates: the inner-fit
  // rectangle's corners, where the part is, the vertices of the no-fit
  // polygons (where it touches one without entering it), and the corners of
  // the places clear of all others or of all but one.
  // `local`: only places that keep the part's box centre within the part's
  // own size of where it is.
  void moveToLeastPenetration(std::vector<PlacedShape>& layout, size_t i, const Lanes& lanes,
                              const std::vector<double>& weights, std::mt19937& random, bool local) {
    const size_t n = layout.size();
    const int part = layout[i].part;
    PlacedShape best = layout[i];
    double bestScore = std::numeric_limits<double>::max();
    const Shape& current = shapes_[part][layout[i].shape];
    const IntPoint centre = centreOf(layout[i]);
    const cInt reach = std::max(current.maxX - current.minX, current.maxY - current.minY);
    // The lanes (beds) to look in: where the part is, and for a move that
    // may go anywhere, one other chosen at random.
    const size_t here = static_cast<size_t>(sheetOf(layout[i].at.X + current.maxX));
    std::vector<size_t> looked{std::min(here, lanes.size() - 1)};
    if (!local && lanes.size() > 1) looked.push_back(random() % lanes.size());
    if (looked.size() == 2 && looked[0] == looked[1]) looked.pop_back();
    for (int k = 0; k < static_cast<int>(shapes_[part].size()); ++k) {
      for (size_t lane : looked) {
        const Shape& moving = shapes_[part][k];
        cInt x0 = lanes[lane].first - moving.minX, x1 = lanes[lane].second - moving.maxX, y0 = -moving.minY,
             y1 = height_ - moving.maxY;
        if (local) {
          const cInt atX = centre.X - (moving.minX + moving.maxX) / 2, atY = centre.Y - (moving.minY + moving.maxY) / 2;
          x0 = std::max(x0, atX - reach), x1 = std::min(x1, atX + reach);
          y0 = std::max(y0, atY - reach), y1 = std::min(y1, atY + reach);
        }
        if (x1 < x0 || y1 < y0) continue;
        const auto inArea = [&](const Box& b) { return b[0] <= x1 && b[2] >= x0 && b[1] <= y1 && b[3] >= y0; };
        struct Obstacle {
          size_t other;
          Paths region;
          Box box;
        };
        std::vector<Obstacle> obstaclesOf;
        for (size_t j = 0; j < n; ++j) {
          if (j == i) continue;
          const PlacedShape& q = layout[j];
          const Shape& fixed = shapes_[q.part][q.shape];
          const Box box{q.at.X + fixed.grownMinX - moving.grownMaxX, q.at.Y + fixed.grownMinY - moving.grownMaxY,
                        q.at.X + fixed.grownMaxX - moving.grownMinX, q.at.Y + fixed.grownMaxY - moving.grownMinY};
          if (!inArea(box)) continue;
          // The same pairs meet again and again: their whole no-fit polygons are kept.
          Paths region = placedRegion(noFitPolygonOf(part, k, q.part, q.shape), q.at);
          if (!region.empty()) obstaclesOf.push_back({j, std::move(region), box});
        }
        std::vector<IntPoint> candidates{{x0, y0}, {x1, y0}, {x0, y1}, {x1, y1}};
        if (k == layout[i].shape && layout[i].at.X >= x0 && layout[i].at.X <= x1) candidates.push_back(layout[i].at);
        for (const Obstacle& o : obstaclesOf) {
          for (const Path& path : o.region) {
            for (const IntPoint& p : path) {
              if (p.X >= x0 && p.X <= x1 && p.Y >= y0 && p.Y <= y1) candidates.push_back(p);
            }
          }
        }
        // The corners of the places clear of all but at most one other part:
        // where the no-fit polygons' boundaries cross.
        const auto cornersClearOf = [&](size_t skip) {
          ClipperLib::Clipper clipper;
          clipper.AddPath(Path{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, ClipperLib::ptSubject, true);
          for (size_t o = 0; o < obstaclesOf.size(); ++o) {
            if (o != skip) clipper.AddPaths(obstaclesOf[o].region, ClipperLib::ptClip, true);
          }
          Paths free;
          clipper.Execute(ClipperLib::ctDifference, free, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
          for (const Path& path : free) candidates.insert(candidates.end(), path.begin(), path.end());
        };
        cornersClearOf(obstaclesOf.size());
        // Skipping, in turn, the parts that weigh most (those the part keeps overlapping).
        std::vector<size_t> heaviest(obstaclesOf.size());
        std::iota(heaviest.begin(), heaviest.end(), 0);
        const size_t skipped = std::min(heaviest.size(), kMostSkipped);
        std::partial_sort(heaviest.begin(), heaviest.begin() + skipped, heaviest.end(), [&](size_t a, size_t b) {
          return weights[i * n + obstaclesOf[a].other] > weights[i * n + obstaclesOf[b].other];
        });
        for (size_t o = 0; o < skipped; ++o) cornersClearOf(heaviest[o]);
        if (candidates.size() > kMostCandidates) {  // a random sample, keeping the first few
          std::shuffle(candidates.begin() + 5, candidates.end(), random);
          candidates.resize(kMostCandidates);
        }
        for (const IntPoint& p : candidates) {
          double score = 0;
          for (const Obstacle& o : obstaclesOf) {
            if (p.X <= o.box[0] || p.X >= o.box[2] || p.Y <= o.box[1] || p.Y >= o.box[3]) continue;
            double depth = penetration(o.region, p);
            if (depth <= kRoundingDepth) depth = 0;
            score += weights[i * n + o.other] * depth;
            if (score >= bestScore) break;
          }
          if (score < bestScore) bestScore = score, best = {part, k, p};
        }
      }
    }
    layout[i] = best;
  }

  // How deep `p` lies inside `region` (outer contours and holes): 0 outside
  // or on the boundary, else the distance to the nearest edge.
  static double penetration(const Paths& region, IntPoint p) {
    int winding = 0;
    for (const Path& path : region) {
      const int inside = ClipperLib::PointInPolygon(p, path);
      if (inside == -1) return 0;  // on the boundary: touching
      if (inside == 1) winding += ClipperLib::Orientation(path) ? 1 : -1;
    }
    if (winding <= 0) return 0;
    double nearest = std::numeric_limits<double>::max();
    for (const Path& path : region) {
      nearest = std::min(nearest, squaredDistanceToBoundary(path, static_cast<double>(p.X), static_cast<double>(p.Y)));
    }
    return std::sqrt(nearest);
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
  // the four quarter turns of a pair (a quarter of the work and memory: most
  // panels are unique and allowed 0/90/180/270). `paths` is the no-fit
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
    sheet.room.clear();
  }

  // Where the centre of a disc of `radius` can be: on the area (grown by what
  // a grown shape may overhang it) and clear of every placed shape.
  const CellCover& room(Sheet& sheet, cInt radius) {
    auto it = sheet.room.find(radius);
    if (it != sheet.room.end()) return it->second;
    const cInt overhang = toInt(options_.spacing / 2 + 2 * kSimplifyTolerance);
    Paths free{Path{{-overhang, -overhang},
                    {width_ + overhang, -overhang},
                    {width_ + overhang, height_ + overhang},
                    {-overhang, height_ + overhang}}};
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
    const Box bounds{-overhang, -overhang, width_ + overhang, height_ + overhang};
    return sheet.room.emplace(radius, CellCover(eroded, bounds, roomScale_.cell)).first->second;
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
    ClipperLib::Clipper clipper;
    clipper.AddPath(translatedPath(a.grown, atA), ClipperLib::ptSubject, true);
    clipper.AddPath(translatedPath(b.grown, atB), ClipperLib::ptClip, true);
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
  // For the compaction: whether `a` lies deeper in `b` than a sliver of
  // rounding (no-fit polygon vertices rounded to the grid reach up to a unit
  // into a neighbour), by the measure its moves minimise: penetration() of
  // its reference point in their no-fit polygon, how far it must move to
  // clear `b`. With the no-fit polygons kept, much cheaper than intersecting
  // the shapes (the final layout is still checked exactly).
  bool penetrating(const PlacedShape& a, const PlacedShape& b) {
    if (boxesApart(shapes_[a.part][a.shape], a.at, shapes_[b.part][b.shape], b.at)) return false;
    const TurnedRegion region = noFitPolygonOf(a.part, a.shape, b.part, b.shape);
    return penetration(*region.paths, turned({a.at.X - b.at.X, a.at.Y - b.at.Y}, 4 - region.turns)) > kRoundingDepth;
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

double polygonArea(const Polygon2& polygon) {
  double twice = 0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Point2& a = polygon[i];
    const Point2& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return twice / 2;
}

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
  NestingResult best = *packer.pack(sequence, options.order == OrderMode::Window ? OrderMode::Strict : options.order);
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
    // The compaction allows slivers of rounding between grown shapes; the
    // layout is kept only if the true outlines keep the spacing exactly.
    if (cost(compacted, parts) < cost(best, parts) && layoutProblems(parts, compacted, options).empty()) {
      best = std::move(compacted);
    }
  }
  best.evaluations = evaluations;
  return best;
}

}  // namespace

NestingResult nest(const std::vector<NestingPart>& parts, const NestingOptions& options) {
  for (const auto& part : parts) {
    if (part.outline.size() < 3 || std::abs(polygonArea(part.outline)) <= 0) {
      throw std::invalid_argument(fmt::format("{}: the outline is not a polygon with area", part.name));
    }
    if (part.rotations.empty()) throw std::invalid_argument(fmt::format("{}: no allowed rotation", part.name));
  }
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
