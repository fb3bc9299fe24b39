// Face defect (eq. 3.3) and the discrete Gauss-Bonnet theorem (eq. 3.4-3.5).

#include "geometry/Curvature.h"

#include <gtest/gtest.h>

#include <numbers>
#include <random>

#include "geometry/CornerCutting.h"
#include "geometry/Primitives.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

constexpr double kPi = std::numbers::pi;

TEST(Curvature, PlanarFacesHaveNoDefect) {
  for (const PolygonMesh& mesh : {cube(), dodecahedron(), truncatedIcosahedron()}) {
    for (int f = 0; f < mesh.faceCount(); ++f) EXPECT_NEAR(faceDefect(mesh, f), 0.0, 1e-12);
  }
}

TEST(Curvature, SkewQuadHasTheDefectOfItsAngles) {
  // Corners of a unit square with one corner lifted by h: every angle changes.
  PolygonMesh quad;
  const double h = 0.5;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, h}, {0, 1, 0}};
  quad.faces = {{0, 1, 2, 3}};
  const double lifted = std::acos(Eigen::Vector3d(0, -1, -h).normalized().dot(Eigen::Vector3d(-1, 0, -h).normalized()));
  const double beside = std::acos(Eigen::Vector3d(-1, 0, 0).dot(Eigen::Vector3d(0, 1, h).normalized()));
  EXPECT_NEAR(faceDefect(quad, 0), kPi / 2 + 2 * beside + lifted - 2 * kPi, 1e-12);
  EXPECT_LT(faceDefect(quad, 0), 0.0) << "a saddle-shaped quad is hyperbolic (III.2.1)";
}

TEST(Curvature, CubeCornersCarryHalfPiEach) {
  PolygonMesh mesh = cube();
  const RotationSystem rs = RotationSystem::fromMesh(mesh);
  for (int v = 0; v < 8; ++v) EXPECT_NEAR(vertexDefect(mesh, rs, v), kPi / 2, 1e-12);
}

// Discrete Gauss-Bonnet: vertex defects plus face defects are 2 pi chi,
// closed or open; with planar faces the vertex defects alone.
TEST(Curvature, VertexAndFaceDefectsAddUpToTwoPiChi) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> jitter(-0.15, 0.15);
  for (PolygonMesh mesh :
       {tetrahedron(), icosahedron(), truncatedIcosahedron(), torus(9, 6), genusTwoSlab(), disc(7)}) {
    const MeshTopology t = test::topologyOf(mesh);
    const RotationSystem rs = RotationSystem::fromMesh(mesh);
    EXPECT_NEAR(totalFaceDefect(mesh), 0.0, 1e-9) << "planar faces";
    EXPECT_NEAR(totalVertexDefect(mesh, rs), 2 * kPi * t.euler, 1e-9);
    // Move every vertex: quads become skew, their defects no longer vanish,
    // and only the sum of both kinds of defect keeps its value.
    for (auto& p : mesh.positions) p += Point3(jitter(random), jitter(random), jitter(random));
    const double faces = totalFaceDefect(mesh);
    EXPECT_NEAR(totalVertexDefect(mesh, rs) + faces, 2 * kPi * t.euler, 1e-9);
    if (mesh.faces[0].size() > 3) {
      EXPECT_GT(std::abs(faces), 1e-3);
    }
  }
}

// In a band decomposition all curvature sits in the holes (III.2.1): the
// holes' defects plus the material faces' own defects add up to 2 pi chi,
// whatever the tension. This is a combinatorial identity (it holds for any
// positions); what it checks is that corner cutting puts every new vertex on
// exactly one hole and closes the surface, for every tension.
TEST(Curvature, BandDecompositionHolesCarryTheCurvature) {
  for (PolygonMesh mesh : {cube(), icosahedron(), truncatedIcosahedron(), torus(8, 5), genusTwoSlab()}) {
    const MeshTopology t = test::topologyOf(mesh);
    const RotationSystem rs = RotationSystem::fromMesh(mesh);
    for (double a : {0.5, 0.7}) {
      const CornerCutMesh cut = cornerCut(mesh, rs, a);
      std::vector<char> isHole(cut.mesh.faces.size(), 0);
      for (int f : cut.faceOfFace) isHole[f] = 1;
      EXPECT_NEAR(holeAndMaterialDefect(cut.mesh, isHole), 2 * kPi * t.euler, 1e-9);
    }
  }
}

}  // namespace
}  // namespace rotafab::geometry
