#include "toolpath/MotionPlan.h"

#include <algorithm>
#include <cmath>

namespace rotafab::jobs {
namespace {

// planner.c's SOME_LARGE_VALUE: no limit from a straight junction.
constexpr double kUnlimited = 1.0e38;

}  // namespace

double axisLimited(double perAxis, const Point2& unit) {
  const double largest = std::max(std::abs(unit.x()), std::abs(unit.y()));
  return largest > 0 ? perAxis / largest : perAxis;
}

double junctionSpeedSquared(const Point2& in, const Point2& out, double acceleration, double deviation, bool perAxis) {
  const double cosTheta = -in.dot(out);  // θ is the angle between the two segments, 180° straight on
  if (cosTheta > 0.999999) return 0;     // a reversal: stop
  if (cosTheta < -0.999999) return kUnlimited;
  Point2 turn = out - in;
  turn.normalize();
  const double a = perAxis ? axisLimited(acceleration, turn) : acceleration;
  const double sinHalfTheta = std::sqrt(0.5 * (1.0 - cosTheta));
  return std::max(0.0, a * deviation * sinHalfTheta / (1.0 - sinHalfTheta));
}

double trapezoidSeconds(double length, double entry, double exit, double nominal, double acceleration) {
  if (length <= 0) return 0;
  if (!(acceleration > 0)) return nominal > 0 ? length / nominal : 0;
  const double toNominal = (nominal * nominal - entry * entry) / (2 * acceleration);
  const double fromNominal = (nominal * nominal - exit * exit) / (2 * acceleration);
  if (toNominal + fromNominal <= length) {
    return (nominal - entry) / acceleration + (nominal - exit) / acceleration +
           (length - toNominal - fromNominal) / nominal;
  }
  // No room to reach the nominal speed: a triangle, up to where the
  // acceleration from the entry meets the deceleration to the exit.
  const double peakSquared = (2 * acceleration * length + entry * entry + exit * exit) / 2;
  if (peakSquared < std::max(entry * entry, exit * exit)) return 2 * length / std::max(entry + exit, 1e-12);
  const double peak = std::sqrt(peakSquared);
  return (peak - entry) / acceleration + (peak - exit) / acceleration;
}

void planEntrySpeeds(std::vector<PlannedBlock>& blocks, double firstEntry) {
  if (blocks.empty()) return;
  // Reverse: each block may enter no faster than it can still slow down to
  // the next one's entry (the last one's end is a stop).
  double nextEntrySquared = 0;
  for (auto block = blocks.rbegin(); block != blocks.rend(); ++block) {
    block->entrySquared = std::min(block->maxEntrySquared, nextEntrySquared + 2 * block->acceleration * block->length);
    nextEntrySquared = block->entrySquared;
  }
  // Forward: and no faster than it can be reached from the one before.
  blocks.front().entrySquared = std::min(blocks.front().entrySquared, firstEntry * firstEntry);
  for (size_t i = 0; i + 1 < blocks.size(); ++i) {
    blocks[i + 1].entrySquared =
        std::min(blocks[i + 1].entrySquared, blocks[i].entrySquared + 2 * blocks[i].acceleration * blocks[i].length);
  }
}

MotionTime plannedTime(const Point2& start, const std::vector<Move>& moves, double maxRate, double acceleration,
                       double junctionDeviation, bool perAxis) {
  MotionTime time;
  time.endsAt.assign(moves.size(), 0.0);
  std::vector<PlannedBlock> blocks;
  std::vector<size_t> blockMove;  // the move of each block
  // Runs the blocks planned so far, from a stop to a stop.
  const auto flush = [&] {
    planEntrySpeeds(blocks, 0);
    for (size_t i = 0; i < blocks.size(); ++i) {
      const double exit = i + 1 < blocks.size() ? std::sqrt(blocks[i + 1].entrySquared) : 0.0;
      time.seconds += trapezoidSeconds(blocks[i].length, std::sqrt(blocks[i].entrySquared), exit, blocks[i].nominal,
                                       blocks[i].acceleration);
      time.endsAt[blockMove[i]] = time.seconds;
    }
    blocks.clear();
    blockMove.clear();
  };
  Point2 at = start, previousUnit(0, 0);
  for (size_t m = 0; m < moves.size(); ++m) {
    const Move& move = moves[m];
    if (move.stopBefore) flush();
    const Point2 delta = move.to - at;
    const double length = delta.norm();
    at = move.to;
    if (!(length > 1e-9)) {  // GRBL drops a move of no steps
      time.endsAt[m] = time.seconds;
      continue;
    }
    const Point2 unit = delta / length;
    const double rate = perAxis ? axisLimited(maxRate, unit) : maxRate;
    PlannedBlock block;
    block.length = length;
    block.nominal = move.feed > 0 ? std::min(move.feed, rate) : rate;
    block.acceleration = perAxis ? axisLimited(acceleration, unit) : acceleration;
    if (!blocks.empty()) {
      const double nominals = std::min(blocks.back().nominal, block.nominal);
      block.maxEntrySquared = std::min(
          junctionSpeedSquared(previousUnit, unit, acceleration, junctionDeviation, perAxis), nominals * nominals);
    }
    previousUnit = unit;
    blocks.push_back(block);
    blockMove.push_back(m);
    // Times are known once the blocks after have been planned; the rest wait.
    time.endsAt[m] = -1;
  }
  flush();
  // A dropped move ends when the move before it did.
  for (size_t m = 1; m < moves.size(); ++m) {
    if (time.endsAt[m] < time.endsAt[m - 1]) time.endsAt[m] = time.endsAt[m - 1];
  }
  return time;
}

}  // namespace rotafab::jobs
