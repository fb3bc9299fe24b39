// The planner measured on its output sheets: kerf on every cut, the material
// left between parts, the margins, the cutting order, and the files.

#include "jobs/SheetPlanner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <regex>
#include <sstream>

#include "core/Polygon2.h"
#include "support/TestContext.h"
#include "support/TestSupport.h"
#include "toolpath/SheetReader.h"

namespace rotafab::jobs {
namespace {

Polygon2 circle(Point2 centre, double radius, int sides = 64) {
  Polygon2 p;
  for (int i = 0; i < sides; ++i) {
    const double a = 2 * std::numbers::pi * i / sides;
    p.emplace_back(centre.x() + radius * std::cos(a), centre.y() + radius * std::sin(a));
  }
  return p;
}

// A 2 x 2 in panel with a fastener hole, a fold line and a label stroke.
Part panel(int order) {
  Part part;
  part.name = "panel " + std::to_string(order + 1);
  part.order = order;
  part.outline = {{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  part.holes = {circle({1, 1}, 0.125)};
  part.score = {{{0.2, 0.2}, {1.8, 0.2}}};
  part.etch = {{{0.5, 1.5}, {0.7, 1.7}}};
  return part;
}

profiles::MachineProfile workshop() {
  return profiles::loadMachineProfile(std::filesystem::path(ROTAFAB_SOURCE_DIR) /
                                      "profiles/machines/workshop-32x18.yaml");
}

struct Extent {
  double minX = 1e9, minY = 1e9, maxX = -1e9, maxY = -1e9;
  void add(const Point2& p) {
    minX = std::min(minX, p.x()), minY = std::min(minY, p.y()), maxX = std::max(maxX, p.x()),
    maxY = std::max(maxY, p.y());
  }
};

double segmentDistance(Point2 a, Point2 b, Point2 c, Point2 d) {
  auto pointSegment = [](Point2 p, Point2 s, Point2 t) {
    const Point2 st = t - s;
    const double u = std::clamp((p - s).dot(st) / st.squaredNorm(), 0.0, 1.0);
    return (p - (s + u * st)).norm();
  };
  return std::min({pointSegment(a, c, d), pointSegment(b, c, d), pointSegment(c, a, b), pointSegment(d, a, b)});
}

double pathDistance(const DrawnPath& a, const DrawnPath& b) {
  double best = 1e9;
  for (size_t i = 0; i < a.points.size(); ++i)
    for (size_t j = 0; j < b.points.size(); ++j)
      best = std::min(best, segmentDistance(a.points[i], a.points[(i + 1) % a.points.size()], b.points[j],
                                            b.points[(j + 1) % b.points.size()]));
  return best;
}

// How much larger the parts could be on the 32 x 18 in bed (31.5 x 17.5
// usable): the best of each part's allowed rotations, the worst part.
TEST(SheetPlanner, RoomOnTheBedIsTheGrowthAtWhichTheWorstPartStillFits) {
  Part wide = panel(0);
  wide.outline = {{0, 0}, {10, 0}, {10, 5}, {0, 5}};
  const profiles::MachineProfile machine = workshop();
  EXPECT_NEAR(roomOnTheBed({wide}, machine, 0), 3.15, 1e-12);  // 31.5 / 10, upright: 17.5 / 10 is less
  wide.rotations = {90};
  EXPECT_NEAR(roomOnTheBed({wide}, machine, 0), 1.75, 1e-12);
  Part tall = panel(1);
  tall.outline = {{0, 0}, {5, 0}, {5, 40}, {0, 40}};  // fits no way round
  EXPECT_NEAR(roomOnTheBed({wide, tall}, machine, 0), 31.5 / 40, 1e-12);
  EXPECT_NEAR(roomOnTheBed({tall}, machine, 0.5), 31 / 40.0, 1e-12) << "the kerf takes its width off the bed";
}

TEST(SheetPlanner, KerfIsOnEveryCutAndMaterialStaysBetweenParts) {
  std::vector<Part> parts;
  for (int i = 0; i < 40; ++i) parts.push_back(panel(i));
  PlanOptions options;
  options.kerf = 0.01;
  options.seconds = 5;  // never spent: the first layout is on the one bed the parts' area needs
  const SheetPlan plan = planSheets(parts, workshop(), options, test::context());
  ASSERT_GE(plan.sheets.size(), 1u);
  for (const SheetDrawing& sheet : plan.sheets) {
    std::vector<const DrawnPath*> outers;
    for (const DrawnPath& path : sheet.paths) {
      if (path.operation != Operation::Cut) continue;
      Extent e;
      for (const Point2& p : path.points) e.add(p);
      const double size = e.maxX - e.minX;
      if (size > 1) {
        // The outer contour: the design's 2 in plus the kerf.
        EXPECT_NEAR(size, 2.01, 1e-3);
        EXPECT_NEAR(e.maxY - e.minY, 2.01, 1e-3);
        outers.push_back(&path);
        // Inside the margins.
        EXPECT_GE(e.minX, 0.25 - 1e-9);
        EXPECT_GE(e.minY, 0.25 - 1e-9);
        EXPECT_LE(e.maxX, 32 - 0.25 + 1e-9);
        EXPECT_LE(e.maxY, 18 - 0.25 + 1e-9);
      } else {
        // The hole: its 0.25 in diameter less the kerf.
        EXPECT_NEAR(size, 0.24, 1e-3);
      }
    }
    // Between two cut paths: 1/16 in of material plus the kerf.
    for (size_t a = 0; a < outers.size(); ++a)
      for (size_t b = a + 1; b < outers.size(); ++b)
        EXPECT_GE(pathDistance(*outers[a], *outers[b]), 1.0 / 16 + 0.01 - 1e-3);
  }
}

TEST(SheetPlanner, EachSheetIsEtchedThenScoredThenCutInsideOut) {
  std::vector<Part> parts;
  for (int i = 0; i < 6; ++i) parts.push_back(panel(i));
  PlanOptions options;
  options.seconds = 5;  // never spent: the first layout is on the one bed the parts' area needs
  const SheetPlan plan = planSheets(parts, workshop(), options, test::context());
  ASSERT_EQ(plan.sheets.size(), 1u);
  const auto& paths = plan.sheets[0].paths;
  ASSERT_EQ(paths.size(), 1 + 6 * 4u);  // the material outline, then etch, score, hole, outline of each part
  EXPECT_EQ(paths[0].operation, Operation::Outline);
  auto stage = [](const DrawnPath& p) {
    if (p.operation == Operation::Etch) return 0;
    if (p.operation == Operation::Score) return 1;
    return p.points.size() == 64 ? 2 : 3;  // holes before outer contours
  };
  for (size_t i = 2; i < paths.size(); ++i) EXPECT_LE(stage(paths[i - 1]), stage(paths[i])) << "path " << i;
  // The dissertation's colours from the profile.
  EXPECT_EQ(plan.sheets[0].colours.at(Operation::Cut), (Rgb{0, 0, 255}));
  EXPECT_EQ(plan.sheets[0].colours.at(Operation::Etch), (Rgb{255, 255, 0}));
}

TEST(SheetPlanner, WindowOrderReportsHowFarEachPartMoved) {
  std::vector<Part> parts;
  for (int i = 0; i < 30; ++i) {
    Part part = panel(i);
    const double w = 1 + (i * 7 % 11) * 0.6;  // mixed sizes, so the layout wants to reorder
    part.outline = {{0, 0}, {w, 0}, {w, 1.5}, {0, 1.5}};
    part.holes.clear();
    parts.push_back(part);
  }
  PlanOptions options;
  options.order = OrderMode::Window;
  options.window = 3;
  options.seconds = 0.5;
  const SheetPlan plan = planSheets(parts, workshop(), options, test::context());
  ASSERT_EQ(plan.parts.size(), parts.size());
  for (const PlannedPart& p : plan.parts) {
    EXPECT_EQ(p.moved, p.cuttingIndex - parts[p.part].order);
    EXPECT_LE(std::abs(p.moved), options.window) << parts[p.part].name;
  }
  EXPECT_GT(plan.utilization, 0.0);
  EXPECT_LE(plan.utilization, 1.0);
}

TEST(SheetPlanner, HoleNarrowerThanTheKerfIsRefusedByName) {
  std::vector<Part> parts{panel(0)};
  parts[0].holes = {circle({1, 1}, 0.004)};
  PlanOptions options;
  options.kerf = 0.01;
  try {
    planSheets(parts, workshop(), options, test::context());
    FAIL() << "accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "panel 1: hole 1 is narrower than the kerf (0.01 in)");
  }
}

TEST(SheetPlanner, WritesEpsSvgAndDxfForEverySheet) {
  std::vector<Part> parts;
  for (int i = 0; i < 3; ++i) parts.push_back(panel(i));
  PlanOptions options;
  options.seconds = 5;  // never spent: the first layout is on the one bed the parts' area needs
  options.title = "test";
  const SheetPlan plan = planSheets(parts, workshop(), options, test::context());
  test::TempDir dir;
  const auto files = writeSheets(plan, {true, true, true}, dir.path(), test::context());
  ASSERT_EQ(files.size(), plan.sheets.size());
  EXPECT_EQ(files[0], (std::vector<std::string>{"sheet-001.eps", "sheet-001.svg", "sheet-001.dxf"}));
  const std::string eps = test::readFile(dir.path() / "sheet-001.eps");
  EXPECT_EQ(eps.rfind("%!PS-Adobe-3.0 EPSF-3.0", 0), 0u);
  EXPECT_NE(eps.find("%%BoundingBox: 0 0 2304 1296"), std::string::npos);
  const auto gs = test::run("gs -q -dNOPAUSE -dBATCH -dSAFER -sDEVICE=bbox " + (dir.path() / "sheet-001.eps").string());
  EXPECT_EQ(gs.status, 0) << gs.err;
  // The green material outline spans the bed; the hairline adds a few hundredths of a point.
  const size_t at = gs.err.find("%%HiResBoundingBox:");
  ASSERT_NE(at, std::string::npos) << gs.err;
  double box[4] = {};
  std::istringstream(gs.err.substr(at + 19)) >> box[0] >> box[1] >> box[2] >> box[3];
  EXPECT_NEAR(box[0], 0, 0.1);
  EXPECT_NEAR(box[1], 0, 0.1);
  EXPECT_NEAR(box[2], 2304, 0.1);
  EXPECT_NEAR(box[3], 1296, 0.1);
}

// The sheets are as small as their meaning: a finely sampled outline comes
// out with far fewer corners, to 0.0001 in, and the SVG read back stays
// within 0.0002 in of the geometry everywhere (the largest distance either
// way between the written line and the outline as planned, measured).
TEST(SheetPlanner, SheetsKeepTheGeometryWithin0_0002InchesInFewCornersToATenThousandth) {
  Part part = panel(0);
  part.outline = circle({1.5, 1.5}, 1.5, 20000);  // a rail sampled every 0.0005 in
  part.holes = {circle({1.5, 1.5}, 0.0625, 720)};
  PlanOptions options;
  options.seconds = 5;  // never spent: the first layout is on the one bed the parts' area needs
  options.kerf = 0;
  const SheetPlan plan = planSheets({part}, workshop(), options, test::context());
  ASSERT_EQ(plan.sheets.size(), 1u);
  test::TempDir dir;
  writeSheets(plan, {false, true, false}, dir.path(), test::context());
  const std::string svg = test::readFile(dir.path() / "sheet-001.svg");
  EXPECT_FALSE(std::regex_search(svg, std::regex(R"([ML]-?\d+\.\d{5})"))) << "more than 4 decimals";
  const SheetDrawing read = readSheetSvg(dir.path() / "sheet-001.svg");
  const PlannedPart& placed = plan.parts.front();
  const auto lineDistance = [](const Point2& p, const std::vector<Point2>& line) {
    double best = 1e9;
    for (size_t i = 0; i < line.size(); ++i)
      best = std::min(best, core::distanceToSegment(p, line[i], line[(i + 1) % line.size()]));
    return best;
  };
  int checked = 0;
  for (const Polygon2* local : {&part.outline, &part.holes.front()}) {
    std::vector<Point2> planned;
    for (const Point2& p : *local) planned.push_back(onSheet(placed, p));
    // The written cut whose first corner is nearest the planned line.
    const DrawnPath* written = nullptr;
    for (const DrawnPath& path : read.paths) {
      if (path.operation != Operation::Cut) continue;
      if (!written || lineDistance(path.points.front(), planned) < lineDistance(written->points.front(), planned))
        written = &path;
    }
    ASSERT_NE(written, nullptr);
    EXPECT_LT(written->points.size(), local->size() / 10) << "not simplified";
    double deviation = 0;
    for (const Point2& p : planned) deviation = std::max(deviation, lineDistance(p, written->points));
    for (size_t i = 0; i < written->points.size(); ++i) {
      const Point2& a = written->points[i];
      const Point2& b = written->points[(i + 1) % written->points.size()];
      for (double t : {0.0, 0.25, 0.5, 0.75}) deviation = std::max(deviation, lineDistance(a + t * (b - a), planned));
    }
    EXPECT_LE(deviation, 0.0002) << written->points.size() << " corners";
    EXPECT_GT(deviation, 0.00005) << "simplified no more than the rounding";
    ++checked;
  }
  EXPECT_EQ(checked, 2);
}

TEST(SheetPlanner, SheetFormatsAreSpecsAndWhatTheMachineNamesOrWhatIsAsked) {
  profiles::MachineProfile machine = workshop();
  SheetFormats formats = defaultFormats(machine);
  EXPECT_TRUE(formats.eps && formats.svg && !formats.dxf);
  machine.formats = {"dxf"};
  formats = defaultFormats(machine);
  EXPECT_TRUE(formats.eps && formats.svg && formats.dxf);
  formats = formatsOf("dxf");
  EXPECT_TRUE(!formats.eps && !formats.svg && formats.dxf);
  formats = formatsOf("svg,eps");
  EXPECT_TRUE(formats.eps && formats.svg && !formats.dxf);
  for (const char* bad : {"", "pdf", "svg,,eps", "svg,"}) EXPECT_THROW(formatsOf(bad), std::invalid_argument) << bad;
}

}  // namespace
}  // namespace rotafab::jobs
