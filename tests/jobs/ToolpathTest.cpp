// Toolpaths and their G-code (issue 5): the order of operations, passes,
// travel, and G-code that parses back to the same paths with the right S and
// F for each operation and the laser off at the end.

#include "jobs/Toolpath.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include "TestSupport.h"
#include "jobs/GCode.h"
#include "jobs/SheetReader.h"
#include "jobs/SvgWriter.h"
#include "profiles/Profiles.h"

namespace rotafab::jobs {
namespace {

SheetDrawing sheet() {
  SheetDrawing s;
  s.width = 15, s.height = 15, s.margin = 0.25;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  s.paths.push_back({Operation::Outline, {{0, 0}, {15, 0}, {15, 15}, {0, 15}}, true});
  s.paths.push_back({Operation::Etch, {{1, 1}, {1.5, 1.2}, {2, 1}}, false});
  s.paths.push_back({Operation::Score, {{4, 3}, {1, 3}}, false});
  for (double x : {6.0, 1.0}) {
    s.paths.push_back({Operation::Cut, {{x + 1, 5}, {x + 2, 5}, {x + 2, 6}, {x + 1, 6}}, true});  // a hole
    s.paths.push_back({Operation::Cut, {{x, 4}, {x + 4, 4}, {x + 4, 8}, {x, 8}}, true});          // its part
  }
  return s;
}

const profiles::MachineProfile& grblMachine() {
  static const auto machine =
      profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/grbl-diode-400.yaml");
  return machine;
}

TEST(Toolpath, EtchThenScoreThenInnerThenOuterCutsWithTheirPasses) {
  profiles::MaterialProfile material;
  const Toolpath path = planToolpath(sheet(), grblMachine(), material, MotionLimits{});
  // grbl-diode-400: cut 2 passes (blue), score and etch 1; the outline is not burnt.
  std::vector<std::string> kinds;
  for (const ToolpathStroke& s : path.strokes) {
    kinds.push_back(std::string(profiles::operationName(s.operation)) + (s.inner ? "-inner" : "") +
                    std::to_string(s.pass));
  }
  EXPECT_EQ(kinds, (std::vector<std::string>{"etch1", "score1", "cut-inner1", "cut-inner1", "cut-inner2", "cut-inner2",
                                             "cut1", "cut1", "cut2", "cut2"}));
  // Nearest first: the part at x = 1 before the one at x = 6, and the score
  // entered at its end nearer the etch (it runs backwards).
  EXPECT_EQ(path.strokes[1].points.front(), Point2(1, 3));
  EXPECT_LT(path.strokes[2].points.front().x(), 4);
  // A closed stroke returns to its first corner.
  EXPECT_EQ(path.strokes[2].points.front(), path.strokes[2].points.back());
  EXPECT_EQ(path.strokes[2].points.size(), 5u);
  EXPECT_NEAR(path.strokes[2].power, 1.0, 1e-12);
  EXPECT_NEAR(path.strokes[2].speed, 0.2 * MotionLimits{}.maxSpeed, 1e-12);
  EXPECT_GT(path.seconds, path.burnLength / (0.2 * MotionLimits{}.maxSpeed));
  // Burnt: etch 2 segments, score 3 in, holes 4 in x 2 x 2 passes, parts 16 in x 2 x 2.
  EXPECT_NEAR(path.burnLength, 2 * std::hypot(0.5, 0.2) + 3 + 16 + 64, 1e-9);
}

// A part in another part's hole: its holes, then it, then the hole it sits in, then the outer part.
TEST(Toolpath, NestedCutsGoFromTheInnermostOut) {
  SheetDrawing s;
  s.width = 15, s.height = 15;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  const auto square = [](double x0, double y0, double side) {
    return std::vector<Point2>{{x0, y0}, {x0 + side, y0}, {x0 + side, y0 + side}, {x0, y0 + side}};
  };
  s.paths.push_back({Operation::Cut, square(1, 1, 10), true});  // the big part (depth 0)
  s.paths.push_back({Operation::Cut, square(2, 2, 6), true});   // its hole (1)
  s.paths.push_back({Operation::Cut, square(3, 3, 4), true});   // a part in the hole (2)
  s.paths.push_back({Operation::Cut, square(4, 4, 1), true});   // that part's hole (3)
  profiles::MaterialProfile material;
  const Toolpath path = planToolpath(s, grblMachine(), material, MotionLimits{});
  std::vector<double> sides;
  for (const ToolpathStroke& stroke : path.strokes) {
    if (stroke.pass == 1) sides.push_back((stroke.points[1] - stroke.points[0]).norm());
  }
  EXPECT_EQ(sides, (std::vector<double>{1, 4, 6, 10}));
}

TEST(Toolpath, GCodeParsesBackToTheSamePathsWithEachOperationsPowerAndFeed) {
  profiles::MaterialProfile material;
  MotionLimits limits;
  limits.maxSpeed = 6000 / 25.4 / 60;
  const Toolpath path = planToolpath(sheet(), grblMachine(), material, limits);
  GCodeOptions options;
  options.maxSpindle = 255;
  const auto lines = gcodeLines(path, options);
  ASSERT_GE(lines.size(), 6u);
  EXPECT_EQ(std::vector<std::string>(lines.begin(), lines.begin() + 4),
            (std::vector<std::string>{"G21", "G90", "G94", "M4 S0"}));
  EXPECT_EQ(lines[lines.size() - 2], "M5 S0");
  // Parse: a G0 starts a stroke, G1s continue it; F and S stay in effect.
  struct Parsed {
    std::vector<Point2> points;
    double feed, power;
  };
  std::vector<Parsed> strokes;
  double feed = -1, power = -1;
  static const std::regex move(R"(^G([01]) X(-?[0-9.]+) Y(-?[0-9.]+)(?: F([0-9.]+) S([0-9]+))?$)");
  for (size_t i = 4; i + 2 < lines.size(); ++i) {
    std::smatch m;
    ASSERT_TRUE(std::regex_match(lines[i], m, move)) << lines[i];
    const Point2 p(std::stod(m[2]) / 25.4, std::stod(m[3]) / 25.4);
    if (m[4].matched) feed = std::stod(m[4]), power = std::stod(m[5]);
    if (m[1] == "0") {
      strokes.push_back({{p}, 0, 0});
    } else {
      ASSERT_FALSE(strokes.empty());
      strokes.back().points.push_back(p);
      strokes.back().feed = feed, strokes.back().power = power;
    }
  }
  ASSERT_EQ(strokes.size(), path.strokes.size());
  for (size_t s = 0; s < strokes.size(); ++s) {
    ASSERT_EQ(strokes[s].points.size(), path.strokes[s].points.size());
    for (size_t k = 0; k < strokes[s].points.size(); ++k) {
      EXPECT_LT((strokes[s].points[k] - path.strokes[s].points[k]).norm(), 0.001);
    }
    const profiles::ColourSetting& setting = grblMachine().settingFor(path.strokes[s].operation);
    EXPECT_NEAR(strokes[s].feed, setting.speed / 100 * 6000, 0.05);
    EXPECT_EQ(strokes[s].power, std::round(setting.power / 100 * 255));
  }
}

TEST(Toolpath, TheSvgSheetReadsBackAsItWasWritten) {
  const SheetDrawing written = sheet();
  test::TempDir dir;
  const auto file = dir.path() / "sheet.svg";
  {
    std::ofstream out(file);
    SheetDrawing titled = written;
    titled.title = "test";
    writeSvg(titled, out);
  }
  const SheetDrawing read = readSheetSvg(file);
  EXPECT_EQ(read.width, written.width);
  EXPECT_EQ(read.margin, written.margin);
  ASSERT_EQ(read.paths.size(), written.paths.size());
  for (size_t i = 0; i < read.paths.size(); ++i) {
    EXPECT_EQ(read.paths[i].operation, written.paths[i].operation);
    EXPECT_EQ(read.paths[i].closed, written.paths[i].closed);
    ASSERT_EQ(read.paths[i].points.size(), written.paths[i].points.size());
    for (size_t k = 0; k < read.paths[i].points.size(); ++k) {
      EXPECT_LT((read.paths[i].points[k] - written.paths[i].points[k]).norm(), 1e-9);
    }
  }
}

}  // namespace
}  // namespace rotafab::jobs
