#pragma once
// The ribbons of a plain-woven structure (dissertation IV.1-IV.2): per pass
// of a thread across an edge, the fractional quadrilateral cut from the
// edge's projected region (eq. 4.2-4.11) and lifted by +h where the thread
// goes over, -h where it goes under; per thread, the two rails of C1 cubic
// Bézier curves through consecutive quadrilaterals (eq. 4.17), sampled into
// one closed strip of thin triangles (docs/WEAVE.md, 1.4-1.8).
//
// Readings (docs/WEAVE.md): the second pass of the bilinear interpolation
// uses the width w, not c as printed in eq. 4.6-4.9 (A1); the under quad is
// the over quad transposed, running along the other diagonal of the region
// (A2); the over copy is the +h one, N_e pointing out (A3); a connector
// joins the tail corner nearer the vertex the thread passes to the next
// quad's head corner nearer that vertex (A7). An untwisted edge (a
// single-cycle weave) is passed beside it, in one face's half of the region,
// at height 0 (section 4).

#include <array>
#include <vector>

#include "geometry/EdgeProjection.h"
#include "geometry/WeaveThreads.h"

namespace rotafab::geometry {

struct RibbonShape {
  double width = 0.8;    // w in (0, 1]: the ribbon's share of its region across it
  double curve = 0.6;    // c in (0, 1]: the quad's share of its region along it (1: straight ribbons)
  double offset = 0.05;  // h > 0, inches: how far over and under ribbons stand off the surface
  int samples = 8;       // segments per Bézier curve
};

// A face corner: a face and one of its vertices.
struct FaceCorner {
  int face = -1, vertex = -1;
  bool operator==(const FaceCorner&) const = default;
};

// A thread's pass across the region of one edge. The quad's rows run across
// the thread at its head, middle and tail; side 0 and side 1 are its two
// rails, numbered along the thread (the ribbon's rail P, rail Q).
struct RibbonPass {
  int edge = -1;
  Crossing crossing = Crossing::None;
  FaceCorner from, to;  // where the thread enters and leaves the region
  std::array<Point3, 2> head, middle, tail;
  Point3 lift = Point3::Zero();  // +h N_e over, -h N_e under, 0 beside an untwisted edge: in the points above
  // The crossing's plane (IV.1.2: through P_m, normal N_e; a zero normal
  // beside an untwisted edge), and the two rails of the other thread's
  // strand across it as half-planes, each a point and a unit normal
  // pointing away from that strand: the thread reaches the other strand at
  // the entry rail and leaves it past the exit rail.
  Point3 planePoint = Point3::Zero(), planeNormal = Point3::Zero();
  Point3 entryPoint = Point3::Zero(), entryNormal = Point3::Zero();
  Point3 exitPoint = Point3::Zero(), exitNormal = Point3::Zero();
};

struct Ribbon {
  std::vector<RibbonPass> passes;  // the thread's steps, in its order
  // The sampled rails, cyclic: row i joins railP[i] to railQ[i]; row
  // k * samples is pass k's middle row (A1 B1), and rows go on along the
  // thread. The strip's quad between rows i and i + 1 (mod size) is cut into
  // the triangles (P_i, Q_i, P_i+1), (Q_i, Q_i+1, P_i+1).
  std::vector<Point3> railP, railQ;
  int samples = 0;
  std::vector<char> swapped;  // per pass: rail P is its side 1 (its sides as ribbonPass() numbers them)
};

// The pass of `step` across the region of its edge, with sides as the
// thread meets them (side 0 nearer the vertex at the head). `mesh` and `rs`
// as the region was made from.
RibbonPass ribbonPass(const RotationSystem& rs, const EdgeRegion& region, const ThreadStep& step,
                      const RibbonShape& shape);

// One ribbon per thread. Throws std::invalid_argument for a shape out of
// range (w, c in (0, 1], h > 0, at least one sample). `edgeWidths`, when
// given, is w per edge in place of the shape's (narrowUntilClear()); both
// strands of a crossing take its edge's.
std::vector<Ribbon> weaveRibbons(const RotationSystem& rs, const WeaveThreads& weave,
                                 const std::vector<EdgeRegion>& regions, const RibbonShape& shape,
                                 const std::vector<double>& edgeWidths = {});

// Segment k of `thread`'s ribbon (from pass k's middle row to pass k + 1's,
// both included: samples + 1 rows) made again with `shape`, its rails as
// `ribbon` has them: for trying another width or curve on a few segments.
void segmentRows(const RotationSystem& rs, const std::vector<EdgeRegion>& regions, const Thread& thread,
                 const Ribbon& ribbon, int k, const RibbonShape& shape, std::vector<Point3>& railP,
                 std::vector<Point3>& railQ);

// Where along the segment from pass `here`'s middle to pass `next`'s
// (parameter t of eq. 4.17) the ribbon has left the strand it crosses at
// `here` and where it reaches the one it crosses at `next`: both rails of
// the ribbon, as projected, outside that strand's rails. 0 and 1 beside an
// untwisted edge. When the two leave less than kLeastTurn between them (a
// ribbon wide for its curve), both move apart about their middle.
struct SegmentTurn {
  double leave = 0, arrive = 1;
};
inline constexpr double kLeastTurn = 0.1;
SegmentTurn segmentTurn(const RibbonPass& here, const RibbonPass& next);

// Point t of the segment from pass `here`'s middle to pass `next`'s on rail
// `side`: eq. 4.17's cubic through the passes' quads as projected, then,
// while the ribbon lies over or under the other strand of its crossing
// (t up to turn.leave, from turn.arrive), moved along N_e into that
// crossing's plane and lifted by its ±h; between, the two smoothly blended.
// The strands of a crossing are straight across (rows), so a ribbon that
// followed the cubic's sag over its partner would pass through the
// partner's rows: flat there, the two stay 2h apart wherever one lies over
// the other. Its derivative is the cubic's at both ends (the quad's middle
// and tail lie in the crossing's plane): C1 at every middle.
Point3 segmentPoint(const RibbonPass& here, const RibbonPass& next, const SegmentTurn& turn, int side, double t);

// Point t in [0, 1] of eq. 4.17's cubic, and its derivative.
Point3 bezierPoint(const std::array<Point3, 4>& control, double t);
Point3 bezierDerivative(const std::array<Point3, 4>& control, double t);

// The control points of the segment from pass k's middle to pass k + 1's
// (mod the passes) on rail `side`: middle, tail, next head, next middle.
std::array<Point3, 4> segmentControls(const Ribbon& ribbon, int pass, int side);

}  // namespace rotafab::geometry
