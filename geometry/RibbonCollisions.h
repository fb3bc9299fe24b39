#pragma once
// Ribbons that pass through each other (the dissertation's open problem,
// ch. VII: "the ribbons can intersect each other" where the surface turns
// sharply or the ribbons are wide). Every quad (two triangles) of every
// ribbon's strip is put in a uniform grid by its box, and the quads that
// share a cell are tested against each other (an edge of a triangle of one
// through a triangle of the other), but for a strip's own quads within
// three rows, which touch or nearly. Then, per pair
// of ribbon segments that meet, the widest --width (by bisection, the two
// segments made again at each try) at which they no longer do, and a width
// at which no two ribbons meet, checked on the whole weave.

#include <vector>

#include "core/WorkContext.h"
#include "geometry/WeaveRibbons.h"

namespace rotafab::geometry {

struct RibbonCollision {
  // The mesh edges of the passes that begin the two ribbon segments that
  // meet (a segment runs from one pass's crossing to the next's).
  int edgeA = -1, edgeB = -1;
  double clearWidth = 0;  // the widest width tried at which the two segments alone do not meet (0: none found)
};

struct RibbonCollisions {
  std::vector<RibbonCollision> pairs;  // ordered by edges, one per two edges
  double clearWidth = 0;               // a width at which no ribbons meet anywhere (0: none found)
};

// The pairs of ribbon segments that meet, at most one pair per two edges,
// and, when there are some, a width at which none do: the narrowest of the
// pairs' own, checked on the whole weave made again at it (narrower by a
// quarter, up to four times, while other ribbons still meet). `ribbons` as
// weaveRibbons() made them from `rs`, `weave`, `regions` and `shape`.
RibbonCollisions ribbonCollisions(const RotationSystem& rs, const WeaveThreads& weave,
                                  const std::vector<EdgeRegion>& regions, const std::vector<Ribbon>& ribbons,
                                  const RibbonShape& shape, const core::WorkContext& context);

// The ribbons at `shape`'s width but narrower at the edges where they would
// meet: per pair of segments that meet (the first round looks only at the
// segments that turn about one corner, where nearly all do), the passes of
// both take the pair's own clearing width (or a tenth less than they had,
// when that is not less), and the weave is made again and looked at again,
// everywhere, a few rounds at most. A dense weave (fig. 15) where the surface allows it, and no two
// ribbons through each other where it does not.
// The narrowest a ribbon is made, or worth advising, at `shape`'s width: a
// quarter of it. Narrower ribbons leave their crossings no room for holes.
inline double narrowestUsefulWidth(const RibbonShape& shape) { return shape.width / 4; }

struct ClearedRibbons {
  std::vector<Ribbon> ribbons;
  std::vector<double> edgeWidths;  // w per edge, as the ribbons were made with
  int narrowed = 0;                // edges narrower than the shape's width
  RibbonCollisions left;           // what still meets after the last round (nothing, as a rule)
};
ClearedRibbons narrowUntilClear(const RotationSystem& rs, const WeaveThreads& weave,
                                const std::vector<EdgeRegion>& regions, const RibbonShape& shape,
                                const core::WorkContext& context);

}  // namespace rotafab::geometry
