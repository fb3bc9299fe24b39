// A band cut off its panel (geometry/PanelUnfolding.h, detachBand()): its
// tab is the vertex band up to the depth asked from the band's side, all of
// it where the vertex band is shallower, so that it always lies on the
// vertex band; the piece is the band and the tab, the panel loses the band.
// Or a band cut across its middle (halveBand()).

#include "geometry/PanelUnfolding.h"

#include <gtest/gtest.h>

namespace rotafab::geometry {
namespace {

// A panel whose vertex band is the triangle (0,0), (4,0), (2, apex) with one
// band, a 4 x 1 rectangle, hanging below its first side.
FlatPanel trianglePanel(double apex) {
  FlatPanel panel;
  panel.vertexBand = {{0, 0}, {4, 0}, {2, apex}};
  FlatBand band;
  band.edge = 7;
  band.outline = {{0, 0}, {0, -1}, {4, -1}, {4, 0}};
  panel.bands = {band};
  panel.bandOfSide = {0, -1, -1};
  panel.outline = {{0, 0}, {0, -1}, {4, -1}, {4, 0}, {2, apex}};
  return panel;
}

TEST(DetachBand, AShallowVertexBandIsAllTab) {
  FlatPanel panel = trianglePanel(0.3);
  detachBand(panel, 0, 0.375);
  const FlatBand& band = panel.bands[0];
  ASSERT_TRUE(band.detached);
  EXPECT_EQ(band.tabOutline, (std::vector<Point2>{{0, 0}, {4, 0}, {2, 0.3}}));
  EXPECT_EQ(band.pieceOutline, (std::vector<Point2>{{0, 0}, {0, -1}, {4, -1}, {4, 0}, {2, 0.3}}));
  EXPECT_NEAR(signedArea(band.pieceOutline), 4 + 0.6, 1e-12);
  EXPECT_EQ(panel.outline, panel.vertexBand) << "the panel is its vertex band now";
}

TEST(DetachBand, ADeepVertexBandGivesATabOfTheDepthAsked) {
  FlatPanel panel = trianglePanel(2);
  detachBand(panel, 0, 0.5);
  const std::vector<Point2>& tab = panel.bands[0].tabOutline;
  ASSERT_EQ(tab.size(), 4u);
  EXPECT_EQ(tab[0], Point2(0, 0));
  EXPECT_EQ(tab[1], Point2(4, 0));
  EXPECT_TRUE(tab[2].isApprox(Point2(3.5, 0.5))) << tab[2].transpose();
  EXPECT_TRUE(tab[3].isApprox(Point2(0.5, 0.5))) << tab[3].transpose();
  for (const Point2& p : tab) {
    EXPECT_TRUE(insidePolygon(panel.vertexBand, p) || distanceToOutline(panel.vertexBand, p) < 1e-12) << p.transpose();
  }
  EXPECT_NEAR(signedArea(tab), 0.5 * (4 + 3) * 0.5, 1e-12);  // a trapezoid 0.5 deep
}

TEST(DetachBand, ANonConvexVertexBandIsRefused) {
  FlatPanel panel = trianglePanel(2);
  panel.vertexBand = {{0, 0}, {4, 0}, {4, 2}, {2, 0.5}, {0, 2}};
  panel.bandOfSide = {0, -1, -1, -1, -1};
  EXPECT_THROW(detachBand(panel, 0, 0.5), std::invalid_argument);
}

// The other remedy: the band cut across at s = 1/2. Its near half stays on
// the panel, its far half is a piece; together they are the band, each
// counter-clockwise, and a point is on the piece exactly when it is beyond the cut.
TEST(HalveBand, TheHalvesAreTheBandCutAcrossItsMiddle) {
  FlatPanel panel = trianglePanel(2);
  FlatBand& band = panel.bands[0];
  // Two segments: rail U down the left side (from the panel's side, s = 0), rail V down the right.
  band.points = {{0, 0}, {0, -0.5}, {0, -1}, {4, 0}, {4, -0.5}, {4, -1}};
  band.outline = {{0, 0}, {0, -0.5}, {0, -1}, {4, -1}, {4, -0.5}, {4, 0}};
  halveBand(panel, 0);
  ASSERT_TRUE(band.halved);
  EXPECT_FALSE(band.detached);
  EXPECT_EQ(band.outline, (std::vector<Point2>{{0, 0}, {0, -0.5}, {4, -0.5}, {4, 0}}));
  EXPECT_EQ(band.pieceOutline, (std::vector<Point2>{{0, -0.5}, {0, -1}, {4, -1}, {4, -0.5}}));
  EXPECT_NEAR(signedArea(band.outline) + signedArea(band.pieceOutline), 4, 1e-12);
  EXPECT_EQ(panel.outline, (std::vector<Point2>{{0, 0}, {0, -0.5}, {4, -0.5}, {4, 0}, {2, 2}}));
  EXPECT_TRUE(band.onPiece({1, -0.75}));
  EXPECT_FALSE(band.onPiece({1, -0.25}));
  EXPECT_FALSE(band.onPiece({2, 1})) << "the vertex band stays on the panel";
  EXPECT_THROW(halveBand(panel, 0), std::invalid_argument) << "a band is cut across once";
}

}  // namespace
}  // namespace rotafab::geometry
