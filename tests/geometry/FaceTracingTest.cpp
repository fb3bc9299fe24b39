// Face tracing on (extended) rotation systems, dissertation III.1.2.

#include "geometry/FaceTracing.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>

#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

RotationSystem rotationSystemOf(PolygonMesh mesh) {
  requireUsable(analyzeMesh(mesh));
  return RotationSystem::fromMesh(mesh);
}

// Walk lengths, sorted.
std::vector<size_t> lengths(const std::vector<TracedWalk>& walks) {
  std::vector<size_t> out;
  for (const auto& w : walks) out.push_back(w.darts.size());
  std::sort(out.begin(), out.end());
  return out;
}

// Recomputes, from each walk's darts and trace types alone, the corner it
// turns at between consecutive darts, checks that step is Next(reverse, t) of
// FaceTrace, and that every corner of the rotation system is turned exactly once.
void expectEveryCornerOnce(const RotationSystem& rs, const std::vector<TracedWalk>& walks) {
  std::vector<int> turns(rs.dartCount(), 0);
  for (const auto& walk : walks) {
    const size_t n = walk.darts.size();
    for (size_t i = 0; i < n; ++i) {
      const Dart arriving = RotationSystem::reverse(walk.darts[i]);
      const Dart next = walk.darts[(i + 1) % n];
      const int t = walk.traceTypes[(i + 1) % n];  // the type after crossing darts[i]'s edge
      ASSERT_EQ(next, t == 0 ? rs.rotate(arriving) : rs.rotateBack(arriving)) << "not a FaceTrace step";
      ++turns[t == 0 ? arriving : next];  // corner (x, rotate(x)) is numbered x
    }
  }
  for (Dart corner = 0; corner < rs.dartCount(); ++corner) EXPECT_EQ(turns[corner], 1) << "corner " << corner;
}

TEST(FaceTracing, WithoutTwistsTheWalksAreTheFacesAndTheBoundaries) {
  struct Case {
    const char* name;
    PolygonMesh mesh;
    int boundaryLoops;
  };
  PolygonMesh punctured = torus(6, 4);
  punctured.faces.erase(punctured.faces.begin() + 7);
  for (auto& c : std::vector<Case>{{"cube", cube(), 0},
                                   {"soccer ball", truncatedIcosahedron(), 0},
                                   {"genus 2", genusTwoSlab(), 0},
                                   {"disc", disc(6), 1},
                                   {"punctured torus", punctured, 1}}) {
    SCOPED_TRACE(c.name);
    const RotationSystem rs = rotationSystemOf(c.mesh);
    const auto walks = traceAllFaces(rs);
    expectEveryCornerOnce(rs, walks);
    std::map<int, const TracedWalk*> byFace;
    int boundaries = 0;
    for (const auto& w : walks) {
      if (w.boundary) {
        ++boundaries;
        continue;
      }
      const int face = rs.face(w.darts[0]);
      ASSERT_GE(face, 0);
      EXPECT_FALSE(byFace.contains(face)) << "face " << face << " traced twice";
      byFace[face] = &w;
      // The walk visits the face's corners in the face's own order.
      const auto& corners = c.mesh.faces[face];
      ASSERT_EQ(w.darts.size(), corners.size());
      const auto start = std::find(corners.begin(), corners.end(), rs.origin(w.darts[0])) - corners.begin();
      for (size_t i = 0; i < corners.size(); ++i) {
        EXPECT_EQ(rs.origin(w.darts[i]), corners[(start + i) % corners.size()]);
        EXPECT_EQ(rs.face(w.darts[i]), face);
      }
    }
    EXPECT_EQ(static_cast<int>(byFace.size()), c.mesh.faceCount());
    EXPECT_EQ(boundaries, c.boundaryLoops);
  }
}

TEST(FaceTracing, EveryEdgeTwistedGivesThePetrieWalks) {
  struct Case {
    const char* name;
    PolygonMesh mesh;
    size_t walks, length;
  };
  for (auto& c : std::vector<Case>{{"tetrahedron", tetrahedron(), 3, 4},
                                   {"cube", cube(), 4, 6},
                                   {"octahedron", octahedron(), 4, 6},
                                   {"dodecahedron", dodecahedron(), 6, 10},
                                   {"icosahedron", icosahedron(), 6, 10}}) {
    SCOPED_TRACE(c.name);
    RotationSystem rs = rotationSystemOf(c.mesh);
    for (int k : {1, -1, 3}) {  // only the parity of the twist matters to tracing
      rs.twistAll(k);
      const auto walks = traceAllFaces(rs);
      expectEveryCornerOnce(rs, walks);
      EXPECT_EQ(lengths(walks), std::vector<size_t>(c.walks, c.length));
    }
    rs.twistAll(2);  // a double twist is topologically no twist
    EXPECT_EQ(traceAllFaces(rs).size(), static_cast<size_t>(c.mesh.faceCount()));
  }
}

TEST(FaceTracing, OneTwistMergesTwoFacesAndASecondSplitsThemAgain) {
  // Fig. 7: twisting an edge between two faces merges them into one walk;
  // that walk uses the twisted edge twice in the same direction, so twisting
  // it once more (k = 2) splits it back.
  RotationSystem rs = rotationSystemOf(cube());
  rs.setTwist(0, 1);
  auto walks = traceAllFaces(rs);
  EXPECT_EQ(lengths(walks), (std::vector<size_t>{4, 4, 4, 4, 8}));
  const auto merged = std::find_if(walks.begin(), walks.end(), [](const TracedWalk& w) { return w.darts.size() == 8; });
  std::vector<Dart> onEdge;
  for (Dart d : merged->darts)
    if (RotationSystem::edgeOf(d) == 0) onEdge.push_back(d);
  ASSERT_EQ(onEdge.size(), 2u);
  EXPECT_EQ(onEdge[0], onEdge[1]) << "the merged walk runs the twisted edge twice the same way";
  rs.setTwist(0, 2);
  EXPECT_EQ(lengths(traceAllFaces(rs)), std::vector<size_t>(6, 4));
}

// The three rules of III.1.2 on random twist sequences: twisting e merges two
// walks when its two sides are on different walks, splits a walk that runs e
// twice the same way, and leaves the count when the walk runs e both ways.
TEST(FaceTracing, TwistingFollowsTheMergeSplitRules) {
  std::mt19937 random(7);
  for (PolygonMesh mesh : {cube(), dodecahedron(), torus(5, 4), genusTwoSlab(), disc(6)}) {
    RotationSystem rs = rotationSystemOf(mesh);
    auto walks = traceAllFaces(rs);
    for (int step = 0; step < 60; ++step) {
      const int e = static_cast<int>(random() % rs.edgeCount());
      std::vector<std::pair<int, Dart>> uses;  // (walk, dart) for the two traversals of e
      for (int w = 0; w < static_cast<int>(walks.size()); ++w)
        for (Dart d : walks[w].darts)
          if (RotationSystem::edgeOf(d) == e) uses.emplace_back(w, d);
      ASSERT_EQ(uses.size(), 2u);
      int expectedChange = 0;
      if (uses[0].first != uses[1].first)
        expectedChange = -1;
      else if (uses[0].second == uses[1].second)
        expectedChange = +1;
      const size_t before = walks.size();
      rs.setTwist(e, rs.twist(e) + 1);
      walks = traceAllFaces(rs);
      expectEveryCornerOnce(rs, walks);
      EXPECT_EQ(static_cast<int>(walks.size()) - static_cast<int>(before), expectedChange) << "step " << step;
    }
  }
}

TEST(FaceTracing, RotationAtEveryVertexHasItsValence) {
  const PolygonMesh mesh = truncatedIcosahedron();
  const RotationSystem rs = rotationSystemOf(mesh);
  for (int v = 0; v < rs.vertexCount(); ++v) EXPECT_EQ(rs.valence(v), 3);
  for (Dart d = 0; d < rs.dartCount(); ++d) {
    EXPECT_EQ(rs.origin(rs.rotate(d)), rs.origin(d));
    EXPECT_EQ(rs.rotateBack(rs.rotate(d)), d);
  }
  const RotationSystem open = rotationSystemOf(disc(5));
  EXPECT_EQ(open.valence(0), 5);
  EXPECT_EQ(open.valence(1), 3);  // two rim edges and the spoke
  EXPECT_TRUE(open.isBoundaryVertex(1));
  EXPECT_FALSE(open.isBoundaryVertex(0));
}

}  // namespace
}  // namespace rotafab::geometry
