#pragma once
// The parts of a woven structure's panels that the structure (WeaveStructure.cpp)
// puts together (dissertation IV.4): a crossing's three panels and the
// holes that fasten them, where a label goes on a strip, and a panel cut
// apart where its unfolding folds over itself. Not an interface of its
// own: WeaveStructure.h is.

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "geometry/FastenerHoles.h"
#include "geometry/HersheyFont.h"
#include "geometry/Structure.h"
#include "geometry/WeaveRibbons.h"
#include "geometry/WovenPanels.h"

namespace rotafab::geometry::weaving {

// The three panels of a crossing: over it, and under it before and after
// it along the thread under (indices into the woven panels), each with the
// row of its strip through the crossing.
struct CrossingPanels {
  std::array<int, 3> panel{-1, -1, -1};
  std::array<int, 3> row{};
};

// The flat hole positions of one crossing on its three panels, and the
// clearance they keep, in diameters: from each panel's outline, and
// between the two holes on a panel less one diameter (kClearance from the
// outline and kClearance + 1 between centres keep the same 1.5 diameters
// of material, FastenerHoles.h).
struct CrossingHoles {
  std::array<std::array<Point2, 2>, 3> flat;  // per panel of CrossingPanels, per hole
  std::array<std::array<int, 2>, 3> rows{};   // the strip row each lies on
  double clearance = -std::numeric_limits<double>::infinity();
  double fromOutline = 0, apart = 0;  // the least distance to an outline, and between a panel's two holes, diameters
  bool single = false;                // one hole at the crossing's centre: no room for two

  // How many times larger the mesh must be (every length but the
  // diameter grows with it) for these holes to have room: kLeastClearance,
  // with 2% to spare, as for a band (FastenerHoles.h).
  [[nodiscard]] double scaleNeeded() const {
    constexpr double kSpare = 1.02;
    return std::max(fromOutline > 0 ? kSpare * kLeastClearance / fromOutline : std::numeric_limits<double>::infinity(),
                    apart > 0 ? kSpare * (kLeastClearance + 1) / apart : std::numeric_limits<double>::infinity());
  }
};

// The holes of one crossing, as spread as kClearance allows (WeaveCrossings.cpp).
CrossingHoles placeCrossingHoles(const EdgeRegion& region, const CrossingPanels& at,
                                 const std::vector<WovenPanel>& panels,
                                 const std::vector<std::vector<Point2>>& outlines, const RibbonShape& shape,
                                 double diameter);

// The centre of a strip's row, flat (clamped to the strip).
Point2 centreOfRow(const WovenPanel& panel, int row);
// The direction the thread runs at `row`, flat.
double angleAtRow(const WovenPanel& panel, int row);
// The rows from `from` stepping towards `to`, both included, those on the panel.
std::vector<int> rowsFrom(const WovenPanel& panel, int from, int to);
// The candidate centres for a label, row by row in the order given: on
// each row its middle, then nearer one side and the other (a label beside
// a hole rather than between two).
std::vector<Point2> labelCandidates(const WovenPanel& panel, const std::vector<int>& rows);

// A panel whose unfolded outline crosses itself (its ribbon curls round, as
// round a face at a leaf of a single thread's tree, or round a sharp vertex)
// is cut across its strip, at most twice, into parts that do not; each cut
// leaves the two parts overlapping over a few rows (a lap) with one hole
// through both. The parts keep the panel's flat frame (an unfolding of
// some of its rows is the same as theirs in the whole), so its holes and
// labels stay where they are, each on the part whose rows hold it (a hole
// in a lap on both). The part over the panel's edge stays the panel; the
// others become its pieces, "17a", "17b", each with its name etched on it
// (as a band's piece on its tab; `unfitted` names those it does not fit).
// Leaves the panel as it was when no cut gives parts that keep their holes'
// clearance and hold their labels.
void cutApart(const WovenPanel& w, Panel& panel, const std::vector<int>& holeRows, const std::vector<int>& labelRows,
              double diameter, const HersheyFont& font, std::vector<std::string>& unfitted);

}  // namespace rotafab::geometry::weaving
