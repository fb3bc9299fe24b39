// Each woven panel lies in its own frame along its least box: no turn of its outline has a smaller axis-aligned box,
// and the box's longer side is along x. Measured by turning each outline through every half degree, apart from the
// hull-side construction that chose the frame.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "geometry/Primitives.h"
#include "geometry/WeaveStructure.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"

namespace rotafab::geometry {
namespace {

struct Box {
  double width = 0, height = 0;
};

Box boxTurnedBy(const Polyline2& outline, double radians) {
  const double c = std::cos(radians), s = std::sin(radians);
  double lowX = std::numeric_limits<double>::infinity(), highX = -lowX, lowY = lowX, highY = -lowX;
  for (const Point2& p : outline) {
    const double x = c * p.x() - s * p.y(), y = s * p.x() + c * p.y();
    lowX = std::min(lowX, x), highX = std::max(highX, x), lowY = std::min(lowY, y), highY = std::max(highY, y);
  }
  return {highX - lowX, highY - lowY};
}

void expectEachPanelAlongItsLeastBox(const Structure& structure) {
  ASSERT_FALSE(structure.panels.empty());
  for (const Panel& panel : structure.panels) {
    const Box box = boxTurnedBy(panel.outline, 0);
    EXPECT_GE(box.width, box.height - 1e-9) << "panel " << panel.id << ": its longer side along x";
    double least = std::numeric_limits<double>::infinity();
    for (int step = 1; step < 360; ++step) {
      const Box turned = boxTurnedBy(panel.outline, step * std::numbers::pi / 360);
      least = std::min(least, turned.width * turned.height);
    }
    EXPECT_LE(box.width * box.height, least * (1 + 1e-9)) << "panel " << panel.id;
  }
}

TEST(PanelFrames, EveryWovenPanelLiesAlongItsLeastBox) {
  PolygonMesh mesh = test::atConstructionSize(truncatedIcosahedron());
  requireUsable(analyzeMesh(mesh));
  expectEachPanelAlongItsLeastBox(buildWeaveStructure(mesh, {}, test::context()));
}

}  // namespace
}  // namespace rotafab::geometry
