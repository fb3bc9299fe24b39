// The dual mesh (dissertation V.2).

#include "geometry/DualMesh.h"

#include <gtest/gtest.h>

#include "geometry/Primitives.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

DualMesh dualOf(PolygonMesh& mesh) {
  requireUsable(analyzeMesh(mesh));
  return dualMesh(mesh, RotationSystem::fromMesh(mesh));
}

TEST(DualMesh, SwapsVerticesAndFacesKeepsEdgesAndGenus) {
  for (PolygonMesh mesh : {tetrahedron(), cube(), icosahedron(), truncatedIcosahedron(), torus(7, 5), genusTwoSlab()}) {
    const MeshTopology primal = test::topologyOf(mesh);
    DualMesh dual = dualOf(mesh);
    PolygonMesh dualCopy = dual.mesh;
    const MeshAnalysis analysis = analyzeMesh(dualCopy);
    EXPECT_TRUE(analysis.usable());
    EXPECT_EQ(analysis.flippedFaces, 0) << "dual faces must keep the primal's orientation";
    EXPECT_EQ(dualCopy.faces, dual.mesh.faces) << "and face outwards";
    EXPECT_EQ(analysis.topology.vertices, primal.faces);
    EXPECT_EQ(analysis.topology.faces, primal.vertices);
    EXPECT_EQ(analysis.topology.edges, primal.edges);
    EXPECT_EQ(analysis.topology.genus, primal.genus);
    // A dual face has as many sides as its vertex's valence; a dual vertex sits at its face's centroid.
    const RotationSystem rs = RotationSystem::fromMesh(mesh);
    for (int f = 0; f < dual.mesh.faceCount(); ++f) {
      EXPECT_EQ(static_cast<int>(dual.mesh.faces[f].size()), rs.valence(dual.primalVertexOfFace[f]));
    }
    for (int f = 0; f < mesh.faceCount(); ++f) EXPECT_TRUE(dual.mesh.positions[f].isApprox(faceCentroid(mesh, f)));
  }
}

TEST(DualMesh, IcosahedronAndDodecahedronAreDual) {
  PolygonMesh ico = icosahedron();
  const DualMesh dual = dualOf(ico);
  for (const auto& face : dual.mesh.faces) EXPECT_EQ(face.size(), 5u);
  EXPECT_EQ(dual.mesh.faceCount(), 12);
  // The dual of the dual has the primal's combinatorics: V, E, F and face sizes.
  PolygonMesh dualMeshCopy = dual.mesh;
  const DualMesh back = dualOf(dualMeshCopy);
  EXPECT_EQ(back.mesh.faceCount(), 20);
  for (const auto& face : back.mesh.faces) EXPECT_EQ(face.size(), 3u);
}

TEST(DualMesh, OpenMeshGetsDualFacesOnlyAtInteriorVertices) {
  PolygonMesh fan = disc(6);
  const DualMesh dual = dualOf(fan);
  EXPECT_EQ(dual.mesh.vertexCount(), 6);
  ASSERT_EQ(dual.mesh.faceCount(), 1);
  EXPECT_EQ(dual.primalVertexOfFace[0], 0);
  EXPECT_EQ(dual.mesh.faces[0].size(), 6u);
}

}  // namespace
}  // namespace rotafab::geometry
