// The threads of a plain weave (dissertation III.1.2, IV.1): with every edge
// twisted they are the Petrie walks, counted here independently from the
// faces; over and under alternate along every thread; every twisted edge
// is crossed once over and once under; twisting a spanning tree of the
// dual leaves one thread.
#include "geometry/WeaveThreads.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <stdexcept>

#include "geometry/EdgeUses.h"
#include "geometry/HoleFilling.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

RotationSystem weaveRotationSystem(PolygonMesh mesh) {
  requireUsable(analyzeMesh(mesh));
  return RotationSystem::fromMesh(mesh);
}

struct Named {
  const char* name;
  PolygonMesh mesh;
};

// Ours, and meshes other people made: the bunny, Geomview's trefoil knot
// (a tube, its ends filled), CGAL's double torus (its three holes filled).
std::vector<Named> closedMeshes() {
  std::vector<Named> meshes{{"tetrahedron", tetrahedron()}, {"cube", cube()},
                            {"octahedron", octahedron()},   {"dodecahedron", dodecahedron()},
                            {"icosahedron", icosahedron()}, {"soccer ball", truncatedIcosahedron()},
                            {"torus 8 x 5", torus(8, 5)},   {"genus-2 slab", genusTwoSlab()}};
  meshes.push_back({"bunny", importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj").mesh});
  PolygonMesh knot = importMesh(test::publicMesh("/usr/share/geomview/geom/tref.off").string()).mesh;
  EXPECT_EQ(fillHoles(knot), 2) << "a tube: its two ends closed, as make's --holes fill does";
  meshes.push_back({"tref.off", std::move(knot)});
  PolygonMesh holed = importMesh(test::publicMesh(test::cgalMesh("double-torus-3-holes.off")).string()).mesh;
  EXPECT_EQ(fillHoles(holed), 3);
  meshes.push_back({"double-torus-3-holes.off", std::move(holed)});
  return meshes;
}

// The Petrie walks straight from the face lists, apart from the rotation
// system: half-edges (face, corner), the walk alternately taking the next
// side of the same face and, across the side just taken, the side before
// it in the other face, reversed. A walk and its reverse are two orbits of
// (half-edge, parity). Returns the orbits' lengths, sorted.
std::vector<size_t> petrieOrbitLengths(const PolygonMesh& mesh) {
  std::map<std::pair<int, int>, std::pair<int, int>> sideOf;  // (from, to) -> (face, corner)
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (size_t i = 0; i < face.size(); ++i) sideOf[{face[i], face[(i + 1) % face.size()]}] = {f, static_cast<int>(i)};
  }
  const auto from = [&](std::pair<int, int> h) { return mesh.faces[h.first][h.second]; };
  const auto to = [&](std::pair<int, int> h) {
    const auto& face = mesh.faces[h.first];
    return face[(h.second + 1) % face.size()];
  };
  const auto next = [&](std::pair<int, int> h) {
    return std::pair{h.first, static_cast<int>((h.second + 1) % mesh.faces[h.first].size())};
  };
  const auto prev = [&](std::pair<int, int> h) {
    const int n = static_cast<int>(mesh.faces[h.first].size());
    return std::pair{h.first, (h.second + n - 1) % n};
  };
  const auto twin = [&](std::pair<int, int> h) { return sideOf.at({to(h), from(h)}); };
  std::map<std::pair<std::pair<int, int>, int>, bool> seen;
  std::vector<size_t> orbits;
  for (const auto& [key, h] : sideOf) {
    for (int parity : {0, 1}) {
      if (seen[{h, parity}]) continue;
      size_t length = 0;
      std::pair<int, int> at = h;
      int p = parity;
      while (!seen[{at, p}]) {
        seen[{at, p}] = true;
        ++length;
        at = p == 0 ? next(at) : twin(prev(twin(at)));
        p ^= 1;
      }
      orbits.push_back(length);
    }
  }
  std::sort(orbits.begin(), orbits.end());
  return orbits;
}

void expectAWeave(const RotationSystem& rs, const WeaveThreads& weave) {
  size_t steps = 0;
  for (size_t t = 0; t < weave.threads.size(); ++t) {
    const auto& thread = weave.threads[t].steps;
    steps += thread.size();
    std::vector<Crossing> crossings;
    for (const ThreadStep& step : thread) {
      const bool twisted = (rs.twist(RotationSystem::edgeOf(step.dart)) & 1) != 0;
      EXPECT_EQ(step.crossing == Crossing::None, !twisted);
      if (step.crossing != Crossing::None) crossings.push_back(step.crossing);
    }
    // Over and under alternate along the thread, round the end too.
    ASSERT_EQ(crossings.size() % 2, 0u) << "thread " << t;
    for (size_t i = 0; i < crossings.size(); ++i) {
      EXPECT_NE(crossings[i], crossings[(i + 1) % crossings.size()]) << "thread " << t << " crossing " << i;
    }
    if (!crossings.empty()) {
      EXPECT_EQ(thread.front().crossing, Crossing::Down) << "thread " << t;
    }
    // Consecutive steps meet at a vertex: a thread is a closed walk.
    for (size_t i = 0; i < thread.size(); ++i) {
      EXPECT_EQ(rs.target(thread[i].dart), rs.origin(thread[(i + 1) % thread.size()].dart));
    }
  }
  EXPECT_EQ(steps, static_cast<size_t>(rs.dartCount())) << "every corner once";
  for (int e = 0; e < rs.edgeCount(); ++e) {
    const bool twisted = (rs.twist(e) & 1) != 0;
    for (const StepRef& ref : {weave.up[e], weave.down[e]}) {
      if (!twisted) {
        EXPECT_EQ(ref.thread, -1) << "edge " << e;
        continue;
      }
      ASSERT_GE(ref.thread, 0) << "edge " << e;
      EXPECT_EQ(RotationSystem::edgeOf(weave.threads[ref.thread].steps[ref.step].dart), e);
    }
    if (twisted) {
      EXPECT_EQ(weave.threads[weave.up[e].thread].steps[weave.up[e].step].crossing, Crossing::Up);
      EXPECT_EQ(weave.threads[weave.down[e].thread].steps[weave.down[e].step].crossing, Crossing::Down);
    }
  }
}

TEST(WeaveThreads, EveryEdgeTwistedGivesAThreadPerPetrieWalk) {
  for (auto& [name, mesh] : closedMeshes()) {
    SCOPED_TRACE(name);
    RotationSystem rs = weaveRotationSystem(mesh);
    twistForWeave(rs, WeaveCycles::All);
    const WeaveThreads weave = traceThreads(rs);
    expectAWeave(rs, weave);
    std::vector<size_t> doubled;
    for (const Thread& thread : weave.threads) doubled.insert(doubled.end(), 2, thread.steps.size());
    std::sort(doubled.begin(), doubled.end());
    EXPECT_EQ(doubled, petrieOrbitLengths(mesh)) << "each thread a Petrie walk, each walk a thread";
  }
  // The dissertation's counts (IV.1): a weave of the cube has 4 threads, the
  // tetrahedron 3, the dodecahedron 6.
  for (auto [mesh, threads] :
       std::vector<std::pair<PolygonMesh, size_t>>{{cube(), 4}, {tetrahedron(), 3}, {dodecahedron(), 6}}) {
    RotationSystem rs = weaveRotationSystem(mesh);
    twistForWeave(rs, WeaveCycles::All);
    EXPECT_EQ(traceThreads(rs).threads.size(), threads);
  }
}

TEST(WeaveThreads, TwistingASpanningTreeOfTheDualLeavesOneThread) {
  for (auto& [name, mesh] : closedMeshes()) {
    SCOPED_TRACE(name);
    RotationSystem rs = weaveRotationSystem(mesh);
    for (int root : {0, mesh.faceCount() - 1}) {
      twistForWeave(rs, WeaveCycles::Single, root);
      // The twisted edges: F - 1 of them, joining every face, in no cycle.
      DisjointSets faces(static_cast<size_t>(mesh.faceCount()));
      int twisted = 0;
      for (int e = 0; e < rs.edgeCount(); ++e) {
        if (rs.twist(e) == 0) continue;
        EXPECT_EQ(rs.twist(e), 1);
        ++twisted;
        const int a = rs.face(2 * e), b = rs.face(2 * e + 1);
        EXPECT_NE(faces.find(a), faces.find(b)) << "edge " << e << " closes a cycle";
        faces.unite(a, b);
      }
      EXPECT_EQ(twisted, mesh.faceCount() - 1);
      for (int f = 0; f < mesh.faceCount(); ++f) EXPECT_EQ(faces.find(f), faces.find(0));
      const WeaveThreads weave = traceThreads(rs);
      EXPECT_EQ(weave.threads.size(), 1u);
      expectAWeave(rs, weave);
    }
  }
}

TEST(WeaveThreads, ASurfaceWithABoundaryIsRefusedNamingAnEdge) {
  RotationSystem rs = weaveRotationSystem(disc(6));
  for (WeaveCycles cycles : {WeaveCycles::All, WeaveCycles::Single}) {
    try {
      twistForWeave(rs, cycles);
      ADD_FAILURE() << "a disc was woven";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find("is on a boundary: a weave needs a closed surface"), std::string::npos)
          << error.what();
      EXPECT_EQ(std::string(error.what()).rfind("edge ", 0), 0u) << error.what();
    }
  }
  RotationSystem cubeRs = weaveRotationSystem(cube());
  EXPECT_THROW(twistForWeave(cubeRs, WeaveCycles::Single, 6), std::invalid_argument);
}

}  // namespace
}  // namespace rotafab::geometry
