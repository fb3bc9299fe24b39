#pragma once
// True-shape nesting of parts onto beds or into a strip: the facade of the
// steps in jobs/nesting/. No-fit polygons (unions of the Minkowski sums of
// convex pieces, NoFitPolygons.h), bottom-left placement on the vertices of
// the feasible region, each candidate confirmed by an exact intersection
// test (BottomLeftPacker.h). Then, within a time budget, a search over the
// sequence (swaps, fixed or freed rotations, SequenceSearch.h) and, with free
// order, a compaction by guided local search that lets parts overlap and
// moves them apart again (OverlapCompaction.h): it shortens the strip, or on
// beds the last sheet, whose parts move onto the earlier ones. Parts are
// concave and interlock; bounding boxes and hulls are never used for
// collisions. The first layout is deterministic unless the budget runs
// out in it (NestingOptions::seconds); the searches (side by side on the
// context's executor, from that one first layout) each follow a course
// fixed by their seed, and the time budget decides how far along they
// get, so with a budget the result can differ between machines (a cap on layouts, `evaluations`,
// makes it the same everywhere for the same `threads`).
//
// Coordinates in inches; a placement rotates the part's outline about its own
// origin by `rotation` degrees (counter-clockwise), then translates it by
// (x, y) in the usable area (origin at its bottom-left corner).

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "core/WorkContext.h"

namespace rotafab::jobs {

using Point2 = Eigen::Vector2d;
using Polygon2 = std::vector<Point2>;  // a simple polygon, not closed (first point not repeated)

// The nesting budget when none is given (`--time`): the README's first
// command, the bunny's 3674 panels, finishes in under 30 s on 2 cores.
constexpr double kDefaultNestingSeconds = 20.0;

struct NestingPart {
  std::string name;                                        // for messages: "item 3 copy 2", "panel 17"
  Polygon2 outline;                                        // outer contour, kerf already applied
  std::vector<double> rotations{0.0, 90.0, 180.0, 270.0};  // allowed, degrees
  int order = 0;                                           // assembly order, 0-based
};

// How far the layout may move parts from their assembly order.
enum class OrderMode {
  Strict,  // sheet k holds a contiguous run of the order, each sheet filled before the next
  Window,  // no part is cut more than `window` places before or after its order
  Free,
  // Kits (the dissertation's V.5: builders join panels in the order they
  // are cut): sheet k holds a contiguous run of the order, nested freely
  // within the sheet, the runs' ends moving between neighbouring sheets;
  // part i (1-based in the order, of n on S sheets; a panel's pieces are
  // parts too) on sheet ceil(i S / n) + 1 at the latest, and the first on
  // sheet 1 (inKits()). The first layout fills each sheet before the next
  // (the strict order), and is kept as it is: where large parts come first
  // it may leave a part later than its share, and no search undoes that.
  Kits,
};

struct NestingOptions {
  double width = 31.5;      // usable area; ignored in strip mode
  double height = 17.5;     // usable area, or the strip's height
  bool strip = false;       // one strip of fixed height, least length
  double spacing = 0.0625;  // least distance between two outlines
  // The budget (wall clock) of the whole nesting, from the call: the
  // parts' shapes, the first layout and the improvement. When it runs out
  // in the first layout, the parts not yet placed are laid out in rows by
  // their boxes (NestingResult::inRows, and a note), so that there is a
  // layout when the budget says; after it, the improvement stops with the
  // best layout it found. Not with a cap on layouts (`evaluations`), nor
  // in the strip: the first layout is then always finished.
  double seconds = kDefaultNestingSeconds;
  int evaluations = 0;  // if positive, each search stops after this many layouts (and compaction moves)
  OrderMode order = OrderMode::Free;
  int window = 8;
  unsigned seed = 1;
  // The parts may be cut at any angle, not only at their `rotations` (panels
  // of board or paper, which has no grain to keep). Star-shaped panels
  // interlock at angles other than quarter turns: on jobs too large for
  // no-fit polygons, each part is tried at anyAngleTurns() even turns
  // (docs/PERFORMANCE.md, "Turns other than quarter turns").
  bool anyAngle = false;
  // Searches run side by side on the executor, with seeds seed, seed + 1,
  // ...; the best layout wins. 0: one per thread of the executor. With a cap
  // on layouts, the result is the same on every machine for the same number.
  int threads = 0;
};

struct PartPlacement {
  int part = 0;   // index into the parts
  int sheet = 1;  // 1-based; always 1 in strip mode
  double x = 0, y = 0;
  double rotation = 0;  // degrees
};

struct NestingResult {
  std::vector<PartPlacement> placements;  // one per part, in cutting order
  int sheets = 0;
  double stripLength = 0;  // strip mode: the rightmost extent of any part
  double partArea = 0;     // sum of the outlines' areas
  int evaluations = 0;     // layouts tried (and compaction moves), all searches together
  // Why the search stopped: "area bound" (as few sheets as the parts' area
  // allows), "no better layout" (it found none in many tries), "time
  // budget", "layout cap" (NestingOptions::evaluations); "nothing to
  // search" (strict order, or one part); "too many parts" (the window or the
  // kits, with more parts than kMostPartsForNoFitPolygons: the first layout
  // is the layout).
  std::string stopped;
  // Parts laid out in rows by their boxes (RowLayout.h), after the rest,
  // because the budget ran out before the first layout reached them.
  int inRows = 0;
};

// Throws std::invalid_argument naming the part when a part cannot fit the usable
// area (or the strip's height) in any allowed rotation, and core::Cancelled
// within 100 ms of a cancel. Progress goes to the context as phase
// "nesting": step "first layout" (parts placed of all; when done, the
// layout's sheets and the last one's length), "improving" and "compacting"
// (each better layout, by sheets and length; in the strip, its length).
NestingResult nest(const std::vector<NestingPart>& parts, const NestingOptions& options,
                   const core::WorkContext& context);

// Whether `result` keeps the kits of OrderMode::Kits: each sheet a
// contiguous run of the parts' order (after sheet k, every step up to its
// last can be done), no step later than one sheet beyond its fair share,
// the first step on sheet 1.
bool inKits(const std::vector<NestingPart>& parts, const NestingResult& result);

// What a person needs to know of NestingResult::inRows, in one line, or
// nothing when every part was nested.
std::string inRowsNote(const NestingResult& result);

// Throws std::invalid_argument naming the first part whose outline is not a
// polygon with area, or that has no allowed rotation.
void checkNestingParts(const std::vector<NestingPart>& parts);

// The placed outline of a part, in usable-area coordinates.
Polygon2 placedOutline(const NestingPart& part, const PartPlacement& placement);

// Exact check of a layout: every outline inside the area, no two outlines on a
// sheet overlapping or nearer than `spacing - tolerance`. One line per
// problem. Throws core::Cancelled when `cancellation` is given and set.
std::vector<std::string> layoutProblems(const std::vector<NestingPart>& parts, const NestingResult& result,
                                        const NestingOptions& options, double tolerance = 1e-3,
                                        const core::Cancellation* cancellation = nullptr);

double polygonArea(const Polygon2& polygon);

// The fewest sheets the parts' area fills (their outlines' area over the
// usable area's, rounded up): no layout on beds has fewer.
int sheetsTheAreaNeeds(const std::vector<NestingPart>& parts, const NestingOptions& options);

// The even turns (a multiple of 4, so that quarter turns are among them;
// 4 to 24) tried for parts that may be cut at any angle
// (NestingOptions::anyAngle) and allowed the four quarter turns, on a job
// of `parts` parts: as many as keep parts times turns within 90,000 (the
// bunny's first layout: 4 s on 2 cores), and quarter turns alone on jobs
// small enough for no-fit polygons, whose cost grows with the square of
// the turns.
int anyAngleTurns(size_t parts);

// How many quarter turns (0-3) `degrees` is, or -1 when it is no whole number of them.
int quarterTurns(double degrees);

// `p` turned counter-clockwise about the origin; quarter turns are exact.
Point2 rotatedPoint(const Point2& p, double degrees);  // signed: positive counter-clockwise

// The corners (lowest, highest) of the box of `outline` turned by `degrees` as rotatedPoint() turns it.
std::pair<Point2, Point2> rotatedBox(const Polygon2& outline, double degrees);

}  // namespace rotafab::jobs
