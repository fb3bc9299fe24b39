// Generalized corner cutting (dissertation V.1.1, eq. 5.1-5.2).

#include "geometry/CornerCutting.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <numbers>

#include "geometry/Primitives.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

TEST(CornerCutting, CoefficientsArePositiveAndSumToOne) {
  for (int sides = 3; sides <= 12; ++sides) {
    for (double a : {0.05, 5.0 / 12, dooSabinTension(sides), 0.7, 0.95}) {
      const Eigen::MatrixXd w = cornerCuttingWeights(sides, a);
      for (int n = 0; n < sides; ++n) {
        EXPECT_NEAR(w.row(n).sum(), 1.0, 1e-12);
        EXPECT_GT(w.row(n).minCoeff(), 0.0);
        EXPECT_DOUBLE_EQ(w(n, n), a);
      }
    }
  }
}

TEST(CornerCutting, DooSabinOnAQuadIsTheBiquadraticBSplineRule) {
  EXPECT_DOUBLE_EQ(dooSabinTension(4), 9.0 / 16);
  const Eigen::MatrixXd w = cornerCuttingWeights(4, dooSabinTension(4));
  EXPECT_NEAR(w(0, 1), 3.0 / 16, 1e-15);
  EXPECT_NEAR(w(0, 2), 1.0 / 16, 1e-15);
  EXPECT_NEAR(w(0, 3), 3.0 / 16, 1e-15);
}

// The scheme's eigenvalues are 1, ((2a+1)N-5)/(3N-5) twice and (3aN-5)/(3N-5);
// for Doo-Sabin 1, 1/2, 1/4 whatever N.
TEST(CornerCutting, EigenvaluesAreTheDissertations) {
  for (int sides = 3; sides <= 9; ++sides) {
    for (double a : {dooSabinTension(sides), 0.6, 0.8}) {
      Eigen::VectorXd values = Eigen::EigenSolver<Eigen::MatrixXd>(cornerCuttingWeights(sides, a)).eigenvalues().real();
      std::sort(values.data(), values.data() + sides, std::greater<>());
      const double second = ((2 * a + 1) * sides - 5) / (3.0 * sides - 5);
      const double third = (3 * a * sides - 5) / (3.0 * sides - 5);
      EXPECT_NEAR(values[0], 1.0, 1e-12);
      std::vector<double> expected{second, second};
      for (int i = 3; i < sides; ++i) expected.push_back(third);
      std::sort(expected.begin(), expected.end(), std::greater<>());
      for (int i = 1; i < sides; ++i) EXPECT_NEAR(values[i], expected[i - 1], 1e-12) << "N=" << sides << " a=" << a;
    }
  }
  for (int sides = 3; sides <= 12; ++sides) {  // Doo-Sabin: 1/2 and 1/4 for every N
    const double a = dooSabinTension(sides);
    EXPECT_NEAR(((2 * a + 1) * sides - 5) / (3.0 * sides - 5), 0.5, 1e-12);
    EXPECT_NEAR((3 * a * sides - 5) / (3.0 * sides - 5), 0.25, 1e-12);
  }
}

TEST(CornerCutting, RejectsTensionOutsideTheOpenUnitInterval) {
  EXPECT_THROW(cornerCuttingWeights(4, 0.0), std::invalid_argument);
  EXPECT_THROW(cornerCuttingWeights(4, 1.0), std::invalid_argument);
  EXPECT_THROW(cornerCuttingWeights(2, 0.5), std::invalid_argument);
}

TEST(CornerCutting, VerticesBecomeFacesEdgesBecomeQuadsFacesShrink) {
  for (PolygonMesh mesh :
       {tetrahedron(), cube(), dodecahedron(), truncatedIcosahedron(), torus(6, 5), genusTwoSlab()}) {
    const MeshTopology before = test::topologyOf(mesh);
    const RotationSystem rs = RotationSystem::fromMesh(mesh);
    const CornerCutMesh cut = cornerCut(mesh, rs);
    EXPECT_EQ(cut.mesh.faceCount(), before.faces + before.edges + before.vertices);
    EXPECT_EQ(cut.mesh.vertexCount(), 2 * before.edges);
    for (int v = 0; v < mesh.vertexCount(); ++v) {
      EXPECT_EQ(static_cast<int>(cut.mesh.faces[cut.faceOfVertex[v]].size()), rs.valence(v));
    }
    for (int e = 0; e < rs.edgeCount(); ++e) EXPECT_EQ(cut.mesh.faces[cut.faceOfEdge[e]].size(), 4u);
    for (int f = 0; f < mesh.faceCount(); ++f)
      EXPECT_EQ(cut.mesh.faces[cut.faceOfFace[f]].size(), mesh.faces[f].size());
    // A band decomposition of the same surface: manifold, oriented like the input, same genus.
    PolygonMesh result = cut.mesh;
    const MeshAnalysis analysis = analyzeMesh(result);
    EXPECT_TRUE(analysis.usable());
    EXPECT_EQ(analysis.flippedFaces, 0);
    EXPECT_EQ(result.faces, cut.mesh.faces);
    EXPECT_EQ(analysis.topology.genus, before.genus);
  }
}

// On a regular polygon the new face is the old one scaled about its centre by
// the second eigenvalue ((2a+1)N-5)/(3N-5): "each face becomes a similar face".
TEST(CornerCutting, RegularFacesShrinkToSimilarFaces) {
  for (PolygonMesh mesh : {cube(), dodecahedron(), truncatedIcosahedron()}) {
    const RotationSystem rs = RotationSystem::fromMesh(mesh);
    for (double a : {0.5, 0.6, 0.75}) {
      const CornerCutMesh cut = cornerCut(mesh, rs, a);
      for (int f = 0; f < mesh.faceCount(); ++f) {
        const int sides = static_cast<int>(mesh.faces[f].size());
        const double scale = ((2 * a + 1) * sides - 5) / (3.0 * sides - 5);
        const Point3 centre = faceCentroid(mesh, f);
        const auto& shrunk = cut.mesh.faces[cut.faceOfFace[f]];
        for (int n = 0; n < sides; ++n) {
          const Point3 expected = centre + scale * (mesh.positions[mesh.faces[f][n]] - centre);
          EXPECT_LT((cut.mesh.positions[shrunk[n]] - expected).norm(), 1e-12);
        }
      }
    }
  }
}

TEST(CornerCutting, OpenMeshCutsOnlyInteriorEdgesAndVertices) {
  PolygonMesh fan = disc(6);
  const RotationSystem rs = RotationSystem::fromMesh(fan);
  const CornerCutMesh cut = cornerCut(fan, rs);
  EXPECT_EQ(cut.mesh.faceCount(), 6 + 6 + 1);  // face copies, spoke quads, the centre's hexagon
  EXPECT_EQ(cut.faceOfVertex[1], -1);
  PolygonMesh result = cut.mesh;
  EXPECT_TRUE(analyzeMesh(result).usable());
}

}  // namespace
}  // namespace rotafab::geometry
