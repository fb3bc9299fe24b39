#pragma once
// Compaction by overlap minimisation (Umetani et al. 2009, "Solving the
// irregular strip packing problem via guided local search for overlap
// minimization"; with the collision and overlap measures of sparrow,
// Gardeyn and Wauters 2025, arXiv:2509.13329, and jagua-rs): after the sequence search, take a
// slice out of the strip (or, on beds laid side by side in one row, out of
// the last bed), let the parts overlap, and move them apart again by guided
// local search; a layout in which nothing overlaps is shorter, and is kept.
// On beds the last bed empties into the earlier ones, and one bed fewer is
// used.
//
// Preconditions: a layout without overlaps to start from (the accepted
// layout of CollisionPlacer or BottomLeftPacker, in their frame). One compaction per search; not
// for two threads at once.

#include <functional>
#include <random>
#include <utility>
#include <vector>

#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs::nesting {

class OverlapCompaction {
 public:
  explicit OverlapCompaction(const PartShapes& shapes) : shapes_(shapes) {}

  // Compacts `layout` (the beds side by side in one row) while `goOn` says
  // the budget allows another move; `moves` counts them; `shorter` hears of
  // each better layout kept (beds, last bed's length in inches). The layout
  // is exact: a try succeeds only when no two grown shapes reach into each
  // other by more than kCollisionSlack each. Returns the best layout, bed
  // by bed in each bed's own coordinates, in cutting order; a bed in the
  // middle that the moves emptied is left out.
  NestingResult compact(std::vector<PlacedShape> layout, std::mt19937& random, const std::function<bool()>& goOn,
                        int& moves, const std::function<void(int, double)>& shorter) const;

  // Puts `incoming` on the bed of `bed` (one bed's parts, in its own
  // coordinates) where it overlaps the others least, of places sampled as
  // a move samples them, then moves them all apart while `goOn` allows.
  // True, with `bed` holding it, when nothing overlaps; else `bed` is as
  // it was. Beds only.
  bool insert(std::vector<PlacedShape>& bed, const PlacedShape& incoming, std::mt19937& random,
              const std::function<bool()>& goOn, int& moves) const;

 private:
  // The compaction lays the beds side by side in one row, bed s from
  // s * pitch on, a gap wider than any overhang of a grown shape between
  // two: a layout of many beds is then one layout. These give the x ranges
  // (lanes) of the beds in a row ending at `length` (in the strip: one),
  // and the bed that a part ending at `right` is on.
  using Lanes = std::vector<std::pair<cInt, cInt>>;
  [[nodiscard]] Lanes lanesUpTo(cInt length) const;
  [[nodiscard]] cInt laneStartOf(cInt right) const;
  [[nodiscard]] int sheetOf(cInt right) const;
  [[nodiscard]] int bedsUsed(const std::vector<PlacedShape>& layout) const;
  [[nodiscard]] cInt lengthOf(const std::vector<PlacedShape>& layout) const;
  [[nodiscard]] IntPoint centreOf(const PlacedShape& p) const;
  bool moveInto(PlacedShape& p, IntPoint centre, const Lanes& lanes) const;
  bool separate(std::vector<PlacedShape>& layout, const Lanes& lanes, std::mt19937& random,
                const std::function<bool()>& goOn, int& moves) const;
  [[nodiscard]] bool colliding(const PlacedShape& a, const PlacedShape& b) const;
  [[nodiscard]] double weightedOverlap(const std::vector<PlacedShape>& layout, size_t i, int k, IntPoint at,
                                       const std::vector<double>& weights, double enough) const;
  void sampledMove(std::vector<PlacedShape>& layout, size_t i, const Lanes& lanes, const std::vector<double>& weights,
                   std::mt19937& random) const;
  [[nodiscard]] bool apart(const std::vector<PlacedShape>& layout) const;

  const PartShapes& shapes_;
};

}  // namespace rotafab::jobs::nesting
