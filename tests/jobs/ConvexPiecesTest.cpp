// The no-fit polygons' building blocks (issue 3, item 2): convex pieces must
// tile the polygon exactly, the linear-time sum of two convex polygons must be
// their Minkowski sum, and a cell cover must hold every point of its region.

#include "jobs/nesting/CellCover.h"
#include "jobs/nesting/ConvexPieces.h"
#include "support/ClipperSupport.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

namespace rotafab::jobs::nesting {
namespace {

using ClipperLib::cInt;
using ClipperLib::IntPoint;
using ClipperLib::Path;
using ClipperLib::Paths;

using test::areaOf;
using test::boolean;

// Concave polygons on the grid: stars, wavy strips, combs, and random
// star-shaped polygons (every ray from the centre crosses the boundary once).
Path randomPolygon(std::mt19937& random) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Path p;
  const auto add = [&](double x, double y) { p.push_back({std::llround(x * 1e4), std::llround(y * 1e4)}); };
  switch (random() % 4) {
    case 0: {
      const int spikes = 3 + random() % 8;
      for (int i = 0; i < 2 * spikes; ++i) {
        const double r = (i % 2 ? 0.2 + 0.6 * unit(random) : 1.0) * (1 + 2 * unit(random));
        add(r * std::cos(std::numbers::pi * i / spikes), r * std::sin(std::numbers::pi * i / spikes));
      }
      break;
    }
    case 1: {
      const double length = 4 + 16 * unit(random), amplitude = unit(random), width = 0.3 + unit(random);
      const int steps = 8 + random() % 40;
      for (int i = 0; i <= steps; ++i) add(length * i / steps, amplitude * std::sin(4 * std::numbers::pi * i / steps));
      for (int i = steps; i >= 0; --i) {
        add(length * i / steps, width + amplitude * std::sin(4 * std::numbers::pi * i / steps));
      }
      break;
    }
    case 2: {  // a comb: teeth of random depth along a bar
      const int teeth = 2 + random() % 10;
      add(0, 0);
      add(2.0 * teeth, 0);
      for (int t = teeth - 1; t >= 0; --t) {
        const double depth = 1 + 3 * unit(random);
        add(2.0 * t + 1.5, 1), add(2.0 * t + 1.5, 1 + depth), add(2.0 * t + 0.5, 1 + depth), add(2.0 * t + 0.5, 1);
      }
      add(0, 1);
      break;
    }
    default: {
      const int n = 5 + random() % 40;
      for (int i = 0; i < n; ++i) {
        const double r = 0.3 + 3 * unit(random), a = 2 * std::numbers::pi * i / n;
        add(r * std::cos(a), r * std::sin(a));
      }
    }
  }
  if (random() % 2) std::reverse(p.begin(), p.end());  // either orientation is accepted
  return p;
}

TEST(ConvexPieces, TileThePolygonExactlyWithConvexPieces) {
  std::mt19937 random(20111);
  for (int trial = 0; trial < 300; ++trial) {
    const Path polygon = randomPolygon(random);
    SCOPED_TRACE("trial " + std::to_string(trial) + ", " + std::to_string(polygon.size()) + " vertices");
    const auto pieces = convexPieces(polygon);
    ASSERT_TRUE(pieces.has_value());
    double sum = 0;
    for (const Path& piece : *pieces) {
      ASSERT_GE(piece.size(), 3u);
      EXPECT_GT(ClipperLib::Area(piece), 0) << "counter-clockwise";
      for (size_t i = 0; i < piece.size(); ++i) {
        const IntPoint &a = piece[i], &b = piece[(i + 1) % piece.size()], &c = piece[(i + 2) % piece.size()];
        const __int128 turn =
            static_cast<__int128>(b.X - a.X) * (c.Y - b.Y) - static_cast<__int128>(b.Y - a.Y) * (c.X - b.X);
        EXPECT_GT(turn, 0) << "every corner turns left: the piece is convex";
      }
      sum += ClipperLib::Area(piece);
    }
    // Pieces with disjoint interiors whose areas add up to the polygon's, and
    // nothing of the polygon outside them: an exact tiling.
    const double area = std::abs(ClipperLib::Area(polygon));
    EXPECT_NEAR(sum, area, 1e-9 * area);
    EXPECT_NEAR(areaOf(boolean(ClipperLib::ctDifference, {polygon}, *pieces)), 0, 1e-9 * area);
    EXPECT_NEAR(std::abs(areaOf(boolean(ClipperLib::ctUnion, *pieces, {}))), area, 1e-9 * area);
  }
}

TEST(ConvexPieces, ConvexPolygonIsOnePiece) {
  const Path square{{0, 0}, {10, 0}, {10, 10}, {5, 10}, {0, 10}};  // a straight corner is dropped
  const auto pieces = convexPieces(square);
  ASSERT_TRUE(pieces.has_value());
  ASSERT_EQ(pieces->size(), 1u);
  EXPECT_EQ(pieces->front().size(), 4u);
}

TEST(ConvexPieces, SelfIntersectingPolygonIsRefused) {
  const Path bowTie{{0, 0}, {10, 10}, {10, 0}, {0, 10}};
  // Either refused, or pieces that still add up: never a wrong tiling silently.
  const auto pieces = convexPieces(bowTie);
  if (pieces) {
    double sum = 0;
    for (const Path& piece : *pieces) sum += ClipperLib::Area(piece);
    EXPECT_LE(sum, 100.0);
  }
  EXPECT_FALSE(convexPieces(Path{{0, 0}, {1, 1}}).has_value()) << "two points are no polygon";
}

// The convex hull of a point set (Andrew's monotone chain), counter-clockwise,
// without collinear points: the Minkowski sum of two convex polygons is the
// hull of the sums of their vertices, an independent exact reference.
Path convexHull(Path points) {
  std::sort(points.begin(), points.end(),
            [](const IntPoint& a, const IntPoint& b) { return a.X < b.X || (a.X == b.X && a.Y < b.Y); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  const auto cross = [](const IntPoint& o, const IntPoint& a, const IntPoint& b) {
    return static_cast<__int128>(a.X - o.X) * (b.Y - o.Y) - static_cast<__int128>(a.Y - o.Y) * (b.X - o.X);
  };
  Path hull(2 * points.size());
  size_t k = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

TEST(ConvexMinkowskiSum, IsTheHullOfTheVertexSums) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 500; ++trial) {
    // Random convex polygons: pieces of random concave ones.
    const auto a = convexPieces(randomPolygon(random));
    const auto b = convexPieces(randomPolygon(random));
    ASSERT_TRUE(a && b);
    const Path& p = (*a)[random() % a->size()];
    const Path& q = (*b)[random() % b->size()];
    Path sums;
    for (const IntPoint& u : p) {
      for (const IntPoint& v : q) sums.push_back({u.X + v.X, u.Y + v.Y});
    }
    const Path hull = convexHull(sums);
    const Path sum = convexMinkowskiSum(p, q);
    EXPECT_EQ(ClipperLib::Area(sum), ClipperLib::Area(hull)) << "trial " << trial;
    // Same region: every hull vertex is a vertex of the sum (which may keep straight corners).
    for (const IntPoint& v : hull) {
      EXPECT_NE(std::find(sum.begin(), sum.end(), v), sum.end()) << "trial " << trial;
    }
  }
}

TEST(CellCover, HoldsEveryPointOfTheRegionAndNothingFarFromIt) {
  std::mt19937 random(11);
  std::uniform_int_distribution<cInt> coordinate(-5000, 205000);
  for (int trial = 0; trial < 20; ++trial) {
    // A region with holes: a box minus random polygons, like a sheet's free space.
    Paths region{Path{{0, 0}, {200000, 0}, {200000, 100000}, {0, 100000}}};
    Paths taken;
    for (int i = 0; i < 12; ++i) {
      Path p = randomPolygon(random);
      const IntPoint at{coordinate(random), coordinate(random) / 2};
      for (IntPoint& v : p) v.X += at.X, v.Y += at.Y;
      if (ClipperLib::Area(p) < 0) std::reverse(p.begin(), p.end());
      taken.push_back(p);
    }
    region = boolean(ClipperLib::ctDifference, region, taken);
    const CellCover cover(region, {-10000, -10000, 210000, 110000}, 2500);
    std::uniform_int_distribution<cInt> x(-10000, 210000), y(-10000, 110000);
    int inside = 0;
    for (int i = 0; i < 4000; ++i) {
      const IntPoint p{x(random), y(random)};
      bool in = false;
      for (const Path& path : region) {
        if (ClipperLib::PointInPolygon(p, path) != 0) in = !in;  // even-odd over contours and holes
      }
      if (in) {
        ++inside;
        EXPECT_TRUE(cover.meets({p.X, p.Y, p.X, p.Y})) << "(" << p.X << ", " << p.Y << ") is in the region";
      }
    }
    EXPECT_GT(inside, 100);
    // A box far from any point of the region: a hole's inside, well away from its edge.
    EXPECT_FALSE(cover.meets({300000, 0, 400000, 100000}));
    EXPECT_FALSE(cover.empty());
    // The runs hold the region: nothing of it is left outside them.
    Paths runs;
    for (const Box& b : cover.runs()) runs.push_back(Path{{b[0], b[1]}, {b[2], b[1]}, {b[2], b[3]}, {b[0], b[3]}});
    EXPECT_NEAR(std::abs(areaOf(boolean(ClipperLib::ctDifference, region, runs))), 0, 1.0);
  }
}

TEST(CellCover, EmptyRegionMeetsNothing) {
  const CellCover cover({}, {0, 0, 1000, 1000}, 100);
  EXPECT_TRUE(cover.empty());
  EXPECT_FALSE(cover.meets({0, 0, 1000, 1000}));
}

}  // namespace
}  // namespace rotafab::jobs::nesting
