#include "geometry/PanelUnfolding.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/StripUnfolding.h"

namespace rotafab::geometry {

Point2 FlatBand::at(double s, double t) const {
  const int segments = static_cast<int>(points.size()) / 2 - 1;
  const double x = s * segments;
  const int i = std::min(static_cast<int>(x), segments - 1);
  const double along = x - i;
  const Point2 u = (1 - along) * points[i] + along * points[i + 1];
  const Point2 v = (1 - along) * points[segments + 1 + i] + along * points[segments + 2 + i];
  return (1 - t) * u + t * v;
}

namespace {

// Develops `band` from its side on the panel's vertex band (its two points
// already placed in `points`), triangle by triangle from that end.
void develop(const EdgeBand& band, bool fromA, std::vector<Point2>& points, const Point2& inside) {
  std::vector<Point3> space;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) space.push_back(band.point(i));
  auto triangles = band.triangles();
  if (!fromA) std::reverse(triangles.begin(), triangles.end());
  std::vector<char> placed(points.size(), 0);
  const int k = band.segments();
  placed[fromA ? 0 : k] = placed[fromA ? k + 1 : 2 * k + 1] = 1;
  try {
    unfoldStrip(space, triangles, points, placed, inside);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("a band has a side of zero length");
  }
}

// The cut contour: the vertex band's corners, each side but those of
// detached bands going out around its band.
void rebuildOutline(FlatPanel& panel) {
  panel.outline.clear();
  for (size_t side = 0; side < panel.vertexBand.size(); ++side) {
    panel.outline.push_back(panel.vertexBand[side]);
    const int b = panel.bandOfSide[side];
    if (b < 0 || panel.bands[b].detached) continue;
    // Closed by the side from its end back to its start: counter-clockwise, as the panel's outline runs.
    const auto& band = panel.bands[b].outline;
    panel.outline.insert(panel.outline.end(), band.begin() + 1, band.end() - 1);
  }
}

}  // namespace

void detachBand(FlatPanel& panel, int index, double depth) {
  const int sides = static_cast<int>(panel.vertexBand.size());
  const int side =
      static_cast<int>(std::find(panel.bandOfSide.begin(), panel.bandOfSide.end(), index) - panel.bandOfSide.begin());
  const Point2& from = panel.vertexBand[side];
  const Point2& to = panel.vertexBand[(side + 1) % sides];
  const Point2 along = (to - from).normalized(), inward(-along.y(), along.x());
  // The tab: the vertex band up to `depth` from this side (all of it where
  // it is shallower), so that it lies on the vertex band whatever the
  // band's shape. Clipping by one line keeps a convex polygon one polygon.
  for (int c = 0; c < sides; ++c) {
    if (core::turn(panel.vertexBand[c], panel.vertexBand[(c + 1) % sides], panel.vertexBand[(c + 2) % sides]) < 0) {
      throw std::invalid_argument("its vertex band is not convex, so a tab cannot be cut from it");
    }
  }
  std::vector<Point2> tab;
  const auto height = [&](const Point2& p) { return (p - from).dot(inward); };
  for (int c = 0; c < sides; ++c) {
    const Point2& p = panel.vertexBand[(side + c) % sides];
    const Point2& q = panel.vertexBand[(side + c + 1) % sides];
    if (height(p) <= depth) tab.push_back(p);
    if ((height(p) < depth) != (height(q) < depth) && height(p) != height(q)) {
      tab.push_back(p + (q - p) * ((depth - height(p)) / (height(q) - height(p))));
    }
  }
  if (tab.size() < 3 || !(signedArea(tab) > 0)) throw std::invalid_argument("its vertex band has no room for a tab");
  FlatBand& band = panel.bands[index];
  band.detached = true;
  band.tabOutline = tab;  // from, to, then around the vertex band back towards `from`
  Point2 centre = Point2::Zero();
  for (const Point2& p : tab) centre += p;
  band.tab = centre / static_cast<double>(tab.size());
  band.pieceOutline = band.outline;  // from `from` around the band to `to`
  band.pieceOutline.insert(band.pieceOutline.end(), tab.begin() + 2, tab.end());
  if (crossesItself(band.pieceOutline)) {
    // A band that reaches over its own vertex band crosses its tab.
    throw std::invalid_argument("the piece would cross its own tab");
  }
  rebuildOutline(panel);
}

void halveBand(FlatPanel& panel, int index) {
  FlatBand& band = panel.bands[index];
  if (band.detached || band.halved) throw std::invalid_argument("the band is already cut off");
  const int segments = static_cast<int>(band.points.size()) / 2 - 1;
  // Along the rail the outline leaves the vertex band by (t = out), then back
  // along the other: s runs from this copy's end (near) to the other's.
  const double near = band.fromA ? 0.0 : 1.0, far = 1.0 - near, middle = 0.5, out = band.fromA ? 0.0 : 1.0;
  const auto stretch = [&](double from, double to) {
    std::vector<double> s{from};
    for (int i = 1; i < segments; ++i) {
      const double at = band.fromA ? static_cast<double>(i) / segments : 1.0 - static_cast<double>(i) / segments;
      if ((at - from) * (to - at) > 0) s.push_back(at);
    }
    s.push_back(to);
    return s;
  };
  const auto around = [&](double from, double to) {
    std::vector<Point2> outline;
    const std::vector<double> s = stretch(from, to);
    for (double x : s) outline.push_back(band.at(x, out));
    for (auto x = s.rbegin(); x != s.rend(); ++x) outline.push_back(band.at(*x, 1 - out));
    return outline;
  };
  std::vector<Point2> nearHalf = around(near, middle), farHalf = around(middle, far);
  if (crossesItself(farHalf) || !(signedArea(farHalf) > 0)) throw std::invalid_argument("its far half crosses itself");
  band.halved = true;
  band.outline = std::move(nearHalf);
  band.pieceOutline = std::move(farHalf);
  rebuildOutline(panel);
}

FlatPanel unfoldPanel(const RotationSystem& rs, const BandDecomposition& decomposition,
                      const std::vector<EdgeBand>& bands, int face) {
  FlatPanel panel;
  panel.face = face;
  const VertexBand& vb = decomposition.vertexBands[face];
  panel.origin = vb.centroid;
  // The frame's x along the vertex band's longest side (a side can be
  // nearly nothing where corner cutting squeezes a corner).
  size_t longest = 0;
  for (size_t i = 0; i < vb.corners.size(); ++i) {
    const auto side = [&](size_t k) { return (vb.corners[(k + 1) % vb.corners.size()] - vb.corners[k]).norm(); };
    if (side(i) > side(longest)) longest = i;
  }
  panel.xAxis = (vb.corners[(longest + 1) % vb.corners.size()] - vb.corners[longest]).normalized();
  panel.yAxis = vb.normal.cross(panel.xAxis).normalized();
  for (const Point3& p : vb.corners) {
    panel.vertexBand.emplace_back((p - panel.origin).dot(panel.xAxis), (p - panel.origin).dot(panel.yAxis));
  }
  const int sides = static_cast<int>(vb.corners.size());
  Dart d = rs.faceDart(face);
  for (int side = 0; side < sides; ++side, d = rs.faceNext(d)) {
    const Point2& from = panel.vertexBand[side];
    const Point2& to = panel.vertexBand[(side + 1) % sides];
    const int e = RotationSystem::edgeOf(d);
    if (rs.isBoundaryEdge(e)) {
      panel.bandOfSide.push_back(-1);
      continue;
    }
    const EdgeBand& band = bands[e];
    const int k = band.segments();
    FlatBand flat;
    flat.edge = e;
    flat.fromA = d == 2 * e;
    flat.points.resize(2 * k + 2);
    // On face A the side runs u -> v (rail U from `from`); on face B, v -> u.
    if (flat.fromA) {
      flat.points[0] = from, flat.points[k + 1] = to;
    } else {
      flat.points[2 * k + 1] = from, flat.points[k] = to;
    }
    const Point2 along = to - from;
    develop(band, flat.fromA, flat.points, (from + to) / 2 + Point2(-along.y(), along.x()));
    // From `from` out along its rail, across the far end, back along the other rail.
    const auto railPoint = [&](bool railU, int i) { return flat.points[railU ? i : k + 1 + i]; };
    const bool outRailU = flat.fromA;
    std::vector<int> out(k + 1);
    for (int i = 0; i <= k; ++i) out[i] = flat.fromA ? i : k - i;
    flat.outline.push_back(from);
    for (int i = 1; i <= k; ++i) flat.outline.push_back(railPoint(outRailU, out[i]));
    for (int i = k; i >= 0; --i) flat.outline.push_back(railPoint(!outRailU, out[i]));
    // Closed by the side from `to` back to `from`: counter-clockwise, as the panel's outline runs.
    panel.bandOfSide.push_back(static_cast<int>(panel.bands.size()));
    panel.bands.push_back(std::move(flat));
  }
  rebuildOutline(panel);
  return panel;
}

std::vector<std::pair<int, int>> overlappingPieces(const FlatPanel& panel) {
  std::vector<std::pair<int, int>> result;
  const int n = static_cast<int>(panel.bands.size());
  // A piece that crosses itself: a vertex band projected from a twisted face,
  // or a band whose development curls over itself (V.4).
  if (crossesItself(panel.vertexBand)) result.emplace_back(-1, -1);
  for (int i = 0; i < n; ++i) {
    if (!panel.bands[i].detached && crossesItself(panel.bands[i].outline)) result.emplace_back(i, i);
  }
  const auto piece = [&](int i) -> const std::vector<Point2>& {
    return i < 0 ? panel.vertexBand : panel.bands[i].outline;
  };
  const auto middle = [&](int i) {
    const auto& o = piece(i);
    return i < 0 ? Point2((o[0] + o[1] + o[2]) / 3) : Point2((o[o.size() / 2] + o[o.size() / 2 - 1]) / 2);
  };
  const auto attached = [&](int i) { return i < 0 || !panel.bands[i].detached; };
  for (int i = -1; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      if (!attached(i) || !attached(j)) continue;
      if (core::outlinesCross(piece(i), piece(j)) || insidePolygon(piece(i), middle(j)) ||
          insidePolygon(piece(j), middle(i))) {
        result.emplace_back(i, j);
      }
    }
  }
  return result;
}

}  // namespace rotafab::geometry
