// growUntilRoom (Structure.h): a structure whose holes have no room is built
// again larger. A weave's offset does not grow with the mesh, so the scale
// its crossings ask for falls short: growing goes on while each attempt
// leaves fewer without room, and stops where it does not, or at the most.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "geometry/FastenerHoles.h"
#include "geometry/Structure.h"
#include "support/TestContext.h"

namespace rotafab::geometry {
namespace {

PolygonMesh triangleOfSide(double side) {
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {side, 0, 0}, {0, side, 0}};
  mesh.faces = {{0, 1, 2}};
  return mesh;
}

// A build that needs the mesh `needed` large and, at `side`, asks for
// `asked(side)` times more, with `withoutRoom(side)` places lacking room.
struct FakeBuild {
  double needed;
  std::function<double(double)> asked;
  std::function<int(double)> withoutRoom;
  int attempts = 0;
  Structure operator()(const PolygonMesh& mesh) {
    ++attempts;
    const double side = mesh.positions[1].x();
    if (side >= needed * 0.99) return Structure{};  // as a hole with room to spare
    NoRoomForHoleError error("edge 1: no room", withoutRoom(side), asked(side), 0.125);
    throw error;
  }
};

TEST(GrowUntilRoom, GrowsOnWhileEachAttemptLeavesFewerWithoutRoom) {
  // As CGAL's knot2 woven: each attempt asks for three quarters of what it lacks (in scale's logarithm).
  FakeBuild build{2.0, [](double side) { return std::pow(2.0 / side, 0.75); },
                  [](double side) { return static_cast<int>(1000 * (2.0 - side)) + 1; }};
  PolygonMesh mesh = triangleOfSide(1.0);
  const GrownStructure grown = growUntilRoom(
      mesh, [&](const PolygonMesh& m) { return build(m); }, test::context());
  EXPECT_GT(build.attempts, kGrowAttempts);
  EXPECT_LE(build.attempts, kMostGrowAttempts);
  EXPECT_GE(mesh.positions[1].x(), 2.0 * 0.99);
  EXPECT_NEAR(grown.grown, mesh.positions[1].x(), 1e-9);
}

TEST(GrowUntilRoom, StopsWhereAnAttemptLeavesNoFewerAndAtTheMost) {
  // No fewer after the third attempt: the third's error, no fourth.
  FakeBuild stuck{10.0, [](double) { return 1.1; }, [](double) { return 7; }};
  PolygonMesh mesh = triangleOfSide(1.0);
  EXPECT_THROW(growUntilRoom(
                   mesh, [&](const PolygonMesh& m) { return stuck(m); }, test::context()),
               NoRoomForHoleError);
  EXPECT_EQ(stuck.attempts, kGrowAttempts);

  // Fewer each time, but never enough: kMostGrowAttempts, then its error.
  FakeBuild short_{100.0, [](double) { return 1.1; }, [](double side) { return static_cast<int>(1000 / side); }};
  mesh = triangleOfSide(1.0);
  try {
    growUntilRoom(
        mesh, [&](const PolygonMesh& m) { return short_(m); }, test::context());
    FAIL() << "built";
  } catch (const NoRoomForHoleError& error) {
    EXPECT_EQ(error.bands, static_cast<int>(1000 / mesh.positions[1].x()));
  }
  EXPECT_EQ(short_.attempts, kMostGrowAttempts);
}

}  // namespace
}  // namespace rotafab::geometry
