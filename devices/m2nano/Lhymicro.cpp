#include "devices/m2nano/Lhymicro.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace rotafab::devices::m2nano {

uint8_t crc8(const uint8_t* bytes, size_t count) {
  uint8_t crc = 0;
  for (size_t i = 0; i < count; ++i) {
    uint8_t byte = bytes[i];
    for (int bit = 0; bit < 8; ++bit) {
      const bool mix = ((crc ^ byte) & 1) != 0;
      crc >>= 1;
      if (mix) crc ^= 0x8C;
      byte >>= 1;
    }
  }
  return crc;
}

Packet packet(const std::string& payload) {
  if (payload.size() > 30) throw std::invalid_argument("an LHYMICRO-GL packet holds 30 bytes");
  Packet p{};
  p[0] = 0xA6, p[1] = 0x00;
  for (size_t i = 0; i < 30; ++i) p[2 + i] = i < payload.size() ? static_cast<uint8_t>(payload[i]) : 'F';
  p[32] = 0xA6;
  p[33] = crc8(p.data() + 2, 30);
  return p;
}

std::vector<Packet> packets(const std::string& line) {
  std::vector<Packet> out;
  for (size_t at = 0; at < line.size(); at += 30) out.push_back(packet(line.substr(at, 30)));
  return out;
}

std::string distance(long mils) {
  if (mils < 0) throw std::invalid_argument("an LHYMICRO-GL distance is not negative");
  std::string out(static_cast<size_t>(mils / 255), 'z');
  const long rest = mils % 255;
  if (rest >= 52) {
    out += fmt::format("{:03}", rest);
  } else if (rest >= 26) {
    out += '|';
    out += static_cast<char>('a' + rest - 26);
  } else if (rest >= 1) {
    out += static_cast<char>('a' + rest - 1);
  }
  return out;
}

std::string speedCode(double mmPerSecond) {
  // The board's timer period per mil step (ms), in its low-speed timebase:
  // value = 65536 - (m * period + b), m = 12120 / 12, b = 8; the step digits
  // and the diagonal correction as MeerK40t computes them.
  const double period = 25.4 / mmPerSecond;
  const double m = 12120.0 / 12, b = 8;
  const long value = std::clamp(static_cast<long>(65536 - (m * period + b)), 0L, 65535L);
  const long step = std::min(static_cast<long>(std::floor(mmPerSecond)) + 1, 128L);
  const long diagonal =
      std::clamp(static_cast<long>(0.261199033289 * m * period / static_cast<double>(step)), 0L, 65535L);
  return fmt::format("CV{:03}{:03}1{:03}{:03}{:03}C", value / 256, value % 256, step, diagonal / 256, diagonal % 256);
}

std::string compactLine(long dx, long dy, bool laser, CompactState& state) {
  // Unit steps along the line (Zingl's Bresenham), merged into runs of the same step.
  struct Run {
    int sx, sy;
    long count;
  };
  std::vector<Run> runs;
  long x = 0, y = 0;
  const long ax = std::labs(dx), ay = -std::labs(dy);
  const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
  long error = ax + ay;
  while (x != dx || y != dy) {
    const long twice = 2 * error;
    int stepX = 0, stepY = 0;
    if (twice >= ay && x != dx) error += ay, x += sx, stepX = sx;
    if (twice <= ax && y != dy) error += ax, y += sy, stepY = sy;
    if (!runs.empty() && runs.back().sx == stepX && runs.back().sy == stepY) {
      ++runs.back().count;
    } else {
      runs.push_back({stepX, stepY, 1});
    }
  }
  std::string out;
  const auto laserLetter = [&] {
    if (state.laser != laser) out += laser ? 'D' : 'U', state.laser = laser;
  };
  for (const Run& run : runs) {
    if (run.sy == 0) {  // along x
      if (state.engaged != 'x' || state.xDirection != run.sx) out += run.sx > 0 ? 'B' : 'T';
      state.engaged = 'x', state.xDirection = run.sx;
    } else if (run.sx == 0) {  // along y
      if (state.engaged != 'y' || state.yDirection != run.sy) out += run.sy > 0 ? 'R' : 'L';
      state.engaged = 'y', state.yDirection = run.sy;
    } else {  // diagonal
      if (state.xDirection != run.sx) out += run.sx > 0 ? 'B' : 'T';
      if (state.yDirection != run.sy) out += run.sy > 0 ? 'R' : 'L';
      out += 'M';
      state.engaged = 'm', state.xDirection = run.sx, state.yDirection = run.sy;
    }
    laserLetter();
    out += distance(run.count);
  }
  if (runs.empty()) laserLetter();
  return out;
}

jobs::MotionLimits motionLimits() {
  jobs::MotionLimits limits;
  limits.maxSpeed = 100 / 25.4;       // in/s
  limits.acceleration = 1000 / 25.4;  // in/s^2 (an estimate: the board's ramps are not documented)
  return limits;
}

namespace {

// A sheet point in mils on the board: x right, y toward the front from the back-left home.
std::pair<long, long> boardMils(const jobs::Toolpath& toolpath, const jobs::Point2& p) {
  if (p.x() < -1e-9 || p.y() < -1e-9 || p.x() > toolpath.width + 1e-9 || p.y() > toolpath.height + 1e-9) {
    throw std::invalid_argument(fmt::format("sheet {}: a point ({:.4g}, {:.4g}) off the {:.4g} x {:.4g} in bed",
                                            toolpath.sheet, p.x(), p.y(), toolpath.width, toolpath.height));
  }
  return {std::lround(p.x() * 1000), std::lround((toolpath.height - p.y()) * 1000)};
}

// Compact mode at a speed: the code, then the directions (y toward the
// front, then x right; the last one names the major axis).
std::string enterCompact(const std::string& code) { return code + "NRBS1E"; }

}  // namespace

LhymicroJob jobProgram(const jobs::Toolpath& toolpath, size_t firstStroke) {
  // One line (its own packets, padded with 'F') per compact-mode section:
  // a line ends only after "@NSE" or "FNSE", where padding is harmless.
  LhymicroJob job;
  size_t before = 0;  // the bytes of the lines already closed
  long atX = 0, atY = 0;
  if (firstStroke == 0) {
    job.lines.push_back("IPP");
    before = 3;
  } else {
    std::tie(atX, atY) = boardMils(toolpath, toolpath.strokes.at(firstStroke - 1).points.back());
  }
  std::string line, speed;
  CompactState state;
  for (size_t s = firstStroke; s < toolpath.strokes.size(); ++s) {
    const jobs::ToolpathStroke& stroke = toolpath.strokes[s];
    const std::string code = speedCode(std::max(stroke.speed * 25.4, 1.0));
    if (code != speed) {
      // First from default mode ("I"), then from compact mode without finishing ("@NSE").
      if (speed.empty()) {
        line.push_back('I');
      } else {
        line += "@NSE";
        before += line.size();
        job.lines.push_back(std::exchange(line, std::string()));
      }
      line += enterCompact(code);
      speed = code;
      state = CompactState{};
    }
    const auto [x0, y0] = boardMils(toolpath, stroke.points.front());
    line += compactLine(x0 - atX, y0 - atY, false, state);
    atX = x0, atY = y0;
    for (size_t i = 1; i < stroke.points.size(); ++i) {
      const auto [x, y] = boardMils(toolpath, stroke.points[i]);
      line += compactLine(x - atX, y - atY, true, state);
      atX = x, atY = y;
    }
    if (state.laser) line += 'U', state.laser = false;
    job.strokeEnds.push_back(before + line.size());
  }
  // The board runs on after FNSE; homing must wait until it reports the job
  // finished (status 236), which a file cannot: the driver homes, not the job.
  if (!speed.empty()) {
    line += "FNSE";
    job.lines.push_back(std::move(line));
  }
  return job;
}

std::vector<std::string> jobLines(const jobs::Toolpath& toolpath) { return jobProgram(toolpath).lines; }

std::vector<std::string> frameLines(const jobs::Toolpath& toolpath, double mmPerSecond) {
  const auto box = jobs::toolpathBounds(toolpath);
  const auto [left, front] = boardMils(toolpath, jobs::Point2(box[0], box[1]));
  const auto [right, back] = boardMils(toolpath, jobs::Point2(box[2], box[3]));
  std::string line(1, 'I');  // (appended, not "I" + ...: GCC 12 warns falsely on that)
  line += enterCompact(speedCode(mmPerSecond));
  CompactState state;
  long atX = 0, atY = 0;
  for (const auto& [x, y] : {std::pair{left, back}, {right, back}, {right, front}, {left, front}, {left, back}}) {
    line += compactLine(x - atX, y - atY, false, state);
    atX = x, atY = y;
  }
  line += "FNSE";
  return {"IPP", line};
}

std::string egvFile(const std::vector<std::string>& lines) {
  std::string out =
      "Document type : LHYMICRO-GL file\nFile version: 1.0.01\nCopyright: Unknown\nCreator-Software: rotafab\n\n"
      "%0%0%0%0%\n";
  for (const std::string& line : lines) out += line + "\n";
  return out;
}

std::string egvProgram(const std::vector<jobs::Toolpath>& toolpaths) {
  std::vector<std::string> lines;
  for (const jobs::Toolpath& toolpath : toolpaths) {
    const auto sheet = jobLines(toolpath);
    lines.insert(lines.end(), sheet.begin(), sheet.end());
  }
  return egvFile(lines);
}

std::string describeEgvProgram(const std::vector<jobs::Toolpath>& toolpaths) {
  return fmt::format("LHYMICRO-GL for {} sheet{} (an .egv file K40 Whisperer and MeerK40t open)", toolpaths.size(),
                     toolpaths.size() == 1 ? "" : "s");
}

}  // namespace rotafab::devices::m2nano
