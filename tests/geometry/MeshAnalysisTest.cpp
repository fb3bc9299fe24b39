// Validation and topology: each broken mesh is named element by element, an
// inconsistent orientation is repaired, and the counts of `inspect` are right.

#include "geometry/MeshAnalysis.h"

#include <gtest/gtest.h>

#include <numbers>

#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

std::vector<std::string> messages(const MeshAnalysis& analysis) {
  std::vector<std::string> out;
  for (const auto& p : analysis.problems) out.push_back(p.message);
  return out;
}

TEST(MeshAnalysis, EdgeSharedByThreeFacesIsNamed) {
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  mesh.faces = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}};
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_EQ(messages(analysis), std::vector<std::string>{"edge (0, 1) is shared by 3 faces (0, 1, 2)"});
  EXPECT_FALSE(analysis.topology.manifold);
  EXPECT_FALSE(analysis.topology.genus.has_value());
}

TEST(MeshAnalysis, BowTieVertexIsNamed) {
  // Two tetrahedra touching at one vertex: every edge is fine, the vertex is not.
  PolygonMesh mesh = tetrahedron();
  test::append(mesh, tetrahedron(), Point3(2, 2, 2));  // vertex 0 of the copy lands on (3,3,3); move it onto vertex 0
  mesh.positions[4] = mesh.positions[0];
  for (auto& face : mesh.faces)
    for (int& v : face)
      if (v == 4) v = 0;
  mesh.positions.erase(mesh.positions.begin() + 4);
  for (auto& face : mesh.faces)
    for (int& v : face)
      if (v > 4) --v;
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_EQ(messages(analysis),
            std::vector<std::string>{"vertex 0 at (1, 1, 1) is a bow-tie: its faces form 2 separate fans"});
  EXPECT_FALSE(analysis.topology.manifold);
}

TEST(MeshAnalysis, HolesTouchingAtABowTieAreTwoLoops) {
  // Two triangles sharing only vertex 0: a walk along the boundary finds two loops.
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
  mesh.faces = {{0, 1, 2}, {0, 3, 4}};
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_EQ(analysis.topology.boundaryLoops, 2);
  EXPECT_EQ(analysis.topology.components, 1);
  ASSERT_EQ(analysis.problems.size(), 1u);
  EXPECT_EQ(analysis.problems[0].kind, MeshProblemKind::BowTieVertex);
}

TEST(MeshAnalysis, InconsistentOrientationIsRepairedAndSaid) {
  PolygonMesh mesh = cube();
  std::reverse(mesh.faces[1].begin(), mesh.faces[1].end());
  std::reverse(mesh.faces[4].begin(), mesh.faces[4].end());
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_TRUE(analysis.usable());
  EXPECT_EQ(analysis.flippedFaces, 2);
  EXPECT_EQ(analysis.notes, std::vector<std::string>{"flipped 2 faces to make the orientation consistent"});
  EXPECT_EQ(mesh.faces, cube().faces);
}

TEST(MeshAnalysis, InsideOutClosedMeshIsTurnedOutwards) {
  PolygonMesh mesh = icosahedron();
  for (auto& face : mesh.faces) std::reverse(face.begin(), face.end());
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_EQ(analysis.notes,
            std::vector<std::string>{"reversed all faces of 1 closed component so that they face outwards"});
  PolygonMesh expected = icosahedron();
  EXPECT_EQ(mesh.faces, expected.faces);
}

TEST(MeshAnalysis, MoebiusStripIsRefusedAsNonOrientable) {
  PolygonMesh mesh = moebiusStrip(10);
  const MeshAnalysis analysis = analyzeMesh(mesh);
  ASSERT_EQ(analysis.problems.size(), 1u);
  EXPECT_EQ(analysis.problems[0].kind, MeshProblemKind::NonOrientable);
  EXPECT_NE(analysis.problems[0].message.find("the surface is not orientable"), std::string::npos);
  EXPECT_FALSE(analysis.topology.orientable);
  EXPECT_TRUE(analysis.topology.manifold);
  EXPECT_EQ(analysis.topology.euler, 0);
  EXPECT_THROW(requireUsable(analysis), InvalidMeshError);
}

TEST(MeshAnalysis, ZeroAreaFaceAndRepeatedCornerAreNamed) {
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {0, 1, 0}, {1, 1, 0}};
  mesh.faces = {{0, 1, 2}, {0, 1, 3, 4, 1}};
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_EQ(messages(analysis), (std::vector<std::string>{"face 0 has zero area (its corners (0, 1, 2) are collinear)",
                                                          "face 1 visits vertex 1 more than once"}));
  try {
    requireUsable(analysis);
    FAIL() << "accepted";
  } catch (const InvalidMeshError& error) {
    EXPECT_STREQ(error.what(),
                 "face 0 has zero area (its corners (0, 1, 2) are collinear) (and 1 more problem; `rotafab inspect` "
                 "lists them)");
  }
}

TEST(MeshAnalysis, CountsOfSeveralComponentsAndBoundaries) {
  // A cube, a torus and an open disc, side by side.
  PolygonMesh mesh = cube();
  test::append(mesh, torus(6, 4), Point3(10, 0, 0));
  test::append(mesh, disc(5), Point3(-10, 0, 0));
  const MeshTopology t = test::topologyOf(mesh);
  EXPECT_EQ(t.components, 3);
  EXPECT_EQ(t.boundaryLoops, 1);
  EXPECT_EQ(t.vertices, 8 + 24 + 6);
  EXPECT_EQ(t.euler, 2 + 0 + 1);
  EXPECT_EQ(t.genus, 0 + 1 + 0);
}

TEST(MeshAnalysis, OpenCylinderAndPuncturedTorus) {
  // A torus with one quad removed: genus 1, one boundary loop.
  PolygonMesh punctured = torus(6, 4);
  punctured.faces.erase(punctured.faces.begin() + 5);
  MeshTopology t = test::topologyOf(punctured);
  EXPECT_EQ(t.boundaryLoops, 1);
  EXPECT_EQ(t.genus, 1);
  EXPECT_EQ(t.euler, -1);
  // A ring of quads around the torus's tube cut out leaves a cylinder: two loops, genus 0.
  PolygonMesh cylinder = torus(6, 4);
  cylinder.faces.resize(4 * 3);  // the first three rings of quads
  cleanMesh(cylinder);           // and the vertices they leave unused
  t = test::topologyOf(cylinder);
  EXPECT_EQ(t.boundaryLoops, 2);
  EXPECT_EQ(t.genus, 0);
  EXPECT_EQ(t.components, 1);
}

}  // namespace
}  // namespace rotafab::geometry
