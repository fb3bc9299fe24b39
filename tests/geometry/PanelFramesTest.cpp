// Each woven panel lies in its own frame along its least box: no turn of its outline has a smaller axis-aligned box,
// and the box's longer side is along x. Measured by turning each outline through every half degree, apart from the
// hull-side construction that chose the frame.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "core/Polygon2.h"
#include "geometry/Primitives.h"
#include "geometry/Structure.h"
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

// Everything on a panel turns with its outline, as one rigid piece: each
// hole, label box corner, stroke, score and piece point keeps its distance
// from two corners of the outline.
TEST(PanelFrames, APanelsHolesLabelsScoresAndPiecesTurnWithItsOutline) {
  const double turn = 0.52;  // radians: a 4 x 1 rectangle lying at about 30 degrees
  const auto at = [&](double x, double y) {
    return Point2(std::cos(turn) * x - std::sin(turn) * y + 3, std::sin(turn) * x + std::cos(turn) * y - 1);
  };
  Panel panel;
  panel.outline = {at(0, 0), at(4, 0), at(4, 1), at(0, 1)};
  panel.holes = {{3, at(0.5, 0.5), 0.125}};
  PanelLabel label{"12", 12, LabelRole::Up, {}, {{at(1, 0.3), at(1.3, 0.6)}}};
  label.box.origin = at(1, 0.3);
  label.box.angle = turn + 0.1;
  label.box.along = Point2(std::cos(label.box.angle), std::sin(label.box.angle));
  label.box.width = 0.6, label.box.height = 0.2;
  panel.labels = {label};
  panel.scores = {{at(2, 0), at(2, 1)}};
  PanelPiece piece;
  piece.outline = {at(3, 0), at(4, 0), at(4, 1)};
  piece.holes = {{0, at(3.7, 0.3), 0.125}};
  piece.labels = {label};
  panel.pieces = {piece};

  std::vector<Point2> before;
  const auto gather = [](const Panel& p) {
    std::vector<Point2> points(p.outline.begin(), p.outline.end());
    for (const auto& hole : p.holes) points.push_back(hole.xy);
    for (const auto* labels : {&p.labels, &p.pieces[0].labels}) {
      for (const auto& l : *labels) {
        for (const Point2& corner : l.box.corners()) points.push_back(corner);
        for (const auto& stroke : l.strokes) points.insert(points.end(), stroke.begin(), stroke.end());
      }
    }
    for (const auto& score : p.scores) points.insert(points.end(), score.begin(), score.end());
    points.insert(points.end(), p.pieces[0].outline.begin(), p.pieces[0].outline.end());
    for (const auto& hole : p.pieces[0].holes) points.push_back(hole.xy);
    return points;
  };
  before = gather(panel);
  std::vector<Panel> panels{panel};
  layPanelsAlongTheirLeastBoxes(panels, test::context());
  const std::vector<Point2> after = gather(panels[0]);
  ASSERT_EQ(after.size(), before.size());
  for (size_t i = 0; i < before.size(); ++i) {
    for (size_t corner : {0, 1}) {
      EXPECT_NEAR((after[i] - after[corner]).norm(), (before[i] - before[corner]).norm(), 1e-9) << "point " << i;
    }
    // Turned, not mirrored: the same side of the outline's first side.
    EXPECT_NEAR(core::cross(after[1] - after[0], after[i] - after[0]),
                core::cross(before[1] - before[0], before[i] - before[0]), 1e-9)
        << "point " << i;
  }
  const Box box = boxTurnedBy(panels[0].outline, 0);
  EXPECT_NEAR(box.width, 4, 1e-9);
  EXPECT_NEAR(box.height, 1, 1e-9);
  EXPECT_NEAR(panels[0].labels[0].box.along.norm(), 1, 1e-12);
}

}  // namespace
}  // namespace rotafab::geometry
