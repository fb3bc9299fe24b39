#pragma once
// The woven ribbons cut into panels and unfolded (dissertation IV.3-IV.4;
// docs/WEAVE.md, 1.9-1.10): each thread is cut at its down crossings into
// down-up-down panels, one per up crossing, so one per twisted edge. A
// panel runs from the middle row of the down crossing before its up
// crossing to that of the down crossing after it, and on past each by an
// overlap, so that both panels meeting at a down crossing cover it and are
// fastened through it with the panel over them (A9). Each panel's strip of
// thin triangles is unfolded from its up crossing's middle row outwards,
// one triangle at a time (eq. 4.18-4.26, StripUnfolding.h), with the up
// edge's N_e mapped to +z: the outside of the structure faces up.

#include <array>
#include <vector>

#include "geometry/StripUnfolding.h"
#include "geometry/WeaveRibbons.h"

namespace rotafab::geometry {

struct WovenPanel {
  int thread = -1;
  int upPass = -1;                   // the pass of its up crossing in its thread
  int upEdge = -1;                   // mesh edges: its up crossing's
  std::array<int, 2> downEdges{};    // and its down crossings', before and after it along the thread
  int firstRow = 0;                  // the ribbon row of its first row (wrapped round the thread)
  int upRow = 0;                     // its rows' index of the up crossing's middle row
  std::array<int, 2> downRows{};     // and of the down crossings'
  std::vector<Point3> railP, railQ;  // its rows, in space
  std::vector<Point2> flatP, flatQ;  // and unfolded
  double area = 0;                   // of its triangles, in space

  [[nodiscard]] int rows() const { return static_cast<int>(railP.size()); }
  // Rail P forwards, then rail Q backwards: counter-clockwise (the
  // unfolding keeps the outside up, so rail P lies on the right of the
  // thread's direction when the outline would turn clockwise, and the
  // outline starts with rail Q then).
  [[nodiscard]] std::vector<Point2> outline() const;
  // The outline of its rows first..last only.
  [[nodiscard]] std::vector<Point2> outlineOfRows(int first, int last) const;
  // The area in space of its strip's triangles between rows first and last.
  [[nodiscard]] double areaOfRows(int first, int last) const;
  // The strip's triangles as (row, rail) corners: quad i (rows i, i + 1) is
  // (P_i, Q_i, P_i+1), (Q_i, Q_i+1, P_i+1); index r is P_r, rows() + r is Q_r.
  [[nodiscard]] const Point3& corner(int index) const;
  [[nodiscard]] const Point2& flatCorner(int index) const;
};

// The panels of `ribbons`, thread by thread, each thread's in the order of
// their up crossings along it; `overlapRows` rows past each down crossing's
// middle row (at most half a Bézier segment). Throws std::invalid_argument
// for a thread with a single down crossing (its panel would go round it).
std::vector<WovenPanel> wovenPanels(const std::vector<Ribbon>& ribbons, const std::vector<EdgeRegion>& regions,
                                    int overlapRows);

// The triangle of a panel's strip holding the point where the line through
// `point` along `direction` meets the strip, searched among the quads of
// rows first..last; its corners (WovenPanel::corner indices) and weights.
// The nearest triangle, the point clamped into it, when the line misses.
struct StripPoint {
  std::array<int, 3> corners{};
  std::array<double, 3> weights{};
  double miss = 0;  // how far the line passes from the strip's triangles (0 when it meets one)
  [[nodiscard]] Point3 inSpace(const WovenPanel& panel) const;
  [[nodiscard]] Point2 onPanel(const WovenPanel& panel) const;
};
StripPoint stripPointOnLine(const WovenPanel& panel, int first, int last, const Point3& point, const Point3& direction);

}  // namespace rotafab::geometry
