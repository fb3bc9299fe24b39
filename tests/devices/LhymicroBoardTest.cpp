// The simulated M2 Nano board's interpreter: it must run what our encoder
// writes (jobLines) and reproduce the toolpath, and follow the protocol notes
// on homing, abort, pause, timing and rule breaks.

#include "devices/sim/LhymicroBoard.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "devices/m2nano/Lhymicro.h"

namespace rotafab::devices::sim {
namespace {

std::array<uint8_t, 30> payloadOf(const m2nano::Packet& packet) {
  std::array<uint8_t, 30> payload{};
  std::copy(packet.begin() + 2, packet.begin() + 32, payload.begin());
  return payload;
}

std::array<uint8_t, 30> payloadOf(const std::string& text) { return payloadOf(m2nano::packet(text)); }

// Sends a command line as the driver does, waiting (in machine time) while the board is full; returns the waits.
int feed(LhymicroBoard& board, const std::string& line) {
  int waits = 0;
  for (const m2nano::Packet& packet : m2nano::packets(line)) {
    while (board.full() && waits < 1000000) board.advance(0.01), ++waits;
    board.accept(payloadOf(packet));
  }
  return waits;
}

// Runs until nothing is left; returns the machine time it took (to 1 ms).
double runToEnd(LhymicroBoard& board) {
  double seconds = 0;
  while (board.busy() && seconds < 10000) board.advance(0.001), seconds += 0.001;
  return seconds;
}

std::string allViolations(const LhymicroBoard& board) {
  std::string text;
  for (const std::string& v : board.violations()) text += v + "\n";
  return text;
}

double distanceToSegment(double px, double py, double ax, double ay, double bx, double by) {
  const double dx = bx - ax, dy = by - ay;
  const double length2 = dx * dx + dy * dy;
  const double t = length2 > 0 ? std::clamp(((px - ax) * dx + (py - ay) * dy) / length2, 0.0, 1.0) : 0.0;
  return std::hypot(px - (ax + t * dx), py - (ay + t * dy));
}

// Three strokes on an 12 x 8 in bed: corners with a 45-degree diagonal at
// 20 mm/s, an arc of short chords at 8 mm/s, and slanted lines at 20 mm/s
// again (so the speed changes twice with "@NSE"). Points on whole mils, so
// that the one-mil tolerance is the board's and the encoder's, not rounding.
jobs::Toolpath sampleToolpath() {
  jobs::Toolpath path;
  path.width = 12, path.height = 8;
  const auto mil = [](double inches) { return std::round(inches * 1000) / 1000; };
  jobs::ToolpathStroke corners;
  corners.speed = 20 / 25.4;
  corners.points = {{1, 7}, {3, 7}, {4, 6}, {4, 5}};
  jobs::ToolpathStroke arc;
  arc.speed = 8 / 25.4;
  for (int i = 0; i <= 30; ++i) {
    const double angle = i * (1.5 * std::numbers::pi / 30);
    arc.points.emplace_back(mil(7 + 1.5 * std::cos(angle)), mil(4 + 1.5 * std::sin(angle)));
  }
  jobs::ToolpathStroke slanted;
  slanted.speed = 20 / 25.4;
  slanted.points = {{2, 2}, {5, 3.3}, {2.5, 1}};
  path.strokes = {corners, arc, slanted};
  return path;
}

// The laser-on moves of a trace, in order.
std::vector<std::array<long, 4>> litMoves(const LhymicroBoard& board) {
  std::vector<std::array<long, 4>> moves;
  for (const BoardSegment& s : board.trace()) {
    if (s.laser) moves.push_back({s.x0, s.y0, s.x1, s.y1});
  }
  return moves;
}

// A job held after stroke k (what the driver sends on a pause: the job up to
// the stroke's end, then "@NSE") and resumed with jobProgram(toolpath, k + 1)
// burns what the whole job burns, move for move, and breaks no rule.
TEST(LhymicroBoard, AJobHeldAfterAnyStrokeAndResumedBurnsTheSame) {
  const jobs::Toolpath path = sampleToolpath();
  const m2nano::LhymicroJob whole = m2nano::jobProgram(path);
  LhymicroBoard reference;
  for (const std::string& line : whole.lines) feed(reference, line);
  runToEnd(reference);
  ASSERT_EQ(whole.strokeEnds.size(), path.strokes.size());
  for (size_t k = 0; k < path.strokes.size(); ++k) {
    std::string stream;
    for (const std::string& line : whole.lines) stream += line;
    LhymicroBoard board;
    // Up to the end of stroke k, cut where the driver cuts it: "IPP" alone, then the rest with "@NSE".
    feed(board, "IPP");
    feed(board, stream.substr(3, whole.strokeEnds[k] - 3) + "@NSE");
    runToEnd(board);
    EXPECT_FALSE(board.laser());
    EXPECT_EQ(board.mode(), BoardMode::Default);
    const m2nano::LhymicroJob rest = m2nano::jobProgram(path, k + 1);
    EXPECT_EQ(rest.strokeEnds.size(), path.strokes.size() - k - 1);
    if (k + 1 == path.strokes.size()) {
      EXPECT_TRUE(rest.lines.empty());
    }
    for (const std::string& line : rest.lines) feed(board, line);
    runToEnd(board);
    EXPECT_EQ(litMoves(board), litMoves(reference)) << "held after stroke " << k + 1;
    EXPECT_TRUE(board.violations().empty()) << "held after stroke " << k + 1 << ": " << allViolations(board);
  }
}

// Padding inside compact mode is a rule break the board reports.
TEST(LhymicroBoard, PaddingInsideCompactModeIsReported) {
  LhymicroBoard board;
  feed(board, "ICV2502451021000015CNRBS1EDzzz");  // a full packet: no padding
  feed(board, "B");                               // padded: "BFFF...", and the next packet goes on
  feed(board, "aU@NSE");
  runToEnd(board);
  ASSERT_FALSE(board.violations().empty());
  EXPECT_NE(board.violations().front().find("padding 'F' inside compact mode"), std::string::npos)
      << allViolations(board);
}

TEST(LhymicroBoard, RunsJobLinesAndReproducesTheStrokes) {
  const jobs::Toolpath path = sampleToolpath();
  LhymicroBoard::Options options;
  options.capacityPackets = 2;  // so that the feeding has to wait on full()
  LhymicroBoard board(options);
  int waits = 0;
  size_t packetCount = 0;
  for (const std::string& line : m2nano::jobLines(path)) {
    waits += feed(board, line);
    packetCount += m2nano::packets(line).size();
  }
  EXPECT_GT(waits, 0);
  runToEnd(board);
  EXPECT_FALSE(board.busy());
  EXPECT_TRUE(board.finished());
  EXPECT_FALSE(board.laser());
  EXPECT_EQ(board.mode(), BoardMode::Finished);
  EXPECT_EQ(board.packetsExecuted(), packetCount);
  EXPECT_TRUE(board.violations().empty()) << allViolations(board);

  // The lit moves, as chains of touching segments with nothing dark between them.
  std::vector<std::vector<BoardSegment>> chains;
  bool inChain = false;
  for (const BoardSegment& s : board.trace()) {
    if (!s.laser) {
      inChain = false;
      continue;
    }
    if (!inChain || chains.back().back().x1 != s.x0 || chains.back().back().y1 != s.y0) chains.emplace_back();
    chains.back().push_back(s);
    inChain = true;
  }
  ASSERT_EQ(chains.size(), path.strokes.size());
  for (size_t k = 0; k < chains.size(); ++k) {
    const jobs::ToolpathStroke& stroke = path.strokes[k];
    std::vector<std::pair<double, double>> vertices;  // board mils
    for (const jobs::Point2& p : stroke.points) vertices.emplace_back(p.x() * 1000, (path.height - p.y()) * 1000);
    const std::vector<BoardSegment>& chain = chains[k];
    ASSERT_LE(std::hypot(chain.front().x0 - vertices[0].first, chain.front().y0 - vertices[0].second), 1.0) << k;
    // A vertex can fall inside a move (the board merges runs that go on the
    // same way, as the encoder leaves out the letter): each vertex must lie on
    // a move, in order, and each move end on the edge it is cutting.
    size_t next = 1;  // the vertex the chain heads for
    for (const BoardSegment& s : chain) {
      EXPECT_NEAR(s.mmPerSecond, stroke.speed * 25.4, stroke.speed * 25.4 * 0.01) << k;
      while (next < vertices.size() &&
             distanceToSegment(vertices[next].first, vertices[next].second, s.x0, s.y0, s.x1, s.y1) <= 1.0) {
        ++next;
      }
      const auto& [ax, ay] = vertices[next - 1];
      const auto& [bx, by] = vertices[std::min(next, vertices.size() - 1)];
      EXPECT_LE(distanceToSegment(s.x1, s.y1, ax, ay, bx, by), 1.0)
          << "stroke " << k << " edge " << next << " at (" << s.x1 << ", " << s.y1 << ")";
    }
    EXPECT_LE(std::hypot(chain.back().x1 - vertices.back().first, chain.back().y1 - vertices.back().second), 1.0);
    EXPECT_EQ(next, vertices.size()) << "stroke " << k << " stops short";
  }
}

TEST(LhymicroBoard, DecodesEveryDistanceTheEncoderWrites) {
  for (long mils = 0; mils < 3000; ++mils) {
    LhymicroBoard board;
    feed(board, "IR" + m2nano::distance(mils) + "S1P");
    board.advance(100);
    ASSERT_EQ(board.y(), mils) << m2nano::distance(mils);
    ASSERT_TRUE(board.violations().empty()) << allViolations(board);
  }
}

TEST(LhymicroBoard, IppHomes) {
  LhymicroBoard board;
  feed(board, "IBzzz235Rzzz235S1P");
  const double rapid = runToEnd(board);
  EXPECT_NEAR(rapid, std::hypot(1000, 1000) * 0.0254 / 100, 0.002);
  EXPECT_EQ(board.x(), 1000);
  EXPECT_EQ(board.y(), 1000);
  EXPECT_TRUE(board.railLocked());
  EXPECT_FALSE(board.finished());  // a rapid move is no finished job
  ASSERT_EQ(board.trace().size(), 1u);
  EXPECT_FALSE(board.trace()[0].laser);
  EXPECT_DOUBLE_EQ(board.trace()[0].mmPerSecond, 100);

  feed(board, "IPP");
  board.advance(0.25);  // half of homeSeconds
  EXPECT_TRUE(board.busy());
  EXPECT_FALSE(board.finished());
  board.advance(0.26);
  EXPECT_FALSE(board.busy());
  EXPECT_EQ(board.x(), 0);
  EXPECT_EQ(board.y(), 0);
  EXPECT_TRUE(board.finished());
  EXPECT_TRUE(board.trace().back().homing);
  EXPECT_EQ(board.mode(), BoardMode::Default);
  // The next packet clears the finished state.
  board.accept(payloadOf("IS2P"));
  EXPECT_FALSE(board.finished());
  runToEnd(board);
  EXPECT_FALSE(board.railLocked());
  EXPECT_TRUE(board.violations().empty()) << allViolations(board);
}

TEST(LhymicroBoard, AbortDropsWhatIsQueuedAndStopsWhereTheHeadIs) {
  LhymicroBoard::Options options;
  options.capacityPackets = 16;
  LhymicroBoard board(options);
  feed(board, "IPP");
  feed(board, std::string("I") + m2nano::speedCode(20) + "NRBS1ED" + m2nano::distance(2000) + "R" +
                  m2nano::distance(2000) + "UFNSE");
  for (int i = 0; i < 3; ++i) feed(board, "IBzzz235S1P");
  board.advance(0.5 + 1.0);  // home, then a second of the cut
  ASSERT_EQ(board.mode(), BoardMode::Compact);
  ASSERT_TRUE(board.laser());
  const long x = board.x();
  EXPECT_NEAR(x, 1000 * 20 / 25.4, 2);
  const size_t executed = board.packetsExecuted();

  board.accept(payloadOf("I"));
  EXPECT_FALSE(board.busy());
  EXPECT_FALSE(board.laser());
  EXPECT_EQ(board.mode(), BoardMode::Default);
  EXPECT_FALSE(board.finished());
  EXPECT_EQ(board.x(), x);
  EXPECT_EQ(board.y(), 0);
  EXPECT_EQ(board.packetsExecuted(), executed + 1);
  EXPECT_EQ(board.packetsDropped(), 4u);  // the cut's second packet and the three rapid moves
  ASSERT_FALSE(board.trace().empty());
  EXPECT_TRUE(board.trace().back().laser);  // the cut as far as it went
  EXPECT_EQ(board.trace().back().x1, x);
  const size_t moves = board.trace().size();
  board.advance(5);
  EXPECT_EQ(board.x(), x);
  EXPECT_EQ(board.trace().size(), moves);
  EXPECT_TRUE(board.violations().empty()) << allViolations(board);
}

TEST(LhymicroBoard, PnPausesAndResumes) {
  LhymicroBoard board;
  feed(board, std::string("I") + m2nano::speedCode(20) + "NRBS1EDzzz235UFNSE");
  board.advance(0.5);
  const long x = board.x();
  EXPECT_NEAR(x, 0.5 * 20 / 0.0254, 2);
  board.accept(payloadOf("PN"));
  EXPECT_TRUE(board.paused());
  board.advance(2);
  EXPECT_EQ(board.x(), x);
  EXPECT_TRUE(board.laser());
  EXPECT_TRUE(board.busy());
  board.accept(payloadOf("PN"));
  EXPECT_FALSE(board.paused());
  board.advance(0.75);  // the cut takes 1.27 s in all: 0.02 s to go
  EXPECT_TRUE(board.busy());
  EXPECT_GT(board.x(), x);
  EXPECT_LT(board.x(), 1000);
  board.advance(0.05);
  EXPECT_FALSE(board.busy());
  EXPECT_EQ(board.x(), 1000);
  EXPECT_TRUE(board.finished());
  // The pause froze the move, it did not split it.
  ASSERT_EQ(board.trace().size(), 1u);
  EXPECT_EQ(board.trace()[0].x0, 0);
  EXPECT_EQ(board.trace()[0].x1, 1000);
  EXPECT_TRUE(board.violations().empty()) << allViolations(board);
}

TEST(LhymicroBoard, MovesTakeTheirTimeAtTheCodedSpeed) {
  const auto seconds = [](const std::string& code, const std::string& moves) {
    LhymicroBoard board;
    feed(board, "I" + code + "NRBS1E" + moves + "UFNSE");
    const double t = runToEnd(board);
    EXPECT_TRUE(board.finished());
    EXPECT_TRUE(board.violations().empty()) << allViolations(board);
    return t;
  };
  const double inchAt20 = 1000 * 0.0254 / 20;  // 1.27 s
  EXPECT_NEAR(seconds(m2nano::speedCode(20), "Dzzz235"), inchAt20, inchAt20 * 0.01);
  // The normal (gear) form of 20 mm/s from the notes, and a diagonal's sqrt(2) per step.
  EXPECT_NEAR(seconds("CV1752231021000191", "Dzzz235"), inchAt20, inchAt20 * 0.01);
  EXPECT_NEAR(seconds(m2nano::speedCode(20), "MDzzz235"), inchAt20 * std::numbers::sqrt2,
              inchAt20 * std::numbers::sqrt2 * 0.01);
  EXPECT_NEAR(seconds(m2nano::speedCode(5), "Dzzz235"), 1000 * 0.0254 / 5, 1000 * 0.0254 / 5 * 0.01);
}

TEST(LhymicroBoard, RuleBreaksAreReported) {
  {
    LhymicroBoard board;
    feed(board, "IBzzXz235S1P");  // a stray 'X'; the rest still runs
    runToEnd(board);
    ASSERT_EQ(board.violations().size(), 1u) << allViolations(board);
    EXPECT_NE(board.violations()[0].find("unknown byte 0x58"), std::string::npos) << board.violations()[0];
    EXPECT_EQ(board.x(), 1000);
  }
  {
    LhymicroBoard board;
    feed(board, "ITzzz235S1P");
    runToEnd(board);
    ASSERT_EQ(board.violations().size(), 1u) << allViolations(board);
    EXPECT_EQ(board.violations()[0], "head off the bed at (-1000, 0)");
  }
  {
    LhymicroBoard board;
    feed(board, "IDBzzz235S1P");
    runToEnd(board);
    ASSERT_EQ(board.violations().size(), 1u) << allViolations(board);
    EXPECT_NE(board.violations()[0].find("laser on in default mode"), std::string::npos);
  }
  {
    LhymicroBoard board;  // a burn left lit into FNSE
    feed(board, std::string("I") + m2nano::speedCode(20) + "NRBS1EDzzz235FNSE");
    runToEnd(board);
    EXPECT_FALSE(board.laser());
    ASSERT_EQ(board.violations().size(), 1u) << allViolations(board);
    EXPECT_NE(board.violations()[0].find("no U"), std::string::npos);
  }
  {
    LhymicroBoard::Options options;
    options.capacityPackets = 2;
    LhymicroBoard board(options);
    board.accept(payloadOf("IBaS1P"));
    EXPECT_FALSE(board.full());
    board.accept(payloadOf("IBaS1P"));
    EXPECT_TRUE(board.full());
    EXPECT_TRUE(board.violations().empty());
    board.accept(payloadOf("IBaS1P"));
    EXPECT_EQ(board.violations().size(), 1u);
  }
}

TEST(LhymicroBoard, FinishedModeIgnoresAllButI) {
  LhymicroBoard board;
  feed(board, "FNSE");  // K40 Whisperer's "unfreeze", from default mode
  runToEnd(board);
  EXPECT_EQ(board.mode(), BoardMode::Finished);
  EXPECT_TRUE(board.finished());
  feed(board, "BzzzS1P");
  runToEnd(board);
  EXPECT_EQ(board.x(), 0);
  feed(board, "IBzzzS1P");
  runToEnd(board);
  EXPECT_EQ(board.x(), 765);
  EXPECT_EQ(board.mode(), BoardMode::Default);
  EXPECT_TRUE(board.violations().empty()) << allViolations(board);
}

}  // namespace
}  // namespace rotafab::devices::sim
