#pragma once
// Unfolding a vertex panel (dissertation V.4, with IV.3's triangle-strip
// unfolding): the planar vertex band is laid flat in its own plane, seen
// from outside, and each edge band is developed from the vertex band's side
// it hangs on, triangle by triangle: each triangle keeps its three edge
// lengths and goes on the far side of the edge it shares with the one before
// (the first on the outside of the vertex band's side). Both copies of a band
// are developed from the same triangles, one from each end, so they are
// congruent: a point of the band (its triangle and barycentric coordinates)
// lies at the same distances on both panels.

#include <Eigen/Core>
#include <array>
#include <vector>

#include "geometry/DevelopableBands.h"

namespace rotafab::geometry {

using Point2 = Eigen::Vector2d;

struct FlatBand {
  int edge = -1;
  bool fromA = true;            // hangs on face A's side (the panel is face A), else on face B's
  std::vector<Point2> points;   // of EdgeBand::point(i), i = 0 .. 2k+1, in the panel's frame
  std::vector<Point2> outline;  // the band alone, counter-clockwise, its side on the vertex band included
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

// Signed area (positive counter-clockwise).
double signedArea(const std::vector<Point2>& polygon);

// Pairs of the panel's pieces that overlap: -1 for the vertex band, else an
// index into bands; (i, i) for a piece that crosses itself. Empty when no
// two pieces' outlines cross, none holds another's middle, and none
// crosses itself. (Developed triangles never turn over: each goes on the
// far side of the edge it shares, so a fold shows only as crossing outlines.)
std::vector<std::pair<int, int>> overlappingPieces(const FlatPanel& panel);

}  // namespace rotafab::geometry
