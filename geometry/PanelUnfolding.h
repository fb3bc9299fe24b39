#pragma once
// Unfolding a vertex panel (dissertation V.4, with IV.3's triangle-strip
// unfolding, StripUnfolding.h): the planar vertex band is laid flat in its
// own plane, seen from outside, and each edge band is developed from the
// vertex band's side it hangs on, triangle by triangle, the first on the
// outside of the vertex band's side. Both copies of a band are developed
// from the same triangles, one from each end, so they are congruent: a point
// of the band (its triangle and barycentric coordinates) lies at the same
// distances on both panels.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "core/Polygon2.h"
#include "geometry/DevelopableBands.h"

namespace rotafab::geometry {

using core::crossesItself;
using core::distanceToOutline;
using core::insidePolygon;
using core::Point2;
using core::signedArea;

struct FlatBand {
  int edge = -1;
  bool fromA = true;            // hangs on face A's side (the panel is face A), else on face B's
  std::vector<Point2> points;   // of EdgeBand::point(i), i = 0 .. 2k+1, in the panel's frame
  std::vector<Point2> outline;  // the band alone, counter-clockwise, its side on the vertex band included
  // Cut off its panel (detachBand()): then cut as a piece of its own, the
  // band and a tab over the vertex band, fastened to it through `tab`.
  bool detached = false;
  std::vector<Point2> pieceOutline;  // counter-clockwise, in the panel's frame
  std::vector<Point2> tabOutline;    // the tab alone: the band's side (from, to), then over the vertex band
  Point2 tab = Point2::Zero();       // the extra fastener's hole, on the piece and on the vertex band
  bool tabGlued = false;             // the tab has no room for that hole and is glued instead
  // Cut across its middle (halveBand()): `outline` is then the near half,
  // which stays on the panel, and `pieceOutline` the far half, a piece of
  // its own. Each half carries one of the band's holes, and the other copy,
  // whole, holds both: it bridges the cut.
  bool halved = false;

  // Whether a point of this copy is on a piece cut from its panel.
  [[nodiscard]] bool onPiece(const Point2& p) const { return detached || (halved && insidePolygon(pieceOutline, p)); }

  // The point (s, t) of this copy: s from face A's side (0) to face B's (1)
  // along the rails, t from rail U (0) to rail V (1), bilinear in each segment.
  [[nodiscard]] Point2 at(double s, double t) const;
};

struct FlatPanel {
  int face = -1;
  // The vertex band's plane: panel point (x, y) is origin + x * xAxis + y * yAxis.
  Point3 origin, xAxis, yAxis;
  std::vector<Point2> vertexBand;  // the corners, counter-clockwise
  std::vector<FlatBand> bands;     // one per interior edge of the face, in the order of its sides
  std::vector<int> bandOfSide;     // side i (corner i to i+1) -> index into bands, -1 on a boundary edge
  std::vector<Point2> outline;     // the cut contour, counter-clockwise, not closed
};

// Throws std::invalid_argument if a band has a side of zero length (a degenerate face).
FlatPanel unfoldPanel(const RotationSystem& rs, const BandDecomposition& decomposition,
                      const std::vector<EdgeBand>& bands, int face);

// V.4's remedy for a panel that would overlap itself: band `index` is cut
// off and becomes a piece of its own, the band plus a tab over the vertex
// band along their common side (the vertex band clipped to `depth` from
// that side: all of it where it is shallower), fastened back through one
// extra hole in the tab (`tab`: its corners' mean until the caller places
// it). The panel's outline loses the band. Throws std::invalid_argument
// when the vertex band is not convex or the piece would cross itself; the
// panel is then left half changed (detach a copy).
void detachBand(FlatPanel& panel, int index, double depth);

// The other remedy, for a band whose tab has no room (V.4 leaves the cut
// open): band `index` is cut across at its middle, s = 1/2, between the two
// holes of its length; the near half stays on the panel and the far half
// becomes a piece. The other copy of the band must stay whole. Throws
// std::invalid_argument when the far half would cross itself; the panel is
// then left half changed (halve a copy).
void halveBand(FlatPanel& panel, int index);

// Pairs of the panel's pieces that overlap: -1 for the vertex band, else an
// index into bands; (i, i) for a piece that crosses itself. Empty when no
// two pieces' outlines cross, none holds another's middle, and none
// crosses itself. Bands cut off (detachBand()) are no longer pieces of the
// panel and are skipped. (Developed triangles never turn over: each goes on
// the far side of the edge it shares, so a fold shows only as crossing outlines.)
std::vector<std::pair<int, int>> overlappingPieces(const FlatPanel& panel);

}  // namespace rotafab::geometry
