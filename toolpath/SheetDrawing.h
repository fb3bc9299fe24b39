#pragma once
// One laser sheet as it is to be drawn: the bed and the paths on it, in sheet
// coordinates (inches, origin at the bottom-left corner of the bed, y up),
// each path tagged with its operation and listed in cutting order. The EPS,
// SVG and DXF writers turn a SheetDrawing into files that describe exactly the
// same geometry. The planner (nesting, kerf, ordering) produces it; labels
// arrive already turned into single-stroke polylines (geometry/HersheyFont.h).

#include <fmt/format.h>
#include <Eigen/Core>
#include <map>
#include <optional>

#include <string>
#include <string_view>
#include <vector>

#include "core/Decimal.h"
#include "profiles/Operation.h"

namespace rotafab::jobs {

using Point2 = Eigen::Vector2d;

using profiles::Operation;
using profiles::Rgb;

// What a sheet's files resolve: a laser resolves about 0.001 in, so the
// writers give coordinates to 0.0001 in, and the planner simplifies every
// path to within kSheetSimplification of its geometry. With the rounding
// (at most 0.00005 in on each axis), the lines written stay within 0.0002
// in of the geometry, far inside a kerf's tolerance.
constexpr int kSheetDecimals = 4;
constexpr double kSheetSimplification = 0.0002 - 0.00005 * 1.41421356237 - 1e-6;

// A round hole as the files give it: one true circle (SVG arcs, PostScript's
// arc, a DXF CIRCLE) rather than the dozens of corners of its polygon, which
// were half the bytes of a sheet of panels.
struct Circle {
  Point2 centre = Point2::Zero();
  double radius = 0;
};

// The polygon a toolpath follows around a circle: kCircleSides sides that
// touch it, so that a fastener of the circle's diameter still passes.
constexpr int kCircleSides = 32;
std::vector<Point2> circlePolygon(const Circle& circle);

struct DrawnPath {
  Operation operation = Operation::Cut;
  std::vector<Point2> points;  // at least 2
  bool closed = false;         // the last point joins the first (not repeated)
  std::string part = {};       // the part it belongs to, as an id ("panel-17"); empty: the bed's
  // A closed path that is this circle: the files write the circle, and
  // `points` is its circlePolygon().
  std::optional<Circle> circle = {};
};

// The drawn path of a circle: its polygon, closed, with the circle kept.
DrawnPath circlePath(Operation operation, const Circle& circle, std::string part = {});

struct SheetDrawing {
  int index = 1;        // 1-based sheet number
  int sheetCount = 1;   // of how many, for the title
  double width = 32.0;  // the bed, inches
  double height = 18.0;
  double margin = 0.25;              // no path may come nearer the bed's edge
  std::string title;                 // e.g. "bunny (band) - sheet 1 of 12"
  std::map<Operation, Rgb> colours;  // the machine profile's colour for each operation
  std::vector<DrawnPath> paths;      // in cutting order
};

// What every writer requires before it writes a byte: a bed of positive size,
// a colour for each operation drawn, paths of two or more finite points on
// the bed. Throws std::invalid_argument naming the sheet, the path and what is wrong.
void checkDrawable(const SheetDrawing& sheet);

// Fixed-point with `decimals` digits, trailing zeros dropped, never "-0": the
// numbers of every sheet format, the same in any locale.
std::string formatDecimal(double value, int decimals);
// The same, appended to `out` without a string of its own (the writers' inner loops).
void appendDecimal(fmt::memory_buffer& out, double value, int decimals);

// The writers give a path's points after its first as moves in whole units
// (core/Decimal.h), so that the moves add up exactly to the rounded points.
using core::appendUnits;
using core::unitsOf;

// Text for a one-line header field: printable ASCII only ('?' for anything
// else), at most 200 characters.
std::string printableAscii(std::string_view text);

}  // namespace rotafab::jobs
