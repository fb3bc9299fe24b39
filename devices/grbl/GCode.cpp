#include "devices/grbl/GCode.h"

#include <fmt/format.h>

#include <cmath>

namespace rotafab::devices::grbl {

using namespace jobs;

namespace {

std::string millimetres(double inches) { return formatDecimal(inches * kMillimetresPerInch, 3); }

}  // namespace

GCodeProgram gcodeProgram(const jobs::Toolpath& toolpath, const GCodeOptions& options) {
  GCodeProgram program;
  std::vector<std::string>& lines = program.lines;
  lines = {"G21", "G90", "G94", "M4 S0"};
  for (const ToolpathStroke& stroke : toolpath.strokes) {
    lines.push_back(
        fmt::format("G0 X{} Y{}", millimetres(stroke.points.front().x()), millimetres(stroke.points.front().y())));
    const std::string feed = formatDecimal(stroke.speed * kMillimetresPerInch * 60, 1);
    const std::string power = formatDecimal(std::round(stroke.power * options.maxSpindle), 0);
    for (size_t i = 1; i < stroke.points.size(); ++i) {
      std::string line =
          fmt::format("G1 X{} Y{}", millimetres(stroke.points[i].x()), millimetres(stroke.points[i].y()));
      if (i == 1) line += fmt::format(" F{} S{}", feed, power);
      lines.push_back(std::move(line));
    }
    program.strokeEnds.push_back(lines.size());
  }
  lines.push_back("M5 S0");
  lines.push_back("G0 X0 Y0");
  // A move per line from the first G0 to the last, but the M5 (its moves
  // are toolpathMoves', in the same order).
  int move = 0;
  for (const std::string& line : lines)
    program.lineMove.push_back(line.starts_with("G0 ") || line.starts_with("G1 ") ? move++ : -1);
  return program;
}

std::vector<std::string> gcodeLines(const jobs::Toolpath& toolpath, const GCodeOptions& options) {
  return gcodeProgram(toolpath, options).lines;
}

}  // namespace rotafab::devices::grbl
