// The nester's shapes (jobs/nesting/Shapes.h): made in one rotation and
// turned exactly on the grid for the other quarter turns, each holds its
// outline grown by half the spacing, with its core and poles inside it;
// they are built as they are asked for, and the bound on the largest pole
// that the first layout's raster is capped at holds before they are.
#include "jobs/nesting/Shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "support/ClipperSupport.h"
#include "support/NestingParts.h"
#include "support/TestContext.h"

namespace rotafab::jobs::nesting {
namespace {

// The nester's test parts, the last with a turn that is no quarter: made again, not turned.
std::vector<NestingPart> testParts(unsigned seed, int count) {
  std::vector<NestingPart> parts = test::randomParts(seed, count);
  parts.back().rotations = {0, 45, 90, 270};
  return parts;
}

using test::areaOf;
using test::boolean;

double distanceToEdges(const Path& polygon, IntPoint p) {
  double best = std::numeric_limits<double>::max();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const IntPoint &a = polygon[i], &b = polygon[(i + 1) % polygon.size()];
    const double dx = static_cast<double>(b.X - a.X), dy = static_cast<double>(b.Y - a.Y);
    const double t = std::clamp(((p.X - a.X) * dx + (p.Y - a.Y) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    best = std::min(best, std::hypot(p.X - (a.X + t * dx), p.Y - (a.Y + t * dy)));
  }
  return best;
}

TEST(NestingShapes, EveryRotationHoldsItsOutlineGrownByHalfTheSpacingWithItsCoreAndPolesInside) {
  const auto parts = testParts(3, 12);
  NestingOptions options;
  options.spacing = 0.0625;
  PartShapes shapes(parts, options, test::context());
  shapes.buildAll(test::context());
  for (size_t i = 0; i < parts.size(); ++i) {
    for (size_t k = 0; k < parts[i].rotations.size(); ++k) {
      SCOPED_TRACE(parts[i].name + " at " + std::to_string(parts[i].rotations[k]) + " degrees");
      const Shape& shape = shapes.at(static_cast<int>(i), static_cast<int>(k));
      EXPECT_EQ(shape.rotation, parts[i].rotations[k]);
      const Path outline = toPath(rotated(parts[i].outline, parts[i].rotations[k]));
      const Box box = boxOf(outline);
      EXPECT_EQ((Box{shape.minX, shape.minY, shape.maxX, shape.maxY}), box);
      EXPECT_GT(ClipperLib::Area(shape.grown), 0) << "counter-clockwise";
      // Grown by half the spacing (less two grid units for rounding) and
      // nothing of it outside the shape.
      const Path needed = grown(outline, options.spacing / 2 - 2 / kScale, ClipperLib::jtRound);
      EXPECT_LT(areaOf(boolean(ClipperLib::ctDifference, {needed}, {shape.grown})), 1.0);
      EXPECT_EQ(boxOf(shape.grown), (Box{shape.grownMinX, shape.grownMinY, shape.grownMaxX, shape.grownMaxY}));
      EXPECT_LT(areaOf(boolean(ClipperLib::ctDifference, {shape.core}, {shape.grown})), 1.0);
      EXPECT_EQ(boxOf(shape.core), shape.coreBox);
      ASSERT_FALSE(shape.poles.empty());
      for (const Shape::Pole& pole : shape.poles) {
        EXPECT_EQ(ClipperLib::PointInPolygon(pole.centre, shape.grown), 1);
        EXPECT_GE(distanceToEdges(shape.grown, pole.centre), pole.radius - 1.0);
      }
      EXPECT_LE(shape.poles.front().radius, shapes.largestPoleBound());
    }
  }
}

// Forty spiky stars, whose boxes promise more than their poles hold, and
// a square whose pole is larger than all of theirs though its box is
// smaller: the bound must still cover it.
TEST(NestingShapes, AreBuiltAsAskedAndTheLargestPoleIsBoundedBefore) {
  std::vector<NestingPart> parts;
  for (int i = 0; i < 40; ++i) {
    NestingPart star;
    star.name = "star " + std::to_string(i + 1);
    star.order = i;
    for (int k = 0; k < 16; ++k) {
      const double angle = std::numbers::pi * k / 8 + 0.01 * i, r = k % 2 ? 0.5 : 3.0;
      star.outline.emplace_back(r * std::cos(angle), r * std::sin(angle));
    }
    parts.push_back(std::move(star));
  }
  NestingPart square;
  square.name = "square";
  square.order = 40;
  square.outline = {{0, 0}, {2.5, 0}, {2.5, 2.5}, {0, 2.5}};
  parts.push_back(square);
  NestingOptions options;
  PartShapes shapes(parts, options, test::context());
  const double bound = shapes.largestPoleBound();
  int built = 0;
  for (size_t i = 0; i < parts.size(); ++i) built += shapes.built(static_cast<int>(i)) ? 1 : 0;
  EXPECT_LT(built, static_cast<int>(parts.size())) << "only the parts that could hold the largest pole";
  EXPECT_FALSE(shapes.built(40));
  const std::vector<int> asked{40, 39, 39};
  shapes.build(asked, test::context());
  EXPECT_TRUE(shapes.built(40));
  EXPECT_TRUE(shapes.built(39));
  EXPECT_NEAR(shapes.area(40), std::pow((2.5 + options.spacing) * kScale, 2), 0.02 * 2.5 * 2.5 * kScale * kScale);
  shapes.buildAll(test::context());
  double largest = 0;
  for (size_t i = 0; i < parts.size(); ++i) {
    for (const Shape& shape : shapes.of(static_cast<int>(i))) largest = std::max(largest, shape.poles.front().radius);
  }
  EXPECT_NEAR(largest, shapes.at(40, 0).poles.front().radius, 1e-9) << "the square's";
  EXPECT_LE(largest, bound);
  EXPECT_EQ(shapes.largestPoleBound(), largest) << "exact once every shape is built";
}

}  // namespace
}  // namespace rotafab::jobs::nesting
