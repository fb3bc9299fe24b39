#pragma once
// LHYMICRO-GL, the command language of the Lihuiyu M2 Nano board (K40
// lasers), as MeerK40t, K40 Whisperer and LibLaserCut speak it (learnt from
// them, written anew): distances in mils (1/1000 in) as letters and
// digits, direction letters, laser on (D) and off (U), speed codes, and the
// 30-byte packets with their CRC-8 that go over USB. The board has no power
// control (the machine's dial sets it): speed and passes are what it varies.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "toolpath/Toolpath.h"

namespace rotafab::devices::m2nano {

// CRC-8/MAXIM (1-Wire: reflected polynomial 0x8C, init 0) of a packet's 30 payload bytes.
uint8_t crc8(const uint8_t* bytes, size_t count);

// One USB bulk transfer: 0xA6 0x00, the 30-byte payload (padded with 'F'), 0xA6, the CRC.
using Packet = std::array<uint8_t, 34>;
Packet packet(const std::string& payload);  // payload: at most 30 bytes
// A command line cut into packets of 30 bytes, the last one padded with 'F'.
std::vector<Packet> packets(const std::string& line);

// The board's answers to a status request (the second byte of six): the
// packet taken, and room for the next; busy (checking the packet, or no
// room); the packet arrived corrupted, send it again; the job has finished;
// a power fault.
enum BoardStatus : int { kOk = 206, kBusy = 238, kCrcError = 207, kFinished = 236, kPowerFault = 239 };

// A distance of `mils` steps: 'z' per 255, then 52..254 as three digits, 26..51 as '|' and a letter, 1..25 a..y.
std::string distance(long mils);

// The vector speed code for `mmPerSecond` on the M2 board, in the low-speed
// ("suffix C") form MeerK40t uses by default: "CV2502451021000015C" for 20 mm/s.
std::string speedCode(double mmPerSecond);

// A line of (dx, dy) mils in compact (cut) mode, with the laser on or off,
// from `state`; returns the commands and updates the state.
struct CompactState {
  int xDirection = 1;  // B (+x, right) or T (-x)
  int yDirection = 1;  // R (+y, toward the front) or L (-y)
  char engaged = 'x';  // 'x', 'y' or 'm' (diagonal): which letters are in effect
  bool laser = false;
};
std::string compactLine(long dx, long dy, bool laser, CompactState& state);

// The whole job for one sheet, one command line per compact-mode section
// (each line starts its own packets): home, then compact mode at each
// stroke's speed (a speed change is "@NSE" and a new code), travel with the
// laser off, each stroke burnt, FNSE. Sheet coordinates (y up) become the
// board's (home at the back left, y toward the front). Throws
// std::invalid_argument for a point off the toolpath's bed.
std::vector<std::string> jobLines(const jobs::Toolpath& toolpath);

// The same lines, and where each stroke's commands end, counted in bytes of
// the lines one after another (for progress by strokes; each stroke ends
// with the laser off, so a driver can hold there). From `firstStroke` on,
// the program resumes a job held after the stroke before it: no home, from
// where that stroke ended.
struct LhymicroJob {
  std::vector<std::string> lines;
  std::vector<size_t> strokeEnds;
};
LhymicroJob jobProgram(const jobs::Toolpath& toolpath, size_t firstStroke = 0);

// Framing: home, then the box of the strokes traced in compact mode with the laser off.
std::vector<std::string> frameLines(const jobs::Toolpath& toolpath, double mmPerSecond);

// The .egv file K40 Whisperer and MeerK40t open (docs/CONTRACT.md, "Devices").
std::string egvFile(const std::vector<std::string>& lines);

// The .egv file of the sheets' jobs one after another, as a dry run writes
// it, and what it is, for people.
std::string egvProgram(const std::vector<jobs::Toolpath>& toolpaths);
std::string describeEgvProgram(const std::vector<jobs::Toolpath>& toolpaths);

// The M2's motion limits for the toolpath: a profile's 100% speed is 100 mm/s.
jobs::MotionLimits motionLimits();

}  // namespace rotafab::devices::m2nano
