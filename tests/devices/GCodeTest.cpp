// GRBL's G-code for a toolpath (devices/grbl/GCode.h): it parses back to
// the same paths with the right S and F for each operation, and the laser
// off at the end.

#include "devices/grbl/GCode.h"

#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "profiles/Profiles.h"
#include "support/TestSheets.h"
#include "toolpath/Toolpath.h"

namespace rotafab::devices::grbl {
namespace {

using namespace jobs;
using test::grblMachine;
using test::sheet;

TEST(GCode, ParsesBackToTheSamePathsWithEachOperationsPowerAndFeed) {
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

}  // namespace
}  // namespace rotafab::devices::grbl
