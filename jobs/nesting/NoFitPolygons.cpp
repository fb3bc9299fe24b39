#include "jobs/nesting/NoFitPolygons.h"

#include "jobs/nesting/ConvexPieces.h"

namespace rotafab::jobs::nesting {
namespace {

// The kept no-fit polygons are dropped when they hold this many points (16 bytes each).
constexpr size_t kMostSharedPoints = 8'000'000;

}  // namespace

// The union of many overlapping regions, two at a time up a balanced tree:
// Clipper unites a few large overlapping regions much faster than very many
// small ones at once (27 x 27 convex sums of two wavy strips: 2.6 ms against 59 ms).
Paths unionOf(std::vector<Paths> regions) {
  if (regions.empty()) return {};
  for (size_t step = 1; step < regions.size(); step *= 2) {
    for (size_t i = 0; i + step < regions.size(); i += 2 * step) {
      ClipperLib::Clipper clipper;
      clipper.AddPaths(regions[i], ClipperLib::ptSubject, true);
      clipper.AddPaths(regions[i + step], ClipperLib::ptClip, true);
      clipper.Execute(ClipperLib::ctUnion, regions[i], ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      regions[i + step].clear();
    }
  }
  if (regions.size() == 1) {  // one region: still resolve its own overlaps
    ClipperLib::Clipper clipper;
    clipper.AddPaths(regions[0], ClipperLib::ptSubject, true);
    clipper.Execute(ClipperLib::ctUnion, regions[0], ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  }
  return std::move(regions[0]);
}

// The no-fit polygon of a moving shape against a placed one (at the
// origin): the reference positions where the two grown shapes overlap.
// Built whole from convex pieces and kept for the two shapes' classes
// (instances repeat items many times), up to kMostSharedPoints.
const Paths& NoFitPolygons::sharedNoFitPolygon(int movingPart, int movingShape, int placedPart, int placedShape) {
  const auto key = std::make_pair(shapes_.classOf(movingPart, movingShape), shapes_.classOf(placedPart, placedShape));
  auto it = shared_.find(key);
  if (it == shared_.end()) {
    if (sharedPoints_ > kMostSharedPoints) shared_.clear(), sharedPoints_ = 0;  // bounded memory
    std::vector<Paths> sums;
    for (const Path& a : shapes_.at(placedPart, placedShape).pieces) {
      Paths sum;
      for (const Path& b : shapes_.at(movingPart, movingShape).negatedPieces) sum.push_back(convexMinkowskiSum(a, b));
      sums.push_back(std::move(sum));
    }
    it = shared_.emplace(key, unionOf(std::move(sums))).first;
    for (const Path& path : it->second) sharedPoints_ += path.size();
  }
  return it->second;
}

// The whole no-fit polygon of any two shapes, at the origin. Without
// convex pieces: the Minkowski sum of the boundaries, plus the two cases
// where one shape holds the other.
const Paths& NoFitPolygons::wholeNoFitPolygon(int movingPart, int movingShape, int placedPart, int placedShape) {
  if (!shapes_.at(placedPart, placedShape).pieces.empty() && !shapes_.at(movingPart, movingShape).pieces.empty()) {
    return sharedNoFitPolygon(movingPart, movingShape, placedPart, placedShape);
  }
  const auto key = std::make_tuple(movingPart, movingShape, placedPart, placedShape);
  auto it = wholes_.find(key);
  if (it == wholes_.end()) {
    const Shape& fixed = shapes_.at(placedPart, placedShape);
    const Shape& moving = shapes_.at(movingPart, movingShape);
    Paths whole;
    ClipperLib::MinkowskiSum(moving.negated, fixed.grown, whole, true);
    whole.push_back(translatedPath(fixed.grown, {-moving.grown[0].X, -moving.grown[0].Y}));
    whole.push_back(translatedPath(moving.negated, {fixed.grown[0].X, fixed.grown[0].Y}));
    it = wholes_.emplace(key, unionOf({std::move(whole)})).first;
  }
  return it->second;
}

// Turning two shapes together turns their no-fit polygon: one is kept for
// the four quarter turns of a pair (a quarter of the work and memory for
// the shapes with copies, which obstacles() meets again and again). `paths` is the no-fit
// polygon of the moving shape turned back by `turns` quarter turns against
// the placed part in its first quarter-turn rotation; turned by `turns`,
// it is the one asked for. Turned outlines are exact on the grid, but the
// grown shapes built from them may differ from turned grown shapes by up
// to kSimplifyTolerance (the simplification); both still hold the
// outline grown by half the spacing, so the final exact checks hold, and
// a pair may only look a little more or less apart than it is.
NoFitPolygons::TurnedRegion NoFitPolygons::noFitPolygonOf(int movingPart, int movingShape, int placedPart,
                                                          int placedShape) {
  const int movingQuarter = shapes_.quarterOf(movingPart, movingShape),
            placedQuarter = shapes_.quarterOf(placedPart, placedShape);
  if (movingQuarter >= 0 && placedQuarter >= 0) {
    const int first = shapes_.firstQuarter(placedPart);
    const int turns = (placedQuarter - first + 4) % 4;
    const int moving = shapes_.shapeAtQuarter(movingPart, (movingQuarter - turns + 4) % 4);
    if (moving >= 0) {
      return {&wholeNoFitPolygon(movingPart, moving, placedPart, shapes_.shapeAtQuarter(placedPart, first)), turns};
    }
  }
  return {&wholeNoFitPolygon(movingPart, movingShape, placedPart, placedShape), 0};
}
IntPoint NoFitPolygons::turned(IntPoint p, int turns) {
  for (int t = 0; t < turns % 4; ++t) p = {-p.Y, p.X};
  return p;
}
// The no-fit polygon for a placed part at `at`.
Paths NoFitPolygons::placedRegion(const TurnedRegion& region, IntPoint at) {
  Paths out;
  out.reserve(region.paths->size());
  for (const Path& path : *region.paths) {
    Path& placed = out.emplace_back();
    placed.reserve(path.size());
    for (const IntPoint& p : path) {
      const IntPoint q = turned(p, region.turns);
      placed.push_back({q.X + at.X, q.Y + at.Y});
    }
  }
  return out;
}

// The reference points where shape k of `part` would overlap one of
// `others`: the union of their no-fit polygons, built only where a box of
// reference points `matters`.
Paths NoFitPolygons::obstacles(int part, int k, const std::vector<PlacedShape>& others,
                               const std::function<bool(const Box&)>& matters) {
  const Shape& moving = shapes_.at(part, k);
  std::vector<Paths> noFitPolygons;
  for (const PlacedShape& q : others) {
    if (cancellation_) cancellation_->check();
    const Shape& fixed = shapes_.at(q.part, q.shape);
    // The no-fit polygon lies in this box.
    if (!matters({q.at.X + fixed.grownMinX - moving.grownMaxX, q.at.Y + fixed.grownMinY - moving.grownMaxY,
                  q.at.X + fixed.grownMaxX - moving.grownMinX, q.at.Y + fixed.grownMaxY - moving.grownMinY})) {
      continue;
    }
    if (!fixed.pieces.empty() && !moving.pieces.empty()) {
      // The union over pairs of convex pieces of their linear-time sums is
      // the whole no-fit polygon, either shape inside the other included.
      // Only the part of it in boxes that matter is built. Each
      // pair's sums are united first, which Clipper does faster than one
      // union of everything.
      if (shapes_.classSize(shapes_.classOf(part, k)) > 1 && shapes_.classSize(shapes_.classOf(q.part, q.shape)) > 1) {
        // Both shapes have copies: this no-fit polygon will be met again.
        noFitPolygons.push_back(placedRegion(noFitPolygonOf(part, k, q.part, q.shape), q.at));
        continue;
      }
      std::vector<Paths> sums;  // one per piece of the placed shape
      for (size_t a = 0; a < fixed.pieces.size(); ++a) {
        const Box& fa = fixed.pieceBoxes[a];
        Paths sum;
        for (size_t b = 0; b < moving.negatedPieces.size(); ++b) {
          const Box& mb = moving.negatedPieceBoxes[b];
          if (!matters(
                  {q.at.X + fa[0] + mb[0], q.at.Y + fa[1] + mb[1], q.at.X + fa[2] + mb[2], q.at.Y + fa[3] + mb[3]})) {
            continue;
          }
          sum.push_back(translatedPath(convexMinkowskiSum(fixed.pieces[a], moving.negatedPieces[b]), q.at));
        }
        if (!sum.empty()) sums.push_back(std::move(sum));
      }
      if (!sums.empty()) noFitPolygons.push_back(unionOf(std::move(sums)));
      continue;
    }
    noFitPolygons.push_back(placedRegion(noFitPolygonOf(part, k, q.part, q.shape), q.at));
  }
  return unionOf(std::move(noFitPolygons));
}

}  // namespace rotafab::jobs::nesting
