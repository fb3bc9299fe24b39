// `--repair auto` (geometry/MeshRepair.h): each repair makes a broken mesh
// of the kind people download usable, is counted and names its first
// element as the file numbers it; what cannot be repaired is still refused;
// a mesh that needs nothing is left alone.

#include "geometry/MeshRepair.h"

#include <gtest/gtest.h>

#include "geometry/BandStructure.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

// Welded at identical positions, as the importer leaves a mesh.
PolygonMesh cleaned(PolygonMesh mesh) {
  cleanMesh(mesh);
  return mesh;
}

std::vector<std::string> kinds(const std::vector<MeshRepair>& repairs) {
  std::vector<std::string> out;
  for (const auto& r : repairs) out.push_back(r.kind);
  return out;
}

// Repairs, analyses, and checks that the result is a usable, orientable manifold.
MeshAnalysis repairedAndUsable(PolygonMesh& mesh, std::vector<MeshRepair>& repairs) {
  repairs = repairMesh(mesh);
  MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_TRUE(analysis.usable()) << (analysis.problems.empty() ? "" : analysis.problems.front().message);
  EXPECT_TRUE(analysis.topology.manifold);
  EXPECT_TRUE(analysis.topology.orientable);
  return analysis;
}

TEST(MeshRepair, AMeshThatNeedsNothingIsLeftAlone) {
  for (PolygonMesh mesh : {cube(), torus(8, 5), disc(6), truncatedIcosahedron()}) {
    const PolygonMesh before = mesh;
    EXPECT_TRUE(repairMesh(mesh).empty());
    EXPECT_EQ(mesh.positions, before.positions);
    EXPECT_EQ(mesh.faces, before.faces);
  }
}

TEST(MeshRepair, TwoSolidsTouchingAtAVertexAreSplitThere) {
  // A tetrahedron and its mirror image through its vertex 0: they meet there only.
  PolygonMesh mesh = tetrahedron();
  const Point3 apex = mesh.positions[0];
  test::append(mesh, tetrahedron(), Point3::Zero());
  for (int v = 4; v < 8; ++v) mesh.positions[v] = 2 * apex - mesh.positions[v - 4];
  mesh = cleaned(mesh);
  ASSERT_EQ(mesh.vertexCount(), 7);
  ASSERT_FALSE(analyzeMesh(mesh).usable());
  std::vector<MeshRepair> repairs;
  const MeshAnalysis analysis = repairedAndUsable(mesh, repairs);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"split-bowtie"});
  EXPECT_EQ(repairs[0].count, 1);
  EXPECT_EQ(repairs[0].first, "vertex 0");
  EXPECT_EQ(analysis.topology.components, 2);
  EXPECT_EQ(analysis.topology.genus, 0);
  EXPECT_EQ(analysis.topology.vertices, 8);
}

TEST(MeshRepair, TwoCubesSharingAnEdgeAreSplitAlongIt) {
  PolygonMesh mesh = cube();
  test::append(mesh, cube(), Point3(2, 2, 0));  // the cubes span [-1, 1]: they share the edge x = y = 1
  mesh = cleaned(mesh);
  ASSERT_EQ(mesh.vertexCount(), 14);
  std::vector<MeshRepair> repairs;
  const MeshAnalysis analysis = repairedAndUsable(mesh, repairs);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"split-nonmanifold-edge"});
  EXPECT_EQ(repairs[0].count, 1);
  EXPECT_EQ(analysis.topology.components, 2);
  EXPECT_EQ(analysis.topology.vertices, 16);
  EXPECT_EQ(analysis.topology.genus, 0);
  EXPECT_EQ(analysis.topology.boundaryLoops, 0) << "each cube keeps its own edge, closed";
}

TEST(MeshRepair, AFinOnASurfaceGetsItsOwnEdgeAndTheSurfaceStaysClosed) {
  PolygonMesh mesh = cube();
  // A triangle standing on the cube's edge between vertices a and b.
  const auto& face = mesh.faces[0];
  const int a = face[0], b = face[1];
  const Point3 middle = (mesh.positions[a] + mesh.positions[b]) / 2;
  mesh.positions.push_back(middle + 3 * middle.normalized());
  mesh.faces.push_back({a, b, mesh.vertexCount() - 1});
  std::vector<MeshRepair> repairs;
  const MeshAnalysis analysis = repairedAndUsable(mesh, repairs);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"split-nonmanifold-edge"});
  EXPECT_EQ(analysis.topology.components, 2);
  EXPECT_EQ(analysis.topology.boundaryLoops, 1) << "the fin alone is open";
  EXPECT_EQ(analysis.topology.faces, 7);
}

TEST(MeshRepair, DuplicateFacesGoInEitherDirection) {
  PolygonMesh mesh = cube();
  std::vector<int> reversed(mesh.faces[2].rbegin(), mesh.faces[2].rend());
  std::rotate(reversed.begin(), reversed.begin() + 1, reversed.end());
  mesh.faces.push_back(mesh.faces[4]);
  mesh.faces.push_back(reversed);
  std::vector<MeshRepair> repairs;
  const MeshAnalysis analysis = repairedAndUsable(mesh, repairs);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"drop-duplicate-face"});
  EXPECT_EQ(repairs[0].count, 2);
  EXPECT_EQ(repairs[0].first, "face 6");
  EXPECT_EQ(analysis.topology.faces, 6);
  EXPECT_EQ(analysis.topology.genus, 0);
}

TEST(MeshRepair, NearVerticesAreWeldedAndTheFacesTheyCollapseDropped) {
  // A cube whose face 5 has its own copies of its corners, each off by a
  // millionth of the size, as a file written in single precision gives them;
  // and a sliver triangle between two of them, which the weld collapses.
  PolygonMesh mesh = cube();
  const std::vector<int> shared = mesh.faces[5];
  std::vector<int> own;
  for (int v : shared) {
    own.push_back(mesh.vertexCount());
    mesh.positions.push_back(mesh.positions[v] + Point3(1e-7, -1e-7, 0));
  }
  mesh.faces[5] = own;
  mesh.faces.push_back({own[0], shared[0], own[1]});
  EXPECT_GT(test::topologyOf(mesh).boundaryLoops, 0) << "unwelded, face 5 is apart";
  std::vector<MeshRepair> repairs;
  const MeshAnalysis analysis = repairedAndUsable(mesh, repairs);
  ASSERT_EQ(kinds(repairs), (std::vector<std::string>{"weld", "drop-collapsed-face"}));
  EXPECT_EQ(repairs[0].count, 4);
  EXPECT_EQ(repairs[0].first, "vertex 8");
  EXPECT_EQ(repairs[1].count, 1);
  EXPECT_EQ(repairs[1].first, "face 6");
  EXPECT_EQ(analysis.topology.vertices, 8);
  EXPECT_EQ(analysis.topology.faces, 6);
  EXPECT_EQ(analysis.topology.boundaryLoops, 0);
}

TEST(MeshRepair, VerticesFartherApartThanTheToleranceStayApart) {
  // Two discs, one above the other by a ten-thousandth of their size: two
  // sheets, as a designer may stack them, not one.
  PolygonMesh mesh = disc(8);
  test::append(mesh, disc(8), Point3(0, 0, 1e-4 * boundingBoxDiagonal(mesh)));
  const int before = mesh.vertexCount();
  EXPECT_TRUE(repairMesh(mesh).empty());
  EXPECT_EQ(mesh.vertexCount(), before);
  EXPECT_EQ(test::topologyOf(mesh).components, 2);
}

TEST(MeshRepair, WhatCannotBeRepairedIsStillRefused) {
  PolygonMesh mesh = moebiusStrip(9);
  repairMesh(mesh);
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_FALSE(analysis.usable());
  EXPECT_FALSE(analysis.topology.orientable);
}

TEST(MeshRepair, MessagesNameTheFilesNumbering) {
  test::TempDir dir;
  // Two tetrahedra that share vertex 2 of the file (its unused vertex 0 is dropped on import).
  const auto file = dir.write("bowtie.off",
                              "OFF\n8 8 0\n9 9 9\n0 0 0\n1 1 1\n1 0 0\n0 1 0\n2 2 1\n2 1 2\n1 2 2\n"
                              "3 1 3 4\n3 1 4 2\n3 1 2 3\n3 3 2 4\n"
                              "3 2 5 6\n3 2 6 7\n3 2 7 5\n3 5 7 6\n");
  ImportedMesh imported = importMesh(file);
  const auto repairs = repairMesh(imported.mesh);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"split-bowtie"});
  EXPECT_EQ(repairs[0].first, "vertex 2");
  EXPECT_EQ(repairs[0].line(), "split 1 bow-tie vertex into one copy per fan of faces (the first: vertex 2)");
  EXPECT_TRUE(analyzeMesh(imported.mesh).usable());
}

// A face of zero area, as CAD programs write them: a square pyramid
// whose edge (0, 1) has a vertex 5 in its middle, and the face (0, 1, 5)
// (the file's face 2) across it. It is collapsed, vertex 5 into 0, and the
// pyramid is left, named by the file's face.
TEST(MeshRepair, AFaceOfZeroAreaIsCollapsedAway) {
  test::TempDir dir;
  const auto file = dir.write("cap.off",
                              "OFF\n6 8 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 0.5 1\n0.5 0 0\n"
                              "3 0 3 2\n3 0 2 1\n3 0 1 5\n3 0 5 4\n3 5 1 4\n3 1 2 4\n3 2 3 4\n3 3 0 4\n");
  ImportedMesh imported = importMesh(file);
  const MeshAnalysis before = analyzeMesh(imported.mesh);
  ASSERT_FALSE(before.usable());
  EXPECT_NE(before.problems.front().message.find("face 2 has zero area"), std::string::npos);
  const auto repairs = repairMesh(imported.mesh);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"collapse-degenerate-face"});
  EXPECT_EQ(repairs[0].first, "face 2");
  EXPECT_EQ(repairs[0].count, 1);
  EXPECT_DOUBLE_EQ(repairs[0].moved, 0.5);
  EXPECT_EQ(repairs[0].line(),
            "collapsed 1 face of zero area (collinear corners) into its neighbours, moving the surface at most 0.5 in "
            "(the first: face 2)");
  const MeshAnalysis after = analyzeMesh(imported.mesh);
  EXPECT_TRUE(after.usable());
  EXPECT_EQ(after.topology.faces, 6);
  EXPECT_EQ(after.topology.vertices, 5);
  EXPECT_EQ(after.topology.genus, 0);
}

TEST(MeshRepair, AWallInsideASolidIsCutOffAndItsOpenSidesCounted) {
  // Two cubes side by side with the square between them kept: each of its
  // four edges has three faces, and no two of them belong together.
  PolygonMesh mesh = cube();
  test::append(mesh, cube(), Point3(2, 0, 0));
  mesh = cleaned(mesh);
  // The shared square is in both cubes once (x = 1), facing opposite ways:
  // keep one of them as the wall, drop the other.
  const auto repairs = repairMesh(mesh);
  const MeshAnalysis analysis = analyzeMesh(mesh);
  ASSERT_FALSE(repairs.empty());
  const auto cut = std::find_if(repairs.begin(), repairs.end(),
                                [](const MeshRepair& r) { return r.kind == "split-nonmanifold-edge"; });
  ASSERT_NE(cut, repairs.end()) << repairs.front().line();
  EXPECT_EQ(cut->count, 4);
  EXPECT_GT(cut->leftOpen, 0);
  EXPECT_NE(cut->line().find("left open"), std::string::npos) << cut->line();
  EXPECT_TRUE(analysis.usable());
}

TEST(MeshRepair, AWeldNeverMakesAFaceVisitAVertexTwice) {
  // A hexagon pinched in its middle: corners 0 and 3 a millionth apart.
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {-1, 1, 0}, {-1, -1, 0}, {1e-7, 0, 0}, {1, -1, 0}, {1, 1, 0}};
  mesh.faces = {{0, 1, 2, 3, 4, 5}};
  const auto repairs = repairMesh(mesh);
  EXPECT_TRUE(repairs.empty()) << repairs.front().line();
  EXPECT_EQ(mesh.faces.front().size(), 6u);
}

TEST(MeshRepair, CgalsCowHasABowTieAndIsUsableOnceRepaired) {
  ImportedMesh imported = importMesh(test::publicMesh(test::cgalMesh("cow.off")));
  EXPECT_FALSE(analyzeMesh(imported.mesh).usable());
  std::vector<MeshRepair> repairs;
  const MeshAnalysis analysis = repairedAndUsable(imported.mesh, repairs);
  ASSERT_EQ(kinds(repairs), std::vector<std::string>{"split-bowtie"});
  EXPECT_EQ(repairs[0].first, "vertex 44");
  EXPECT_EQ(analysis.topology.genus, 0);
  EXPECT_EQ(analysis.topology.components, 1);
}

TEST(MeshRepair, TwoCubesSharingAnEdgeBuildAsTwoStructures) {
  PolygonMesh mesh = cube();
  test::append(mesh, cube(), Point3(2, 2, 0));
  mesh = cleaned(mesh);
  repairMesh(mesh);
  const PolygonMesh built = test::atBuildableSize(mesh);
  const Structure structure = buildBandStructure(built, BandOptions{}, test::context());
  EXPECT_EQ(structure.panels.size(), 12u);
}

}  // namespace
}  // namespace rotafab::geometry
