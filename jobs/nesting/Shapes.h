#pragma once
// The nester's shapes (jobs/Nesting.h): each part in each allowed rotation
// on Clipper's integer grid, grown by half the spacing, with what the other
// steps need of it: convex pieces (for no-fit polygons, NoFitPolygons.h),
// discs of one radius inside it (for the room left on a sheet,
// BottomLeftPacker.h), poles (the inscribed discs of sparrow, Gardeyn and
// Wauters 2025, arXiv:2509.13329, for the overlap measure of
// OverlapCompaction.h) and a core a few
// grid units smaller (for the compaction's collision test).
//
// Preconditions: outlines are simple polygons with area (checkNestingParts()).
// Internal to the nester.

#include <clipper.hpp>

#include <array>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "core/WorkContext.h"
#include "jobs/Nesting.h"
#include "jobs/nesting/CellCover.h"

namespace rotafab::jobs::nesting {

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

cInt toInt(double value);
Path toPath(const Polygon2& polygon);
Polygon2 rotated(const Polygon2& polygon, double degrees);
Path translatedPath(const Path& path, IntPoint by);
// The closed path with the fewest corners within `tolerance` grid units of it (Douglas-Peucker).
Path simplifiedPath(const Path& path, double tolerance);
Box boxOf(const Path& path);

// The path grown by `by` inches (its boundary grown too, as a line: a
// needle or slit in the outline encloses no area, yet the laser cuts it);
// the largest path of the offset.
Path grown(const Path& path, double by, ClipperLib::JoinType join);

// The piece of largest area, or `otherwise` when there is none.
Path largestOf(const Paths& pieces, const Path& otherwise);

// The sizes of the sheet's `room` machinery (BottomLeftPacker), in
// proportion to the area's height (instances come in any unit): on the
// 17.5 in high bed, disc radii are rounded down to 1/20 in so that parts of
// similar size share the room regions, cells are 1/4 in, and Clipper's round
// joins keep within 1/100 in.
struct RoomScale {
  cInt radiusStep, cell;
  double arcTolerance;
};
RoomScale roomScaleFor(cInt height);

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
  // clear of every placed shape by the radius (see BottomLeftPacker's room).
  // No discs when the shape is too thin to hold one of the radius step.
  std::vector<IntPoint> centres;
  cInt radius = 0;
  // Poles, as sparrow calls them: discs inside `grown`, the largest first,
  // each the largest in what the earlier ones leave uncovered. The
  // compaction's overlap proxy weighs how deep two shapes' poles reach into
  // each other.
  struct Pole {
    IntPoint centre;
    double radius;
  };
  std::vector<Pole> poles;
  // The centroid of `grown`'s area: the first layout ranks a part's
  // rotations by where it puts their mass (CollisionPlacer::bestSpot()).
  IntPoint centroid{0, 0};
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

// Discs of one radius inside a polygon (Poles.cpp). The largest: a grid
// search for the point farthest from the boundary, refined around the best
// point, its radius the distance from there rounded down to `radiusStep`.
// Then up to `maxDiscs - 1` more of that radius, each at the grid point with
// room for it that is farthest from the centres so far, while that is at
// least a radius away. Every radius is a true distance to the boundary, so
// every disc is inside.
std::pair<cInt, std::vector<IntPoint>> clearDiscs(const Path& polygon, cInt radiusStep, int maxDiscs = 5);
// The poles of a polygon (see Shape::poles; Poles.cpp), at most `most`.
std::vector<Shape::Pole> polesOf(const Path& polygon, size_t most);

// `forNoFitPolygons`: with the convex pieces and discs only the bottom-left
// packer needs. `turnedFrom`, the same part's shape in another rotation:
// for a quarter turn from a quarter turn, the whole shape is turned on the
// grid, exactly; otherwise its poles and discs are turned instead of
// searched again (their radii less twice kSimplifyTolerance, what the two
// grown outlines may differ by), and without `forNoFitPolygons` its grown
// path and core too, their corners rounded to the grid (no offsets).
Shape makeShape(const Polygon2& outline, double rotation, double spacing, cInt radiusStep, bool forNoFitPolygons,
                const Shape* turnedFrom = nullptr);

// The bottom-left packer with no-fit polygons re-lays every part after the
// first one a trial changes: on jobs of more parts than this a trial takes
// seconds (the bunny's 3674 panels: about 100 s), so the sequence search
// that uses it is left out, and the shapes are built without what only it needs.
constexpr size_t kMostPartsForNoFitPolygons = 400;

// A shape placed: its part, its rotation (an index into the part's shapes)
// and where its reference point (the part's origin) is.
struct PlacedShape {
  int part;
  int shape;
  IntPoint at;
};

// Whether the boxes of two placed grown shapes are apart (touching counts as apart).
bool boxesApart(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB);
// Whether two placed shapes' cores (Shape::core) overlap, touching apart:
// an edge of one properly crosses an edge of the other, or a point of one
// (a pole's centre, a vertex, the middle of an edge) is strictly inside the
// other's core. The same both ways round, and a few microseconds. Can miss
// overlaps whose every crossing is at a vertex or along a shared line and
// that hold none of those points; coresOverlap() has the last word.
bool coresColliding(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB);
// Whether two placed shapes' cores have area in common, by Clipper: exact,
// and some tens of microseconds.
bool coresOverlap(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB);
// What two paths, each moved, have in common.
Paths intersectionOf(const Path& a, IntPoint atA, const Path& b, IntPoint atB);

class PartShapes;
// Whether `part` may go on sheet s of `sheets` (each with its `parts`)
// under `policy`: in a strict order only on the last; in a window, only
// if it is then cut at most `window` places after its order.
template <typename Sheets>
bool mayGoOn(const PartShapes& shapes, OrderMode policy, const Sheets& sheets, int s, int part);

// The shapes of every part in every allowed rotation, which parts are
// copies of one another, and the area they are laid out in, on the grid.
// The shapes are built as they are needed, some parts at a time (build()),
// the parts shared out on the context's executor: the first layout builds
// them just ahead of the parts it places, so that a time budget that runs
// out in it has not been spent on shapes it never reached (a 25,888-part
// job's took 6 s). Once buildAll() has run, read-only, shared by the
// searches.
class PartShapes {
 public:
  // Builds the few shapes that largestPoleBound() needs. Throws
  // std::invalid_argument naming a part that fits the area in no allowed
  // rotation, core::Cancelled.
  PartShapes(const std::vector<NestingPart>& parts, const NestingOptions& options, const core::WorkContext& context);

  // Builds the shapes of `which` not built yet. Throws core::Cancelled.
  void build(std::span<const int> which, const core::WorkContext& context);
  // Builds every part's shapes and finds the copies (classOf()), which the
  // searches need. Throws core::Cancelled.
  void buildAll(const core::WorkContext& context);
  [[nodiscard]] bool built(int part) const { return built_[part] != 0; }

  // At least the radius of any part's largest pole (Shape::poles), in grid
  // units: exact once every shape is built, else from the parts' boxes
  // (a disc inside a grown shape is no wider than its box), made exact for
  // the parts that could have the largest.
  [[nodiscard]] double largestPoleBound() const { return largestPoleBound_; }
  // The largest side of each part's box (its first rotation, grown), in grid units.
  [[nodiscard]] cInt sizeBound(int part) const { return sizeBound_[part]; }

  [[nodiscard]] const std::vector<NestingPart>& parts() const { return parts_; }
  [[nodiscard]] const NestingOptions& options() const { return options_; }
  [[nodiscard]] const std::vector<Shape>& of(int part) const { return shapes_[part]; }
  [[nodiscard]] const Shape& at(int part, int shape) const { return shapes_[part][shape]; }
  [[nodiscard]] const Shape& of(const PlacedShape& p) const { return shapes_[p.part][p.shape]; }
  [[nodiscard]] double area(int part) const { return area_[part]; }  // grown, square grid units; once built
  // Shapes that are exact copies share a class (one per part and rotation); after buildAll().
  [[nodiscard]] int classOf(int part, int shape) const { return classOf_[part][shape]; }
  [[nodiscard]] int classSize(int shapeClass) const { return classSize_[shapeClass]; }
  // Each shape's rotation in quarter turns (0-3; -1 when it is not one), and
  // per part the shape at each quarter turn (-1: not allowed) and its first.
  [[nodiscard]] int quarterOf(int part, int shape) const { return quarterOf_[part][shape]; }
  [[nodiscard]] int shapeAtQuarter(int part, int quarter) const { return shapeAtQuarter_[part][quarter]; }
  [[nodiscard]] int firstQuarter(int part) const { return firstQuarter_[part]; }

  // The area, on the grid: its width (in the strip, long enough for every
  // part side by side) and height, and the pitch of the beds laid side by
  // side in one row (OverlapCompaction; 0 in the strip).
  [[nodiscard]] cInt width() const { return width_; }
  [[nodiscard]] cInt height() const { return height_; }
  [[nodiscard]] cInt pitch() const { return pitch_; }
  [[nodiscard]] const RoomScale& roomScale() const { return roomScale_; }
  // Whether the shapes have what the bottom-left packer needs (kMostPartsForNoFitPolygons).
  [[nodiscard]] bool forNoFitPolygons() const { return parts_.size() <= kMostPartsForNoFitPolygons; }

  // The right end of a placed shape's true outline.
  [[nodiscard]] cInt rightOf(const PlacedShape& s) const { return s.at.X + of(s).maxX; }

  // (sheet, shape) pairs in placing order put in cutting order (sheet by
  // sheet, each in the order its parts were placed), `row` set to them with
  // the beds side by side in one row (bed s from s * pitch on), and their
  // placements in inches.
  NestingResult inCuttingOrder(std::vector<std::pair<int, PlacedShape>>& placed, int sheets,
                               std::vector<PlacedShape>& row) const;

  // Placements, in inches, of (sheet, shape) pairs in cutting order.
  [[nodiscard]] NestingResult resultOf(const std::vector<std::pair<int, PlacedShape>>& placed, int sheets) const;

 private:
  const std::vector<NestingPart>& parts_;
  const NestingOptions& options_;
  RoomScale roomScale_;
  std::vector<std::vector<Shape>> shapes_;
  std::vector<std::vector<int>> classOf_;
  std::vector<int> classSize_;
  std::vector<std::vector<int>> quarterOf_;
  std::vector<std::array<int, 4>> shapeAtQuarter_;
  std::vector<int> firstQuarter_;
  std::vector<double> area_;
  std::vector<char> built_;
  std::vector<cInt> sizeBound_;
  double largestPoleBound_ = 0;
  cInt width_ = 0, height_ = 0, pitch_ = 0;
  void buildParts(const std::vector<int>& parts, const core::WorkContext& context);
};

template <typename Sheets>
bool mayGoOn(const PartShapes& shapes, OrderMode policy, const Sheets& sheets, int s, int part) {
  const int count = static_cast<int>(sheets.size());
  if (policy == OrderMode::Strict) return s == count - 1;
  if (policy != OrderMode::Window || s + 1 == count) return true;
  // Placed on sheet s, the part is cut after every part on sheets 0..s.
  int cutBefore = 0;
  for (int k = 0; k <= s; ++k) cutBefore += static_cast<int>(sheets[k].parts.size());
  return shapes.parts()[part].order - cutBefore <= shapes.options().window;
}

}  // namespace rotafab::jobs::nesting
