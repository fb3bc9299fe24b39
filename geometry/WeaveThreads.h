#pragma once
// The threads of a plain-woven structure (dissertation III.1.2 and IV.1):
// the edges to twist, and the walks that face tracing then gives, each a
// thread that goes over and under alternately at the twisted edges it
// crosses (Theorem III.1.1).
//
// Twisting every edge gives the Petrie walks, one thread each (IV.1: "In
// practice, we twist all the edges"). Twisting only the edges of a
// spanning tree of the dual gives a single thread (Xing, Akleman, Chen and
// Gross, "Single-cycle plain-woven objects", SMI 2010): with no twist the
// walks are the faces, and twisting an edge whose two sides lie on two
// different walks merges them (III.1.2), so the F - 1 tree edges, each
// joining two parts of the tree grown so far, leave one walk.

#include <vector>

#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

enum class WeaveCycles {
  All,     // every edge twisted: a thread per Petrie walk
  Single,  // the edges of a spanning tree of the dual: one thread
};

// Sets the twists of `rs` for `cycles`: +1 on every edge; or +1 on the
// edges of a depth-first spanning tree of the dual from face `root`
// (each face's neighbours in the order of its sides) and 0 elsewhere.
// Throws std::invalid_argument for a surface with a boundary (a boundary
// edge has one side: no crossing) or a root that is no face.
void twistForWeave(RotationSystem& rs, WeaveCycles cycles, int root = 0);

// At a twisted edge a thread goes over (reached with trace type 0, IV.1's
// over half-edge E_{i,0}) or under (trace type 1); it crosses no thread at
// an untwisted edge.
enum class Crossing { Up, Down, None };

struct ThreadStep {
  Dart dart;  // the edge crossed, in the direction the thread goes
  Crossing crossing;
  // The trace type with which the walk reached the dart (0 for Up, 1 for
  // Down): at an untwisted edge it says on which side the thread runs, in
  // the face on the dart's left (0) or on its right (1).
  int traceType = 0;
};

struct Thread {
  // Cyclic; from the thread's first down crossing, or from its first step when it has none.
  std::vector<ThreadStep> steps;
};

// Where a thread crosses: thread index, step index.
struct StepRef {
  int thread = -1;
  int step = -1;
};

struct WeaveThreads {
  std::vector<Thread> threads;
  // Per edge, its up crossing and its down crossing (thread -1 for an untwisted edge).
  std::vector<StepRef> up, down;
};

// The threads that face tracing gives on `rs` with its twists, in the
// order of their first corner (Trace-All-Faces). Every twisted edge is
// crossed once over and once under. Requires a closed surface.
WeaveThreads traceThreads(const RotationSystem& rs);

}  // namespace rotafab::geometry
