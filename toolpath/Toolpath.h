#pragma once
// What a laser does with one sheet: the strokes it burns, in order,
// each with its power, speed and pass, and the travel between them. Built from
// the planner's sheet and the machine and material profiles:
// - power, speed and passes per operation from the machine's colour table
//   (fig. 65), overridden by the material's settings for that machine;
// - etch, then score, then the cuts from the innermost out (a part's holes
//   before its outline; a part nested in another's hole before that hole),
//   so that nothing is cut free before the work on it is done; the outline
//   (the material's edge, power 0) is not burnt;
// - within each stage, the strokes in the order that shortens the travel
//   (nearest neighbour, then 2-opt), each entered at its nearer end (an open
//   stroke may run backwards, a closed one start at any corner);
// - every pass of a stage before the next stage.
// Lengths in inches, speeds in inches per second, sheet coordinates (origin
// at the bed's bottom-left corner, y up). Drivers turn it into their bytes.

#include <array>
#include <string>
#include <vector>

#include "profiles/Profiles.h"
#include "toolpath/MotionPlan.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

// What the machine can do; the speeds of the colour table are percentages of `maxSpeed`.
struct MotionLimits {
  double maxSpeed = 500.0 / 25.4 / 60;  // in/s (GRBL's default $110, 500 mm/min)
  double acceleration = 10.0 / 25.4;    // in/s^2 (GRBL's default $120, 10 mm/s^2)
  // How far a corner may be cut (GRBL's $11, inches); 0: every corner is
  // taken from a stop (a controller without look-ahead).
  double junctionDeviation = 0;
  bool perAxis = false;  // the speed and acceleration are each axis's (GRBL's): a diagonal goes faster
};

struct ToolpathStroke {
  Operation operation = Operation::Cut;
  bool inner = false;          // a cut inside another closed cut (a hole, a nested part): before it
  double power = 0;            // 0..1 of the machine's full power
  double speed = 0;            // in/s
  int pass = 1;                // 1-based
  std::vector<Point2> points;  // burnt from the first to the last; a closed path returns to its first point
  double minPower = -1;        // 0..1, at most `power`: where the head slows (a Ruida's corners); < 0: `power`
};

struct Toolpath {
  int sheet = 1;
  double width = 0, height = 0;  // the bed
  std::vector<ToolpathStroke> strokes;
  double burnLength = 0;    // inches, all passes
  double travelLength = 0;  // inches, from the origin through every stroke and back
  double seconds = 0;       // estimated: see estimateSeconds()
  double framePower = 0;    // percent the box is traced at (the machine's frame_power); 0: laser off
};

// How the machine of `profile` moves, by its `motion` (GRBL's defaults when it
// gives none): on GRBL each axis at its own limits, with look-ahead.
MotionLimits profileMotion(const profiles::MachineProfile& profile);

// Throws std::invalid_argument when an operation drawn has no usable setting.
Toolpath planToolpath(const SheetDrawing& sheet, const profiles::MachineProfile& machine,
                      const profiles::MaterialProfile& material, const MotionLimits& limits);

// The rest of a sheet from stroke `firstStroke` on (0-based; the strokes
// before it were cut): a stopped sheet's resume. Lengths and time are the rest's.
Toolpath restOfSheet(const Toolpath& toolpath, size_t firstStroke, const MotionLimits& limits);

// The head's moves: from the origin to each stroke's start at the rapid
// rate, along the stroke at its speed, and back to the origin once the
// laser is off (after a stop: switching it off waits for the motion).
std::vector<Move> toolpathMoves(const Toolpath& toolpath);

// The time to run, as a planner with look-ahead runs it (MotionPlan.h):
// each move accelerating and braking at the limit, corners taken at the
// junction deviation's speed.
MotionTime toolpathTime(const Toolpath& toolpath, const MotionLimits& limits);
double estimateSeconds(const Toolpath& toolpath, const MotionLimits& limits);

// The box the laser head covers (strokes and nothing else), for framing: min x, min y, max x, max y.
std::array<double, 4> toolpathBounds(const Toolpath& toolpath);

}  // namespace rotafab::jobs
