#pragma once
// The improvement of a layout on beds that works on the whole job: the
// least-filled bed is emptied into the others, part by part, the largest
// first. Each part goes where it overlaps least on the bed with the most
// room, and that bed's parts are moved apart again by the compaction's
// guided local search (OverlapCompaction::insert, after Umetani et al.
// 2009 and sparrow); failing that, on the next bed with room. When every
// part of the bed has found another, the bed is closed: one sheet fewer.
// A bed that cannot be emptied is left as it was, and the next least
// filled is tried.
//
// Each separation involves one bed's parts only, so a move costs the same
// however many beds the job has (the compaction of the whole row of beds
// weighs every pair of parts: 13.5 million pairs for the bunny's panels).

#include <functional>
#include <random>
#include <vector>

#include "jobs/nesting/OverlapCompaction.h"
#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs::nesting {

class SheetEmptying {
 public:
  explicit SheetEmptying(const PartShapes& shapes) : shapes_(shapes), compaction_(shapes) {}

  // `layout`: the beds side by side in one row (CollisionPlacer::layout()),
  // without overlaps. Works while `goOn` allows and more beds are used than
  // `fewest`; `moves` counts the moves; `fewer` hears of each bed closed
  // (beds, and the last bed's length in inches). Returns the layout, bed by
  // bed in each bed's own coordinates, in cutting order; its `stopped` is
  // "no better layout" when it ended because no bed could be emptied (each
  // kept a part through a whole pass), else empty.
  NestingResult empty(const std::vector<PlacedShape>& layout, int fewest, std::mt19937& random,
                      const std::function<bool()>& goOn, int& moves,
                      const std::function<void(int, double)>& fewer) const;

 private:
  [[nodiscard]] double partArea(const std::vector<PlacedShape>& bed) const;

  const PartShapes& shapes_;
  OverlapCompaction compaction_;
};

}  // namespace rotafab::jobs::nesting
