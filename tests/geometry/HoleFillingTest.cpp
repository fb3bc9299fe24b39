// Closing the holes of open meshes other people made: one face per loop
// (`--holes fill`), or a patch of triangles about as long as the loop's
// edges (`--holes patch`, after Liepa 2003). Either way the mesh comes out
// closed, manifold and oriented as it was (no face reversed); a patch's
// triangles are no longer than the refinement allows, none of them
// degenerate, and it spans the hole without folding onto its neighbours.
#include "geometry/HoleFilling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "geometry/MeshAnalysis.h"
#include "geometry/io/MeshImport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

PolygonMesh publicMesh(const char* name) { return importMesh(test::publicMesh(test::cgalMesh(name)).string()).mesh; }

// The longest boundary edge (a side of a face whose reverse is no face's side).
double longestBoundaryEdge(const PolygonMesh& mesh) {
  std::set<std::pair<int, int>> sides;
  for (const auto& face : mesh.faces) {
    for (size_t i = 0; i < face.size(); ++i) sides.insert({face[i], face[(i + 1) % face.size()]});
  }
  double longest = 0;
  for (const auto& [a, b] : sides) {
    if (!sides.contains({b, a})) longest = std::max(longest, (mesh.positions[b] - mesh.positions[a]).norm());
  }
  return longest;
}

TEST(HoleFilling, OneFaceCapsEachLoopAndThePatchClosesItWithTrianglesLikeItsEdges) {
  // CGAL's half cylinder (one loop of 136 edges, two half circles and two
  // straight sides: a bent hole), its head (three loops), its mask.
  for (const char* name : {"cylinder.off", "head.off", "mask_cone.off"}) {
    SCOPED_TRACE(name);
    PolygonMesh open = publicMesh(name);
    const MeshAnalysis before = analyzeMesh(open);
    ASSERT_GT(before.topology.boundaryLoops, 0);
    const double edge = longestBoundaryEdge(open);
    const int faces = open.faceCount(), vertices = open.vertexCount();

    PolygonMesh capped = open;
    EXPECT_EQ(fillHoles(capped), before.topology.boundaryLoops);
    EXPECT_EQ(capped.faceCount(), faces + before.topology.boundaryLoops);

    PolygonMesh patched = open;
    EXPECT_EQ(patchHoles(patched), before.topology.boundaryLoops);
    for (PolygonMesh* mesh : {&capped, &patched}) {
      const MeshAnalysis after = analyzeMesh(*mesh);
      EXPECT_TRUE(after.usable());
      EXPECT_EQ(after.topology.boundaryLoops, 0);
      EXPECT_TRUE(after.topology.manifold);
      // (analyzeMesh may turn a closed component's faces all outwards.)
      EXPECT_TRUE(after.flippedFaces == 0 || after.flippedFaces == mesh->faceCount())
          << "oriented like the faces around the hole: " << after.flippedFaces << " faces reversed";
      EXPECT_EQ(after.topology.components, before.topology.components);
    }
    ASSERT_EQ(patched.sourceFace.size(), patched.faces.size());
    ASSERT_EQ(patched.sourceVertex.size(), patched.positions.size());
    double longest = 0, smallestAngle = std::numbers::pi;
    for (int f = faces; f < patched.faceCount(); ++f) {
      const auto& t = patched.faces[f];
      ASSERT_EQ(t.size(), 3u);
      EXPECT_EQ(patched.sourceFace[f], -1) << "a cap: no face of the file";
      for (int i = 0; i < 3; ++i) {
        const Point3& a = patched.positions[t[i]];
        const Point3& b = patched.positions[t[(i + 1) % 3]];
        const Point3& c = patched.positions[t[(i + 2) % 3]];
        longest = std::max(longest, (b - a).norm());
        const Point3 u = b - a, v = c - a;
        smallestAngle = std::min(smallestAngle, std::atan2(u.cross(v).norm(), u.dot(v)));
      }
    }
    for (int v = vertices; v < patched.vertexCount(); ++v) EXPECT_EQ(patched.sourceVertex[v], -1);
    EXPECT_GT(patched.vertexCount(), vertices) << "refined: new vertices inside the holes";
    // (A fan from the middle of the head's 38-edge loop has sides six edges long.)
    EXPECT_LT(longest, 1.5 * edge) << "no triangle much longer than the loop's edges";
    EXPECT_GT(smallestAngle, 2 * std::numbers::pi / 180) << "no sliver";
  }
}

// A hole of 600 corners (a short wide tube, open at both ends): past the
// least-area triangulation's reach, a fan refined; and not to the loop's
// own edge length, which would take some 65,000 triangles a hole, but to
// about the most a patch is refined to.
TEST(HoleFilling, AHoleOfManyCornersIsPatchedWithinItsBudget) {
  constexpr int kAround = 600;
  PolygonMesh tube;
  for (int ring = 0; ring < 2; ++ring) {
    for (int i = 0; i < kAround; ++i) {
      const double a = 2 * std::numbers::pi * i / kAround;
      tube.positions.emplace_back(10 * std::cos(a), 10 * std::sin(a), ring * 0.2);
    }
  }
  for (int i = 0; i < kAround; ++i) {
    const int j = (i + 1) % kAround;
    tube.faces.push_back({i, j, kAround + j, kAround + i});
  }
  ASSERT_EQ(analyzeMesh(tube).topology.boundaryLoops, 2);
  EXPECT_EQ(patchHoles(tube), 2);
  const MeshAnalysis after = analyzeMesh(tube);
  EXPECT_TRUE(after.usable()) << (after.problems.empty() ? "" : after.problems[0].message);
  EXPECT_EQ(after.topology.boundaryLoops, 0);
  EXPECT_EQ(after.topology.genus, 0);
  const int patchFaces = tube.faceCount() - kAround;
  EXPECT_GT(patchFaces, 2 * 2000) << "refined, not a fan alone";
  EXPECT_LT(patchFaces, 2 * 25000) << "about 20,000 triangles a hole at most";
}

// Where one face across the half cylinder's open side turns its normal
// against the curved faces beside it (the Newell normal of the loop points
// down, the arch's top faces up), the patch bends with the hole: at every
// edge of the loop the two faces' normals do not oppose.
TEST(HoleFilling, ThePatchOfABentHoleDoesNotFoldBackOverItsNeighbours) {
  PolygonMesh mesh = publicMesh("cylinder.off");
  const int faces = mesh.faceCount();
  analyzeMesh(mesh);
  patchHoles(mesh);
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  std::map<std::pair<int, int>, int> faceOfSide;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    for (size_t i = 0; i < face.size(); ++i) faceOfSide[{face[i], face[(i + 1) % face.size()]}] = f;
  }
  const auto normal = [&](int f) {
    const auto& t = mesh.faces[f];
    return Point3((mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]))
        .normalized();
  };
  double leastCosine = 1;
  int loopEdges = 0;
  for (int f = faces; f < mesh.faceCount(); ++f) {
    const auto& t = mesh.faces[f];
    for (int i = 0; i < 3; ++i) {
      const int other = faceOfSide.at({t[(i + 1) % 3], t[i]});
      if (other >= faces) continue;  // inside the patch
      ++loopEdges;
      leastCosine = std::min(leastCosine, normal(f).dot(normal(other)));
    }
  }
  EXPECT_EQ(loopEdges, 136);
  // (One face across it meets the arch's top at -1: folded flat back.)
  EXPECT_GE(leastCosine, -0.5) << "no face of the patch turned more than 120 degrees from the face beside it";
}

}  // namespace
}  // namespace rotafab::geometry
