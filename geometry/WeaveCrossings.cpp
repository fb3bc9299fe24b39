#include "geometry/WeaveParts.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/Polygon2.h"
#include "geometry/PanelLabels.h"

namespace rotafab::geometry::weaving {

namespace {

CrossingHoles holesAt(const EdgeRegion& region, const CrossingPanels& at, const std::vector<WovenPanel>& panels,
                      const std::vector<std::vector<Point2>>& outlines, double delta, int reach, double diameter) {
  CrossingHoles holes;
  double fromOutline = std::numeric_limits<double>::infinity(), apart = fromOutline;
  bool missed = false;
  for (size_t k = 0; k < 3; ++k) {
    const WovenPanel& panel = panels[static_cast<size_t>(at.panel[k])];
    for (size_t h = 0; h < 2; ++h) {
      // On the over strand's centre line, either side of the crossing's
      // centre (docs/WEAVE.md, 1.11): along the over panel, across the
      // panels under it.
      const Point3 point = region.at(0.5 + (h == 0 ? -delta : delta), 0.5);
      const StripPoint hit = stripPointOnLine(panel, at.row[k] - reach, at.row[k] + reach, point, region.normal);
      holes.flat[k][h] = hit.onPanel(panel);
      holes.rows[k][h] =
          std::min({hit.corners[0] % panel.rows(), hit.corners[1] % panel.rows(), hit.corners[2] % panel.rows()});
      // A line that misses the strip: no hole through all three panels there.
      missed = missed || hit.miss > 1e-6 * diameter;
    }
    // The two holes as far apart on each panel under as on the panel over
    // (k = 0), about the same middle: a strip under that is tilted from
    // the one over, or bends between the two lines, puts them nearer or
    // farther by a few percent (0.0125 in of 0.31 on CGAL's blobby_3cc),
    // and a fastener through three panels needs its holes to meet when the
    // panels are bent into place. (Each keeps the row it was found on: it
    // moves by half that difference at most, well within a row.)
    if (k > 0) {
      const Point2 middle = (holes.flat[k][0] + holes.flat[k][1]) / 2;
      const Point2 along = holes.flat[k][1] - holes.flat[k][0];
      const double spacing = (holes.flat[0][1] - holes.flat[0][0]).norm();
      if (along.norm() > 0) {
        holes.flat[k][0] = middle - along.normalized() * spacing / 2;
        holes.flat[k][1] = middle + along.normalized() * spacing / 2;
      }
    }
    for (size_t h = 0; h < 2; ++h) {
      fromOutline =
          std::min(fromOutline,
                   core::distanceToOutline(outlines[static_cast<size_t>(at.panel[k])], holes.flat[k][h]) / diameter);
    }
    apart = std::min(apart, (holes.flat[k][0] - holes.flat[k][1]).norm() / diameter);
  }
  holes.fromOutline = missed ? 0 : fromOutline;
  holes.apart = apart;
  holes.clearance = missed ? -std::numeric_limits<double>::infinity() : std::min(fromOutline, apart - 1);
  return holes;
}

}  // namespace

// The largest spread of a crossing's holes, from a quarter of the quad's
// smaller side (in the region's parameters) down to where their centres are
// kClearance + 1 diameters apart, that keeps kClearance diameters to every
// outline; else the spread that keeps the most.
CrossingHoles placeCrossingHoles(const EdgeRegion& region, const CrossingPanels& at,
                                 const std::vector<WovenPanel>& panels,
                                 const std::vector<std::vector<Point2>>& outlines, const RibbonShape& shape,
                                 double diameter) {
  const double largest = std::min(shape.curve, shape.width) / 4;
  const double length = (region.at(1, 0.5) - region.at(0, 0.5)).norm();
  const double smallest = std::min(largest, (kClearance + 1) * diameter / (2 * length));
  const int reach = std::max(1, shape.samples / 2);
  constexpr int kTries = 8;
  CrossingHoles best;
  for (int i = 0; i <= kTries; ++i) {
    const double delta = largest + (smallest - largest) * i / kTries;
    CrossingHoles holes = holesAt(region, at, panels, outlines, delta, reach, diameter);
    if (holes.clearance >= kClearance) return holes;
    if (holes.clearance > best.clearance) best = holes;
  }
  if (best.clearance >= kLeastClearance) return best;
  // No room for two: one at the crossing's centre, as a band too small for
  // two holes gets one (FastenerHoles.h), if that has room.
  CrossingHoles one = holesAt(region, at, panels, outlines, 0, reach, diameter);
  one.single = true;
  one.apart = std::numeric_limits<double>::infinity();
  one.clearance = one.fromOutline > 0 ? one.fromOutline : -std::numeric_limits<double>::infinity();
  return one.clearance > best.clearance || one.clearance >= kLeastClearance ? one : best;
}

Point2 centreOfRow(const WovenPanel& panel, int row) {
  row = std::clamp(row, 0, panel.rows() - 1);
  return (panel.flatP[static_cast<size_t>(row)] + panel.flatQ[static_cast<size_t>(row)]) / 2;
}

double angleAtRow(const WovenPanel& panel, int row) {
  const Point2 along = centreOfRow(panel, row + 1) - centreOfRow(panel, row - 1);
  return std::atan2(along.y(), along.x());
}

std::vector<int> rowsFrom(const WovenPanel& panel, int from, int to) {
  std::vector<int> rows;
  const int step = to >= from ? 1 : -1;
  for (int row = from;; row += step) {
    if (row >= 0 && row < panel.rows()) rows.push_back(row);
    if (row == to) break;
  }
  return rows;
}

std::vector<Point2> labelCandidates(const WovenPanel& panel, const std::vector<int>& rows) {
  std::vector<Point2> candidates;
  for (int row : rows) {
    const Point2 &p = panel.flatP[static_cast<size_t>(row)], &q = panel.flatQ[static_cast<size_t>(row)];
    for (double t : {0.5, 0.25, 0.75}) candidates.push_back(p + t * (q - p));
  }
  return candidates;
}

}  // namespace rotafab::geometry::weaving
