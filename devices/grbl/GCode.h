#pragma once
// G-code for a toolpath, in GRBL 1.1's laser mode ($32=1): millimetres,
// absolute coordinates, M4 dynamic power (the power follows the speed, so
// corners do not burn deeper), S scaled to the controller's $30. Every
// stroke is a G0 to its start (the laser is off on G0 in laser mode) and
// G1 moves with its F and S; M5 at the end. No comments: every byte counts
// against the controller's receive buffer.

#include <string>
#include <vector>

#include "toolpath/Toolpath.h"

namespace rotafab::devices::grbl {

// GRBL speaks millimetres ($13=0); toolpaths are in inches.
inline constexpr double kMillimetresPerInch = 25.4;

struct GCodeOptions {
  double maxSpindle = 1000;  // $30: S for full power
};

// One line each, without the newline.
std::vector<std::string> gcodeLines(const jobs::Toolpath& toolpath, const GCodeOptions& options);

// The same lines, and how many of them run through the end of each stroke
// (for progress by strokes).
// `lineMove`: for each line, the head's move it is (jobs::toolpathMoves'
// numbering), or -1 for a line that does not move it.
struct GCodeProgram {
  std::vector<std::string> lines;
  std::vector<size_t> strokeEnds;
  std::vector<int> lineMove;
};
GCodeProgram gcodeProgram(const jobs::Toolpath& toolpath, const GCodeOptions& options);

}  // namespace rotafab::devices::grbl
