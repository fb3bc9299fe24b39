#pragma once
// No-fit polygons (Bennell and Oliveira 2008, "The geometry of nesting
// problems: a tutorial"): the no-fit polygon of a moving shape against a
// placed one is the set of the moving shape's reference points at which the
// two grown shapes overlap, the Minkowski sum of the placed shape and the
// moving one turned half round. Built from convex pieces
// (ConvexPieces.h: the union of the linear-time sums of each pair of
// pieces), or, for a shape without pieces, from Clipper's MinkowskiSum of
// the boundaries plus the two cases where one shape holds the other. Those
// of shapes that have copies (instances repeat items many times) are kept,
// once for the four quarter turns of a pair, up to a bound on memory.
//
// One NoFitPolygons per search (it keeps what it builds; not for two
// threads at once); the PartShapes it reads are shared.

#include <functional>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "core/Cancellation.h"
#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs::nesting {

// The union of many overlapping regions, two at a time up a balanced tree:
// Clipper unites a few large overlapping regions much faster than very many
// small ones at once (27 x 27 convex sums of two wavy strips: 2.6 ms against 59 ms).
Paths unionOf(std::vector<Paths> regions);

class NoFitPolygons {
 public:
  // `cancellation`, when given, is checked for each placed shape obstacles() meets.
  explicit NoFitPolygons(const PartShapes& shapes, const core::Cancellation* cancellation = nullptr)
      : shapes_(shapes), cancellation_(cancellation) {}

  // The reference points where shape k of `part` would overlap one of
  // `others`: the union of their no-fit polygons, built only where a box of
  // reference points `matters`. Throws core::Cancelled.
  Paths obstacles(int part, int k, const std::vector<PlacedShape>& others,
                  const std::function<bool(const Box&)>& matters);

 private:
  const Paths& sharedNoFitPolygon(int movingPart, int movingShape, int placedPart, int placedShape);
  const Paths& wholeNoFitPolygon(int movingPart, int movingShape, int placedPart, int placedShape);
  struct TurnedRegion {
    const Paths* paths;
    int turns;
  };
  TurnedRegion noFitPolygonOf(int movingPart, int movingShape, int placedPart, int placedShape);
  static IntPoint turned(IntPoint p, int turns);
  static Paths placedRegion(const TurnedRegion& region, IntPoint at);

  const PartShapes& shapes_;
  const core::Cancellation* cancellation_;
  std::map<std::pair<int, int>, Paths> shared_;  // (moving class, placed class) -> no-fit polygon
  size_t sharedPoints_ = 0;
  std::map<std::tuple<int, int, int, int>, Paths> wholes_;  // no-fit polygons without convex pieces
};

}  // namespace rotafab::jobs::nesting
