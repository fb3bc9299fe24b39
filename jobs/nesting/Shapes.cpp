#include "jobs/nesting/Shapes.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <numeric>
#include <stdexcept>
#include <tuple>

#include "core/Polygon2.h"
#include "jobs/nesting/ConvexPieces.h"

namespace rotafab::jobs::nesting {

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

// The piece of largest area, or `otherwise` when there is none.
Path largestOf(const Paths& pieces, const Path& otherwise) {
  if (pieces.empty()) return otherwise;
  return *std::max_element(pieces.begin(), pieces.end(), [](const Path& a, const Path& b) {
    return std::abs(ClipperLib::Area(a)) < std::abs(ClipperLib::Area(b));
  });
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
  return largestOf(out, path);
}

Box boxOf(const Path& path) {
  Box box{std::numeric_limits<cInt>::max(), std::numeric_limits<cInt>::max(), std::numeric_limits<cInt>::min(),
          std::numeric_limits<cInt>::min()};
  for (const IntPoint& p : path) {
    box[0] = std::min(box[0], p.X), box[1] = std::min(box[1], p.Y);
    box[2] = std::max(box[2], p.X), box[3] = std::max(box[3], p.Y);
  }
  return box;
}

RoomScale roomScaleFor(cInt height) {
  const cInt h = std::max<cInt>(height, 3500);
  return {h / 350, h / 70, static_cast<double>(h) / 17500};
}

// Douglas-Peucker (core::simplifiedLine), within `tolerance` grid units of
// the path everywhere, less a unit for the rounding back to the grid.
// Clipper's CleanPolygon was used before: it drops corners one after another,
// each near the line of its neighbours, and along a gentle curve the cuts
// add up (bands' rails lost up to 0.0005 in more than the tolerance, and two
// parts came nearer than the spacing).
Path simplifiedPath(const Path& path, double tolerance) {
  std::vector<Point2> points;
  points.reserve(path.size());
  for (const IntPoint& p : path) points.emplace_back(static_cast<double>(p.X), static_cast<double>(p.Y));
  Path out;
  for (const Point2& p : core::simplifiedLine(points, tolerance - 1, true))
    out.push_back({std::llround(p.x()), std::llround(p.y())});
  return out;
}

Path translatedPath(const Path& path, IntPoint by) {
  Path out;
  out.reserve(path.size());
  for (const IntPoint& p : path) out.push_back({p.X + by.X, p.Y + by.Y});
  return out;
}

namespace {

// `shape` turned by `quarters` quarter turns about the origin: on the grid
// exactly, so the turned shape holds the turned outline as the first holds
// the first (rotated() turns the outline exactly too). A quarter of the
// work of making it again: the offsets by Clipper and the poles were most
// of the cost of a large job's shapes.
Shape turnedShape(const Shape& from, int quarters, double rotation) {
  const auto turn = [quarters](IntPoint p) {
    for (int k = 0; k < quarters; ++k) p = {-p.Y, p.X};
    return p;
  };
  const auto turnPath = [&](const Path& path) {
    Path out;
    out.reserve(path.size());
    for (const IntPoint& p : path) out.push_back(turn(p));
    return out;
  };
  const auto turnBox = [&](cInt minX, cInt minY, cInt maxX, cInt maxY) {
    const IntPoint a = turn({minX, minY}), b = turn({maxX, maxY});
    return Box{std::min(a.X, b.X), std::min(a.Y, b.Y), std::max(a.X, b.X), std::max(a.Y, b.Y)};
  };
  Shape shape;
  shape.rotation = rotation;
  shape.grown = turnPath(from.grown);
  shape.negated = turnPath(from.negated);
  for (const Path& piece : from.pieces) shape.pieces.push_back(turnPath(piece));
  for (const Path& piece : from.negatedPieces) shape.negatedPieces.push_back(turnPath(piece));
  for (const Path& piece : shape.pieces) shape.pieceBoxes.push_back(boxOf(piece));
  for (const Path& piece : shape.negatedPieces) shape.negatedPieceBoxes.push_back(boxOf(piece));
  for (const IntPoint& c : from.centres) shape.centres.push_back(turn(c));
  shape.radius = from.radius;
  for (const Shape::Pole& pole : from.poles) shape.poles.push_back({turn(pole.centre), pole.radius});
  shape.diameter = from.diameter;
  shape.size = from.size;
  shape.core = turnPath(from.core);
  shape.coreBox = boxOf(shape.core);
  std::tie(shape.grownMinX, shape.grownMinY, shape.grownMaxX, shape.grownMaxY) =
      std::tuple_cat(turnBox(from.grownMinX, from.grownMinY, from.grownMaxX, from.grownMaxY));
  std::tie(shape.minX, shape.minY, shape.maxX, shape.maxY) =
      std::tuple_cat(turnBox(from.minX, from.minY, from.maxX, from.maxY));
  return shape;
}

// `from` turned to `shape.rotation` by turning its paths' corners and
// rounding them to the grid, for shapes without what no-fit polygons need
// (`shape` holds the true outline's box already). A rounded corner moves
// less than a grid unit, where the grown path's simplification keeps 2
// units of room (kSimplifyTolerance), so the turned path still holds the
// turned outline grown by half the spacing; the offsets by Clipper, most
// of the cost of a shape, are left out (the bunny's panels at 24 turns:
// 10 s of a 13-s first layout with them).
Shape turnedByRounding(const Shape& from, Shape shape) {
  const double turn = shape.rotation - from.rotation;
  const double c = std::cos(turn * std::numbers::pi / 180.0), s = std::sin(turn * std::numbers::pi / 180.0);
  const auto turned = [&](IntPoint p) {
    const double x = static_cast<double>(p.X), y = static_cast<double>(p.Y);
    return IntPoint{std::llround(c * x - s * y), std::llround(s * x + c * y)};
  };
  const auto turnPath = [&](const Path& path) {
    Path out;
    out.reserve(path.size());
    for (const IntPoint& p : path) out.push_back(turned(p));
    return out;
  };
  shape.grown = turnPath(from.grown);
  for (const IntPoint& p : shape.grown) shape.negated.push_back({-p.X, -p.Y});
  std::tie(shape.grownMinX, shape.grownMinY, shape.grownMaxX, shape.grownMaxY) = std::tuple_cat(boxOf(shape.grown));
  // Less by what the rounding may move a centre and a corner: each under a grid unit's diagonal.
  for (const Shape::Pole& pole : from.poles)
    shape.poles.push_back({turned(pole.centre), std::max(1.0, pole.radius - 2)});
  shape.diameter = std::hypot(static_cast<double>(shape.grownMaxX - shape.grownMinX),
                              static_cast<double>(shape.grownMaxY - shape.grownMinY));
  shape.size = from.size;
  shape.core = turnPath(from.core);
  shape.coreBox = boxOf(shape.core);
  return shape;
}

// The centroid of a polygon's area (the usual shoelace sums).
IntPoint areaCentroid(const Path& path) {
  double twiceArea = 0, x = 0, y = 0;
  for (size_t i = 0; i < path.size(); ++i) {
    const IntPoint& p = path[i];
    const IntPoint& q = path[(i + 1) % path.size()];
    const double cross =
        static_cast<double>(p.X) * static_cast<double>(q.Y) - static_cast<double>(q.X) * static_cast<double>(p.Y);
    twiceArea += cross;
    x += static_cast<double>(p.X + q.X) * cross;
    y += static_cast<double>(p.Y + q.Y) * cross;
  }
  if (twiceArea == 0) return path.empty() ? IntPoint{0, 0} : path.front();
  return {std::llround(x / (3 * twiceArea)), std::llround(y / (3 * twiceArea))};
}

Shape builtShape(const Polygon2& outline, double rotation, double spacing, cInt radiusStep, bool forNoFitPolygons,
                 const Shape* turnedFrom) {
  if (turnedFrom && quarterTurns(rotation) >= 0 && quarterTurns(turnedFrom->rotation) >= 0) {
    return turnedShape(*turnedFrom, (quarterTurns(rotation) - quarterTurns(turnedFrom->rotation) + 4) % 4, rotation);
  }
  Shape shape;
  shape.rotation = rotation;
  Path path = toPath(rotated(outline, rotation));
  if (ClipperLib::Area(path) < 0) std::reverse(path.begin(), path.end());
  std::tie(shape.minX, shape.minY, shape.maxX, shape.maxY) = std::tuple_cat(boxOf(path));
  if (turnedFrom && !forNoFitPolygons) return turnedByRounding(*turnedFrom, std::move(shape));
  shape.grown = grown(path, spacing / 2 + kSimplifyTolerance, ClipperLib::jtMiter);
  shape.grown = simplifiedPath(shape.grown, kSimplifyTolerance * kScale - 2);
  if (ClipperLib::Area(shape.grown) < 0) std::reverse(shape.grown.begin(), shape.grown.end());
  for (const IntPoint& p : shape.grown) shape.negated.push_back({-p.X, -p.Y});
  std::tie(shape.grownMinX, shape.grownMinY, shape.grownMaxX, shape.grownMaxY) = std::tuple_cat(boxOf(shape.grown));
  if (turnedFrom) {
    const double turn = rotation - turnedFrom->rotation;
    const auto turned = [&](IntPoint p) {
      const Point2 q = rotatedPoint(Point2(static_cast<double>(p.X), static_cast<double>(p.Y)), turn);
      return IntPoint{std::llround(q.x()), std::llround(q.y())};
    };
    const double lessBy = 2 * kSimplifyTolerance * kScale + 1;
    for (const Shape::Pole& pole : turnedFrom->poles) {
      shape.poles.push_back({turned(pole.centre), std::max(1.0, pole.radius - lessBy)});
    }
    if (forNoFitPolygons && turnedFrom->radius > static_cast<cInt>(lessBy)) {
      shape.radius = (turnedFrom->radius - static_cast<cInt>(lessBy)) / radiusStep * radiusStep;
      if (shape.radius > 0) {
        for (const IntPoint& c : turnedFrom->centres) shape.centres.push_back(turned(c));
      }
    }
  } else {
    if (forNoFitPolygons) std::tie(shape.radius, shape.centres) = clearDiscs(shape.grown, radiusStep);
    shape.poles = polesOf(shape.grown, kMostPoles);
  }
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
  if (!forNoFitPolygons) return shape;
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

}  // namespace

Shape makeShape(const Polygon2& outline, double rotation, double spacing, cInt radiusStep, bool forNoFitPolygons,
                const Shape* turnedFrom) {
  Shape shape = builtShape(outline, rotation, spacing, radiusStep, forNoFitPolygons, turnedFrom);
  shape.centroid = areaCentroid(shape.grown);
  return shape;
}

PartShapes::PartShapes(const std::vector<NestingPart>& parts, const NestingOptions& options,
                       const core::WorkContext& context)
    : parts_(parts), options_(options), roomScale_(roomScaleFor(toInt(options.height))) {
  shapes_.resize(parts.size());
  area_.assign(parts.size(), 0);
  built_.assign(parts.size(), 0);
  // The true outline's box in each rotation (what makeShape() finds), to
  // check the fit and size the strip before any shape is built.
  std::vector<std::vector<Box>> boxes(parts.size());
  for (size_t i = 0; i < parts.size(); ++i) {
    quarterOf_.emplace_back();
    shapeAtQuarter_.push_back({-1, -1, -1, -1});
    for (size_t k = 0; k < parts[i].rotations.size(); ++k) {
      const int quarter = quarterTurns(parts[i].rotations[k]);
      if (quarter >= 0 && shapeAtQuarter_.back()[quarter] < 0) shapeAtQuarter_.back()[quarter] = static_cast<int>(k);
      quarterOf_.back().push_back(quarter);
      boxes[i].push_back(boxOf(toPath(rotated(parts[i].outline, parts[i].rotations[k]))));
    }
    const auto& at = shapeAtQuarter_.back();
    firstQuarter_.push_back(
        static_cast<int>(std::find_if(at.begin(), at.end(), [](int k) { return k >= 0; }) - at.begin()));
  }
  const auto widthOf = [](const Box& box) { return box[2] - box[0]; };
  const auto heightOf = [](const Box& box) { return box[3] - box[1]; };
  if (options.strip) {
    // A strip long enough for every part side by side.
    for (const auto& partBoxes : boxes) {
      cInt longest = 0;
      for (const Box& box : partBoxes) longest = std::max({longest, widthOf(box), heightOf(box)});
      width_ += longest + toInt(options_.spacing) + 1;
    }
  } else {
    width_ = toInt(options.width);
  }
  height_ = toInt(options.height);
  // Wider than what two grown shapes overhang their beds (spacing / 2 and
  // the simplification each, with mitres), in any unit.
  if (!options.strip) pitch_ = width_ + 2 * toInt(options.spacing) + toInt(1.0);
  for (size_t i = 0; i < parts.size(); ++i) {
    const bool fits = std::any_of(boxes[i].begin(), boxes[i].end(),
                                  [&](const Box& box) { return widthOf(box) <= width_ && heightOf(box) <= height_; });
    if (!fits) {
      const Box& box = boxes[i].front();
      throw std::invalid_argument(fmt::format(
          "{} ({:.4g} x {:.4g}) does not fit the usable area of {:.4g} x {:.4g} in any allowed rotation", parts[i].name,
          widthOf(box) / kScale, heightOf(box) / kScale, options.strip ? 0.0 : options.width, options.height));
    }
  }
  // Grown with mitres (limit 2) by half the spacing and the
  // simplification's tolerance, a shape's box is at most twice that wider
  // each side than the true outline's.
  const cInt overhang = 2 * toInt(options.spacing / 2 + kSimplifyTolerance) + 2;
  std::vector<double> poleBounds;
  for (const auto& partBoxes : boxes) {
    const Box& box = partBoxes.front();
    sizeBound_.push_back(std::max(widthOf(box), heightOf(box)) + 2 * overhang);
    poleBounds.push_back(static_cast<double>(std::min(widthOf(box), heightOf(box))) / 2 + overhang);
  }
  // The largest pole: the parts taken in decreasing order of their bound
  // and built one at a time (a copy of one built counts as built), until
  // the next bound is no more than the largest pole found; past a few
  // dozen builds, that next bound is kept instead.
  std::vector<int> byBound(parts.size());
  std::iota(byBound.begin(), byBound.end(), 0);
  std::stable_sort(byBound.begin(), byBound.end(), [&](int a, int b) { return poleBounds[a] > poleBounds[b]; });
  constexpr size_t kMostBuiltForTheBound = 32;
  std::vector<int> builtForTheBound;
  double largest = 0;
  for (int part : byBound) {
    if (poleBounds[part] <= largest) break;
    const auto copyOf = [&](int other) {
      return poleBounds[other] == poleBounds[part] && parts[other].rotations == parts[part].rotations &&
             parts[other].outline == parts[part].outline;
    };
    const auto built = std::find_if(builtForTheBound.begin(), builtForTheBound.end(), copyOf);
    const int measured = built == builtForTheBound.end() ? part : *built;
    if (built == builtForTheBound.end()) {
      if (builtForTheBound.size() == kMostBuiltForTheBound) {
        largest = poleBounds[part];
        break;
      }
      buildParts({part}, context);
      builtForTheBound.push_back(part);
    }
    const Shape& shape = shapes_[static_cast<size_t>(measured)].front();
    if (!shape.poles.empty()) largest = std::max(largest, shape.poles.front().radius);
  }
  largestPoleBound_ = largest;
}

void PartShapes::build(std::span<const int> which, const core::WorkContext& context) {
  std::vector<int> parts;
  for (int part : which) {
    if (!built(part)) parts.push_back(part);
  }
  std::sort(parts.begin(), parts.end());
  parts.erase(std::unique(parts.begin(), parts.end()), parts.end());
  buildParts(parts, context);
}

void PartShapes::buildParts(const std::vector<int>& parts, const core::WorkContext& context) {
  // The poles of 3674 bunny panels: 3 s on one core.
  context.parallelFor(parts.size(), [&](size_t k) {
    const size_t i = static_cast<size_t>(parts[k]);
    if (built_[i]) return;
    std::vector<Shape>& shapes = shapes_[i];
    shapes.reserve(parts_[i].rotations.size());  // the first stays where the others are turned from
    for (double rotation : parts_[i].rotations) {
      shapes.push_back(makeShape(parts_[i].outline, rotation, options_.spacing, roomScale_.radiusStep,
                                 forNoFitPolygons(), shapes.empty() ? nullptr : &shapes.front()));
    }
    area_[i] = std::abs(ClipperLib::Area(shapes.front().grown));
  });
  for (int part : parts) built_[static_cast<size_t>(part)] = 1;
}

void PartShapes::buildAll(const core::WorkContext& context) {
  std::vector<int> all(parts_.size());
  std::iota(all.begin(), all.end(), 0);
  build(all, context);
  largestPoleBound_ = 0;
  for (const auto& shapes : shapes_) {
    for (const Shape& shape : shapes) {
      if (!shape.poles.empty()) largestPoleBound_ = std::max(largestPoleBound_, shape.poles.front().radius);
    }
  }
  if (!classOf_.empty()) return;
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
}

NestingResult PartShapes::inCuttingOrder(std::vector<std::pair<int, PlacedShape>>& placed, int sheets,
                                         std::vector<PlacedShape>& row) const {
  std::stable_sort(placed.begin(), placed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  row.clear();
  for (auto [sheet, spot] : placed) {
    spot.at.X += sheet * pitch_;
    row.push_back(spot);
  }
  return resultOf(placed, sheets);
}

NestingResult PartShapes::resultOf(const std::vector<std::pair<int, PlacedShape>>& placed, int sheets) const {
  NestingResult result;
  result.sheets = sheets;
  cInt right = 0;
  for (const auto& [sheet, spot] : placed) {
    const Shape& shape = of(spot);
    result.placements.push_back({spot.part, sheet + 1, spot.at.X / kScale, spot.at.Y / kScale, shape.rotation});
    right = std::max(right, spot.at.X + shape.maxX);
  }
  result.stripLength = right / kScale;
  return result;
}

}  // namespace rotafab::jobs::nesting
