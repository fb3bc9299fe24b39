#pragma once
// Which strokes a GRBL machine has finished cutting. GRBL acknowledges a
// line when it enters the planner, up to 15 moves ahead of the head, and
// a stop (feed hold, reset) drops what the planner held: acknowledged is
// not cut. Two things say where the head is. The planner's depth: of the
// moves acknowledged, all but the last `plannerBlocks` (and the stepper's
// few prepared segments) have run
// (GRBL drops a move of no steps, so only moves surely of some steps are
// counted). And the position in the status reports, placed on the first
// move from there on that holds it (a sheet's passes repeat the same
// segments; the depth tells them apart). A position that fits no move (a
// work offset never reported, a garbled report) leaves the count to the
// depth: it may trail the cut, never run ahead of it.

#include <cstddef>
#include <string>
#include <vector>

#include "devices/grbl/GCode.h"

namespace rotafab::devices::grbl {

class CutTracker {
 public:
  CutTracker(const GCodeProgram& program, size_t plannerBlocks);
  // A status report (`<Run|MPos:...|WCO:...>` or with WPos), while the
  // controller has acknowledged the lines before `acknowledgedLines`.
  void observe(const std::string& report, size_t acknowledgedLines);
  // The lines before `acknowledgedLines` acknowledged: the moves the planner cannot hold have run.
  void acknowledged(size_t acknowledgedLines);
  // Every line has run (the machine idle after the last).
  void finished() { strokesCut_ = strokeEnds_.size(); }
  [[nodiscard]] size_t strokesCut() const { return strokesCut_; }

 private:
  struct Segment {
    size_t line;
    double x0, y0, x1, y1;  // mm, work coordinates
    bool startKnown;        // the first move starts wherever the head was
  };
  std::vector<Segment> moves_;
  // Of the first i moves: how many may be planner blocks (of any length
  // but none), and how many surely are (long enough for a step at any
  // resolution a laser has). Each of size moves + 1.
  std::vector<size_t> mayBlocks_, sureBlocks_;
  size_t plannerBlocks_;
  std::vector<size_t> strokeEnds_;
  size_t at_ = 0;  // the move the head was last seen in
  size_t strokesCut_ = 0;
  void headAt(size_t move);
  double offsetX_ = 0, offsetY_ = 0;  // WCO: machine position less work position
};

}  // namespace rotafab::devices::grbl
