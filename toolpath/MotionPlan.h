#pragma once
// Motion time as GRBL 1.1's planner (gnea/grbl planner.c) makes it, for the
// estimate of a job and for the simulated controller: each block runs a
// trapezoid, accelerating and decelerating at the acceleration, and passes
// a corner no faster than the junction speed of the junction deviation model
// (S. Jeon, "Improving Grbl: Cornering Algorithm", 2011: the speed at which
// a circle arc of deviation δ tangent to both segments is taken at the
// acceleration limit). Look-ahead makes every entry speed the fastest from
// which the rest can still stop at the end. Units are the caller's (inches
// and seconds, or millimetres and seconds), one system throughout.

#include <vector>

#include "core/Polygon2.h"

namespace rotafab::jobs {

using Point2 = core::Point2;

// A value limited by each axis's own (GRBL's $110/$120 are per axis): along
// a diagonal both axes share the motion, so the move may go faster.
double axisLimited(double perAxis, const Point2& unit);

// The fastest a path may turn from direction `in` to `out` (unit vectors),
// squared: 0 for a full reversal, unlimited (a large value) straight on.
// (`perAxis`: the acceleration is each axis's, as axisLimited.)
double junctionSpeedSquared(const Point2& in, const Point2& out, double acceleration, double deviation, bool perAxis);

// Seconds to run `length` entering at `entry` and leaving at `exit`, no
// faster than `nominal`, at `acceleration` (entry and exit reachable).
double trapezoidSeconds(double length, double entry, double exit, double nominal, double acceleration);

struct PlannedBlock {
  double length = 0, nominal = 0, acceleration = 0;
  double maxEntrySquared = 0;  // the junction's limit, and both blocks' nominal speeds
  double entrySquared = 0;     // planned
};

// Look-ahead over `blocks` (planner.c's reverse then forward pass): the
// first enters at most at `firstEntry`, the last stops at its end.
void planEntrySpeeds(std::vector<PlannedBlock>& blocks, double firstEntry);

// A straight move of a program: to `to` at `feed` (unlimited: the rapid
// rate); `stopBefore`: the controller drains its planner first (GRBL's
// M3/M4/M5, which wait for the motion before them to end).
struct Move {
  Point2 to;
  double feed = 0;  // 0: rapid
  bool stopBefore = false;
};

// Seconds to run `moves` from `start`, from a stop to a stop, and the time at
// which each move ends.
struct MotionTime {
  double seconds = 0;
  std::vector<double> endsAt;
};
MotionTime plannedTime(const Point2& start, const std::vector<Move>& moves, double maxRate, double acceleration,
                       double junctionDeviation, bool perAxis);

}  // namespace rotafab::jobs
