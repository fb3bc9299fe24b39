#include "devices/grbl/CutTracker.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <regex>

namespace rotafab::devices::grbl {
namespace {

// How near a reported position must be to a move to be on it: a few
// steps (GRBL reports whole steps, 0.0125 mm at 80 a mm, and a diagonal
// is stepped a step off the line), so that the move the head is in always
// holds its position, and the first that does is never a later one.
constexpr double kToleranceMm = 0.05;
// GRBL frees a planner block once its last segment is prepared for the
// stepper, which holds up to 6 (grbl's stepper.c, SEGMENT_BUFFER_SIZE):
// so many moves beyond the planner's may have left it and not yet run.
constexpr size_t kStepperSegments = 6;
// A move this long has steps at any resolution a laser has (over 5 steps a mm).
constexpr double kSurelyStepsMm = 0.2;

std::optional<double> wordValue(const std::string& line, char letter) {
  const size_t at = line.find(std::string(" ") + letter);
  if (at == std::string::npos) return std::nullopt;
  try {
    return std::stod(line.substr(at + 2));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

double distanceToSegment(double px, double py, double x0, double y0, double x1, double y1) {
  const double dx = x1 - x0, dy = y1 - y0, length2 = dx * dx + dy * dy;
  const double t = length2 > 0 ? std::clamp(((px - x0) * dx + (py - y0) * dy) / length2, 0.0, 1.0) : 0.0;
  return std::hypot(px - (x0 + t * dx), py - (y0 + t * dy));
}

bool readPair(const std::smatch& m, double& x, double& y) {
  try {
    x = std::stod(m[1]), y = std::stod(m[2]);
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

CutTracker::CutTracker(const GCodeProgram& program, size_t plannerBlocks)
    : mayBlocks_{0}, sureBlocks_{0}, plannerBlocks_(plannerBlocks), strokeEnds_(program.strokeEnds) {
  double x = 0, y = 0;
  bool known = false;
  for (size_t line = 0; line < program.lines.size(); ++line) {
    if (program.lineMove[line] < 0) continue;
    const std::string& text = program.lines[line];
    const double toX = wordValue(text, 'X').value_or(x), toY = wordValue(text, 'Y').value_or(y);
    moves_.push_back({line, x, y, toX, toY, known});
    // (The first move, from wherever the head was: maybe a block, maybe none.)
    const double length = known ? std::hypot(toX - x, toY - y) : -1;
    mayBlocks_.push_back(mayBlocks_.back() + (length != 0 ? 1 : 0));
    sureBlocks_.push_back(sureBlocks_.back() + (length >= kSurelyStepsMm ? 1 : 0));
    x = toX, y = toY, known = true;
  }
}

void CutTracker::headAt(size_t move) {
  if (move < at_ || move >= moves_.size()) return;
  at_ = move;
  // A stroke's lines end before the line the head is in: cut.
  strokesCut_ = std::max(
      strokesCut_, static_cast<size_t>(std::upper_bound(strokeEnds_.begin(), strokeEnds_.end(), moves_[move].line) -
                                       strokeEnds_.begin()));
}

void CutTracker::acknowledged(size_t acknowledgedLines) {
  // The moves taken: those whose line is before acknowledgedLines.
  const auto taken =
      static_cast<size_t>(std::partition_point(moves_.begin(), moves_.end(),
                                               [&](const Segment& move) { return move.line < acknowledgedLines; }) -
                          moves_.begin());
  const size_t ahead = plannerBlocks_ + kStepperSegments;
  if (sureBlocks_[taken] <= ahead) return;
  // At least this many blocks have run (the planner and the stepper hold
  // the rest), and so every move of the first i, for the most i that may hold no more.
  const size_t run = sureBlocks_[taken] - ahead;
  const auto done = static_cast<size_t>(
      std::partition_point(mayBlocks_.begin(), mayBlocks_.end(), [&](size_t blocks) { return blocks <= run; }) -
      mayBlocks_.begin() - 1);
  headAt(std::min(done, taken));
}

void CutTracker::observe(const std::string& report, size_t acknowledgedLines) {
  acknowledged(acknowledgedLines);
  static const std::regex machine(R"(MPos:(-?[0-9.]+),(-?[0-9.]+))"), work(R"(WPos:(-?[0-9.]+),(-?[0-9.]+))"),
      offset(R"(WCO:(-?[0-9.]+),(-?[0-9.]+))");
  std::smatch m;
  if (std::regex_search(report, m, offset)) readPair(m, offsetX_, offsetY_);
  double x = 0, y = 0;
  if (std::regex_search(report, m, work)) {
    if (!readPair(m, x, y)) return;
  } else if (std::regex_search(report, m, machine)) {
    if (!readPair(m, x, y)) return;
    x -= offsetX_, y -= offsetY_;
  } else {
    return;
  }
  // The head is in a move the controller has taken, at or after the last one it was seen in.
  for (size_t move = at_; move < moves_.size() && moves_[move].line < acknowledgedLines; ++move) {
    const Segment& s = moves_[move];
    const double off = s.startKnown ? distanceToSegment(x, y, s.x0, s.y0, s.x1, s.y1) : std::hypot(x - s.x1, y - s.y1);
    if (off > kToleranceMm) continue;
    headAt(move);
    return;
  }
}

}  // namespace rotafab::devices::grbl
