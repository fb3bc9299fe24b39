#include "geometry/FaceTracing.h"

#include <algorithm>

namespace rotafab::geometry {
namespace {

int edgeType(const RotationSystem& rs, Dart d) {
  return rs.twist(RotationSystem::edgeOf(d)) & 1;  // a k-twist has type k; only its parity matters
}

}  // namespace

TracedWalk traceFace(const RotationSystem& rs, Dart start, int traceType, std::vector<char>* cornerUsed) {
  TracedWalk walk;
  Dart d = start;
  int t = traceType;
  // The dissertation prints the loop condition as "(<u,w> != <u0,w0>) and
  // (t != t0)", which would stop after one step; the walk ends when it is back
  // at the first dart *with* the first trace type (Gross and Tucker).
  do {
    walk.darts.push_back(d);
    walk.traceTypes.push_back(t);
    t = (t + edgeType(rs, d)) & 1;
    const Dart arriving = RotationSystem::reverse(d);
    const Dart next = t == 0 ? rs.rotate(arriving) : rs.rotateBack(arriving);
    if (cornerUsed) (*cornerUsed)[t == 0 ? arriving : next] = 1;
    d = next;
  } while (d != start || t != traceType);
  walk.boundary = std::all_of(walk.darts.begin(), walk.darts.end(), [&](Dart x) { return rs.isBoundary(x); }) &&
                  std::all_of(walk.traceTypes.begin(), walk.traceTypes.end(), [](int x) { return x == 0; });
  return walk;
}

std::vector<TracedWalk> traceAllFaces(const RotationSystem& rs) {
  std::vector<TracedWalk> walks;
  std::vector<char> cornerUsed(rs.dartCount(), 0);
  for (Dart corner = 0; corner < rs.dartCount(); ++corner) {
    // Corner (x, rotate(x)) is entered last when the walk closes at rotate(x).
    if (!cornerUsed[corner]) walks.push_back(traceFace(rs, rs.rotate(corner), 0, &cornerUsed));
  }
  return walks;
}

}  // namespace rotafab::geometry
