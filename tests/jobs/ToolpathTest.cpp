// Toolpaths: the order of operations, passes and travel, and the SVG sheet
// they are planned from, read back.

#include "toolpath/Toolpath.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>

#include "jobs/SvgWriter.h"
#include "profiles/Profiles.h"
#include "support/TestSheets.h"
#include "support/TestSupport.h"
#include "toolpath/SheetReader.h"

namespace rotafab::jobs {
namespace {

using test::grblMachine;
using test::sheet;

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
