#include "geometry/WeaveThreads.h"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "geometry/FaceTracing.h"

namespace rotafab::geometry {
namespace {

void requireClosed(const RotationSystem& rs) {
  for (int e = 0; e < rs.edgeCount(); ++e) {
    if (rs.isBoundaryEdge(e)) {
      throw std::invalid_argument(
          fmt::format("edge {} ({}-{}) is on a boundary: a weave needs a closed surface (fill the holes first)", e + 1,
                      rs.origin(2 * e) + 1, rs.target(2 * e) + 1));
    }
  }
}

}  // namespace

void twistForWeave(RotationSystem& rs, WeaveCycles cycles, int root) {
  requireClosed(rs);
  if (cycles == WeaveCycles::All) {
    rs.twistAll(1);
    return;
  }
  int faces = 0;
  for (Dart d = 0; d < rs.dartCount(); ++d) faces = std::max(faces, rs.face(d) + 1);
  if (root < 0 || root >= faces) throw std::invalid_argument(fmt::format("face {} is no face of the mesh", root + 1));
  rs.twistAll(0);
  // Depth first, without recursion (a mesh may have a million faces): a
  // stack of (face, the dart of it to look across next).
  std::vector<char> reached(static_cast<size_t>(faces), 0);
  std::vector<std::pair<int, Dart>> stack{{root, rs.faceDart(root)}};
  reached[static_cast<size_t>(root)] = 1;
  while (!stack.empty()) {
    auto& [face, d] = stack.back();
    if (d < 0) {
      stack.pop_back();
      continue;
    }
    const Dart across = d;
    const Dart after = rs.faceNext(d);
    d = after == rs.faceDart(face) ? -1 : after;
    const int neighbour = rs.face(RotationSystem::reverse(across));
    if (reached[static_cast<size_t>(neighbour)]) continue;
    reached[static_cast<size_t>(neighbour)] = 1;
    rs.setTwist(RotationSystem::edgeOf(across), 1);
    stack.emplace_back(neighbour, rs.faceDart(neighbour));
  }
  // A closed surface's dual is connected when the surface is: a face not
  // reached is on another component, which one thread cannot reach.
  const auto missed = std::find(reached.begin(), reached.end(), 0);
  if (missed != reached.end()) {
    throw std::invalid_argument(fmt::format(
        "face {} is on another piece of the surface than face {}: one thread cannot weave two pieces (all cycles, a "
        "thread per Petrie walk, weaves each)",
        missed - reached.begin() + 1, root + 1));
  }
}

WeaveThreads traceThreads(const RotationSystem& rs) {
  requireClosed(rs);
  WeaveThreads weave;
  weave.up.assign(static_cast<size_t>(rs.edgeCount()), {});
  weave.down.assign(static_cast<size_t>(rs.edgeCount()), {});
  for (const TracedWalk& walk : traceAllFaces(rs)) {
    Thread thread;
    for (size_t i = 0; i < walk.darts.size(); ++i) {
      const bool twisted = (rs.twist(RotationSystem::edgeOf(walk.darts[i])) & 1) != 0;
      thread.steps.push_back({walk.darts[i],
                              !twisted                  ? Crossing::None
                              : walk.traceTypes[i] == 0 ? Crossing::Up
                                                        : Crossing::Down,
                              walk.traceTypes[i]});
    }
    const auto firstDown = std::find_if(thread.steps.begin(), thread.steps.end(),
                                        [](const ThreadStep& s) { return s.crossing == Crossing::Down; });
    if (firstDown != thread.steps.end()) std::rotate(thread.steps.begin(), firstDown, thread.steps.end());
    const int index = static_cast<int>(weave.threads.size());
    for (size_t i = 0; i < thread.steps.size(); ++i) {
      const ThreadStep& step = thread.steps[i];
      if (step.crossing == Crossing::None) continue;
      StepRef& ref =
          (step.crossing == Crossing::Up ? weave.up
                                         : weave.down)[static_cast<size_t>(RotationSystem::edgeOf(step.dart))];
      // Each strand crosses a twisted edge once: once over, once under (III.1.2, Theorem III.1.1).
      if (ref.thread >= 0) {
        throw std::logic_error(fmt::format("internal: edge {} is crossed {} twice",
                                           RotationSystem::edgeOf(step.dart) + 1,
                                           step.crossing == Crossing::Up ? "over" : "under"));
      }
      ref = {index, static_cast<int>(i)};
    }
    weave.threads.push_back(std::move(thread));
  }
  return weave;
}

}  // namespace rotafab::geometry
