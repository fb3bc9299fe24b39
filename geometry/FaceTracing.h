#pragma once
// Face tracing on an extended graph rotation system (dissertation III.1.2,
// "Face-Tracing Algorithm" and "Trace-All-Faces", after Gross and Tucker).
//
// With no twists the traced walks are the mesh's faces plus one walk per
// boundary loop; with every edge twisted they are the Petrie walks; in general
// they are the cycles of a cyclic plain-weaving (Theorem III.1.1).

#include <vector>

#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

struct TracedWalk {
  std::vector<Dart> darts;      // the oriented edges in the order traced
  std::vector<int> traceTypes;  // the trace type t (0 or 1) with which each dart was reached
  bool boundary = false;        // every dart lies on the open side of a boundary
};

// FaceTrace(<u0, w0>, t0): the walk that starts with dart `start` at trace
// type `traceType`. Each step across an edge adds its twist to t (mod 2) and
// continues with Next(reverse, t): the rotation successor for t = 0, the
// predecessor for t = 1. `cornerUsed`, if given, has one flag per dart and
// marks the corners the walk passes (corner (x, rotate(x)) is numbered x).
TracedWalk traceFace(const RotationSystem& rs, Dart start, int traceType, std::vector<char>* cornerUsed = nullptr);

// Trace-All-Faces: traces from every face corner not yet traced, so that each
// corner belongs to exactly one walk. Walks come in the order of their first
// corner; deterministic.
std::vector<TracedWalk> traceAllFaces(const RotationSystem& rs);

}  // namespace rotafab::geometry
