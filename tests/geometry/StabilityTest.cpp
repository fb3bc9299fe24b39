// Will it stand? (geometry/Stability.h): the centre of mass of the panels
// as built, the footprint they rest on, the margin between the two, and
// where to hang a structure that tips, on shapes whose answers are known.

#include "geometry/Stability.h"

#include <gtest/gtest.h>

namespace rotafab::geometry {
namespace {

// A panel that is one 3D quadrilateral (its area the quad's).
Panel quadPanel(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  Panel panel;
  panel.surface = {{a, b, c, d}};
  panel.area = 0.5 * ((b - a).cross(c - a).norm() + (c - a).cross(d - a).norm());
  return panel;
}

// A box whose bottom is the unit square [0,1] x [0,1] on the ground (y = 0
// with y up) and whose top, `height` above, runs from `left` to `right`
// along x: a cube for 0 and 1.
Structure flaredBox(double height, double left, double right, int up = 1) {
  // Corners in (x, z) on the ground; a point's up coordinate goes to axis `up`.
  const auto at = [&](double x, double h, double z) {
    Point3 p;
    p[(up + 1) % 3] = z;  // the frame's first ground axis
    p[(up + 2) % 3] = x;
    p[up] = h;
    return p;
  };
  const Point3 b0 = at(0, 0, 0), b1 = at(1, 0, 0), b2 = at(1, 0, 1), b3 = at(0, 0, 1);
  const Point3 t0 = at(left, height, 0), t1 = at(right, height, 0), t2 = at(right, height, 1), t3 = at(left, height, 1);
  Structure structure;
  structure.panels = {quadPanel(b0, b1, b2, b3), quadPanel(t0, t1, t2, t3), quadPanel(b0, b1, t1, t0),
                      quadPanel(b1, b2, t2, t1), quadPanel(b2, b3, t3, t2), quadPanel(b3, b0, t0, t3)};
  for (size_t i = 0; i < structure.panels.size(); ++i) structure.panels[i].id = static_cast<int>(i) + 1;
  return structure;
}

// The same box with its top moved by `lean` along x: a leaning tower for more than its width.
Structure leaningBox(double height, double lean, int up = 1) { return flaredBox(height, lean, 1 + lean, up); }

TEST(Stability, ACubeStandsWithHalfItsSideToSpare) {
  StabilityOptions options;
  options.gramsPerSquareInch = 0.25;
  const Stability s = structureStability(leaningBox(1, 0), options);
  EXPECT_TRUE(s.stands);
  EXPECT_NEAR(s.margin, 0.5, 1e-12);
  EXPECT_TRUE(s.centerOfMass.isApprox(Point3(0.5, 0.5, 0.5), 1e-12)) << s.centerOfMass.transpose();
  ASSERT_TRUE(s.massKg.has_value());
  EXPECT_NEAR(*s.massKg, 6 * 0.25 / 1000, 1e-12);
  ASSERT_EQ(s.footprint.size(), 4u);
  for (const Point3& p : s.footprint) EXPECT_EQ(p.y(), 0.0);
  EXPECT_TRUE(s.hangPoints.empty());
}

TEST(Stability, ALeaningTowerTipsAndIsHungAboveItsCentre) {
  // Top moved 3 along x over a height of 4: the centre of mass is over
  // x = 2 (every panel is symmetric about the tower's middle), 1 beyond the base.
  const Stability s = structureStability(leaningBox(4, 3), StabilityOptions{});
  EXPECT_FALSE(s.stands);
  EXPECT_NEAR(s.margin, -1.0, 1e-9);
  EXPECT_NEAR(s.centerOfMass.x(), 2.0, 1e-9);
  EXPECT_NEAR(s.centerOfMass.y(), 2.0, 1e-9);
  EXPECT_FALSE(s.massKg.has_value()) << "no areal density, no mass";
  // Every point above the centre of mass is over the top, beyond it: the
  // nearest pair seen from above is the top's near side.
  ASSERT_EQ(s.hangPoints.size(), 2u);
  for (const Point3& p : s.hangPoints) {
    EXPECT_EQ(p.y(), 4.0);
    EXPECT_EQ(p.x(), 3.0);
  }
}

TEST(Stability, ATopHeavyFunnelIsHungFromPointsWithItsCentreBetweenThem) {
  // Its top runs from -1 to 6 over a base from 0 to 1: the centre of mass is
  // over x > 1, so it tips; its top spreads on both sides of it.
  const Stability s = structureStability(flaredBox(4, -1, 6), StabilityOptions{});
  EXPECT_FALSE(s.stands);
  EXPECT_GT(s.centerOfMass.x(), 1.0);
  EXPECT_NEAR(s.margin, 1.0 - s.centerOfMass.x(), 1e-9);
  ASSERT_EQ(s.hangPoints.size(), 2u);
  const Point3 &p = s.hangPoints[0], &q = s.hangPoints[1];
  EXPECT_GT(p.y(), s.centerOfMass.y());
  EXPECT_GT(q.y(), s.centerOfMass.y());
  // Seen from above the centre of mass lies between them, and near the
  // segment (the structure's points are the box's corners: a diagonal of
  // the top passes 0.09 in from it): hung from both, each string pulls up
  // and it hangs, all but level, as built.
  const Eigen::Vector2d a(p.x(), p.z()), b(q.x(), q.z()), c(s.centerOfMass.x(), s.centerOfMass.z());
  const double t = (c - a).dot(b - a) / (b - a).squaredNorm();
  EXPECT_GT(t, 0);
  EXPECT_LT(t, 1);
  EXPECT_LT((a + t * (b - a) - c).norm(), 0.1) << p.transpose() << " / " << q.transpose();
  EXPECT_GE((a - b).norm(), 7.0) << "the widest such pair: across the top";
}

TEST(Stability, TheUpAxisIsTheOneAsked) {
  for (int up : {0, 1, 2}) {
    StabilityOptions options;
    options.up = up;
    EXPECT_TRUE(structureStability(leaningBox(1, 0.4, up), options).stands) << up;
    EXPECT_FALSE(structureStability(leaningBox(1, 2.0, up), options).stands) << up;
    for (const Point3& p : structureStability(leaningBox(1, 2.0, up), options).footprint) EXPECT_EQ(p[up], 0.0);
  }
  StabilityOptions wrong;
  wrong.up = 3;
  EXPECT_THROW(structureStability(leaningBox(1, 0), wrong), std::invalid_argument);
  EXPECT_THROW(structureStability(Structure{}, StabilityOptions{}), std::invalid_argument);
}

TEST(Stability, FastenersWeighWhereTheirHolesAre) {
  // Heavy fasteners in the holes of the top panel only pull the centre of mass up.
  Structure box = leaningBox(1, 0);
  box.panels[1].holes.resize(4);
  box.fasteners = 2;
  StabilityOptions options;
  options.gramsPerSquareInch = 1;
  options.gramsPerFastener = 3;  // 6 g in the top, against 6 g of board
  const Stability s = structureStability(box, options);
  // Board: 6 g at height 0.5; fasteners: 6 g at height 1 -> 0.75.
  EXPECT_NEAR(s.centerOfMass.y(), 0.75, 1e-12);
  EXPECT_NEAR(*s.massKg, 0.012, 1e-12);
}

TEST(Stability, PointsNearTheLowestRestOnTheGroundToo) {
  // A cube whose bottom sags by less than the tolerance at one corner still stands on four.
  Structure box = leaningBox(10, 0);
  box.panels[0].surface[0][2].y() = -0.05;  // within 1% of 10 in
  const Stability s = structureStability(box, StabilityOptions{});
  EXPECT_EQ(s.footprint.size(), 4u);
  EXPECT_TRUE(s.stands);
}

}  // namespace
}  // namespace rotafab::geometry
