// Faces as the designer meant them (geometry/CoplanarMerge.h): triangles
// that lie within the angle of one plane become one face when that face is
// a simple polygon, and nothing else changes.

#include "geometry/CoplanarMerge.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <numbers>

#include "geometry/BandStructure.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"

namespace rotafab::geometry {
namespace {

// Each face as a fan of triangles from its first corner, as an STL holds it.
PolygonMesh fanTriangulated(const PolygonMesh& mesh) {
  PolygonMesh triangles;
  triangles.positions = mesh.positions;
  for (const auto& face : mesh.faces)
    for (size_t i = 1; i + 1 < face.size(); ++i) triangles.faces.push_back({face[0], face[i], face[i + 1]});
  return triangles;
}

// A prism over a plane polygon (counter-clockwise), `height` tall, with
// polygon caps and quad sides, facing outwards.
PolygonMesh prism(const std::vector<Eigen::Vector2d>& outline, double height) {
  PolygonMesh mesh;
  const int n = static_cast<int>(outline.size());
  for (const auto& p : outline) mesh.positions.emplace_back(p.x(), p.y(), 0);
  for (const auto& p : outline) mesh.positions.emplace_back(p.x(), p.y(), height);
  std::vector<int> bottom, top;
  for (int i = 0; i < n; ++i) {
    top.push_back(n + i);
    bottom.push_back((n - i) % n);  // reversed, keeping corner 0 first
    mesh.faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  }
  mesh.faces.push_back(bottom);
  mesh.faces.push_back(top);
  return mesh;
}

int facesWithSides(const PolygonMesh& mesh, size_t sides) {
  return static_cast<int>(std::count_if(mesh.faces.begin(), mesh.faces.end(),
                                        [&](const std::vector<int>& f) { return f.size() == sides; }));
}

TEST(CoplanarMerge, ACubeOfTwelveTrianglesIsSixSquaresAgain) {
  PolygonMesh mesh = fanTriangulated(cube());
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const CoplanarMerge merged = mergeCoplanarFaces(mesh, 1.0);
  EXPECT_EQ(merged.facesBefore, 12);
  EXPECT_EQ(merged.facesAfter, 6);
  EXPECT_EQ(merged.regions, 6);
  EXPECT_EQ(facesWithSides(mesh, 4), 6);
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_TRUE(analysis.usable());
  EXPECT_EQ(analysis.flippedFaces, 0) << "the merged faces keep the triangles' orientation";
  EXPECT_EQ(analysis.topology.genus, 0);
  EXPECT_EQ(analysis.topology.vertices, 8);
  EXPECT_EQ(mesh.sourceFace, (std::vector<int>{0, 2, 4, 6, 8, 10})) << "each merged face keeps its seed's index";
}

TEST(CoplanarMerge, ABarOfUnitSquaresIsABoxOfSixFacesAndBuilds) {
  // Three unit cubes in a row, as voxel programs write them: the long sides'
  // inner vertices have only two faces around them once merged, and go.
  PolygonMesh mesh = fanTriangulated(voxelSurface(3, 1, 1, [](int, int, int) { return true; }));
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const CoplanarMerge merged = mergeCoplanarFaces(mesh, 1.0);
  EXPECT_EQ(merged.facesAfter, 6);
  EXPECT_EQ(merged.straightened, 8);
  EXPECT_EQ(facesWithSides(mesh, 4), 6);
  EXPECT_EQ(mesh.vertexCount(), 8);
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const Structure structure = buildBandStructure(test::atBuildableSize(mesh), BandOptions{}, test::context());
  EXPECT_EQ(structure.panels.size(), 6u);
}

TEST(CoplanarMerge, ACurvedSurfaceIsLeftAlone) {
  // Every pair of neighbours meets at an angle: nothing to merge. (Not a
  // hull of points spread over a sphere: four of them may lie within a
  // degree of one plane, and their two triangles rightly become one face.)
  for (PolygonMesh mesh : {tetrahedron(), octahedron(), icosahedron()}) {
    const PolygonMesh before = mesh;
    EXPECT_EQ(mergeCoplanarFaces(mesh, 1.0).regions, 0);
    EXPECT_EQ(mesh.faces, before.faces);
    EXPECT_EQ(mesh.positions, before.positions);
  }
}

TEST(CoplanarMerge, TheSoccerBallsTrianglesAreItsPentagonsAndHexagonsAgain) {
  PolygonMesh mesh = fanTriangulated(truncatedIcosahedron());
  EXPECT_EQ(mergeCoplanarFaces(mesh, 1.0).facesAfter, 32);
  EXPECT_EQ(facesWithSides(mesh, 5), 12);
  EXPECT_EQ(facesWithSides(mesh, 6), 20);
}

TEST(CoplanarMerge, AVertexInsideAMergedFaceGoes) {
  // A hexagon cut into six triangles around its centre, on a pyramid's base.
  PolygonMesh mesh;
  mesh.positions.emplace_back(0, 0, 0);
  for (int i = 0; i < 6; ++i) {
    const double a = i * std::numbers::pi / 3;
    mesh.positions.emplace_back(std::cos(a), std::sin(a), 0);
  }
  mesh.positions.emplace_back(0, 0, 1.5);
  for (int i = 0; i < 6; ++i) {
    mesh.faces.push_back({0, 1 + (i + 1) % 6, 1 + i});  // the base, facing down
    mesh.faces.push_back({1 + i, 1 + (i + 1) % 6, 7});  // the sides
  }
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const CoplanarMerge merged = mergeCoplanarFaces(mesh, 1.0);
  EXPECT_EQ(merged.facesAfter, 7);
  EXPECT_EQ(facesWithSides(mesh, 6), 1);
  EXPECT_EQ(mesh.vertexCount(), 7) << "the centre went";
  EXPECT_EQ(mesh.sourceVertexIndex(0), 1) << "the others keep their source index";
  EXPECT_TRUE(analyzeMesh(mesh).usable());
}

TEST(CoplanarMerge, TheAngleDecides) {
  // Two triangles of a square folded along its diagonal by half a degree.
  const double lift = std::tan(0.5 * std::numbers::pi / 180) * std::sqrt(0.5);
  PolygonMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.positions[3].z() = lift;  // one corner up, the diagonal 0-2 flat
  mesh.faces = {{0, 1, 2}, {0, 2, 3}};
  PolygonMesh strict = mesh;
  EXPECT_EQ(mergeCoplanarFaces(strict, 0.25).regions, 0);
  EXPECT_EQ(mergeCoplanarFaces(mesh, 1.0).regions, 1);
  EXPECT_EQ(mesh.faces, std::vector<std::vector<int>>({{0, 1, 2, 3}}));
}

TEST(CoplanarMerge, APlaneRegionWithAHoleIsNotOneFace) {
  // A square frame: its outline would be two loops.
  PolygonMesh mesh;
  for (double s : {2.0, 1.0})
    for (auto [x, y] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) mesh.positions.emplace_back(s * x, s * y, 0);
  for (int i = 0; i < 4; ++i) {
    const int j = (i + 1) % 4;
    mesh.faces.push_back({i, j, 4 + j});
    mesh.faces.push_back({i, 4 + j, 4 + i});
  }
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const PolygonMesh before = mesh;
  EXPECT_EQ(mergeCoplanarFaces(mesh, 1.0).regions, 0);
  EXPECT_EQ(mesh.faces, before.faces);
}

TEST(CoplanarMerge, AnLShapedPrismIsEightFacesAndBuilds) {
  // The L's caps are not convex: fanned from their reflex corner, merged back.
  const std::vector<Eigen::Vector2d> outline = {{1, 1}, {1, 2}, {0, 2}, {0, 0}, {2, 0}, {2, 1}};
  PolygonMesh mesh = fanTriangulated(prism(outline, 1.0));
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const CoplanarMerge merged = mergeCoplanarFaces(mesh, 1.0);
  EXPECT_EQ(merged.facesAfter, 8);
  EXPECT_EQ(facesWithSides(mesh, 6), 2);
  EXPECT_EQ(facesWithSides(mesh, 4), 6);
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  const PolygonMesh built = test::atBuildableSize(mesh);
  const Structure structure = buildBandStructure(built, BandOptions{}, test::context());
  EXPECT_EQ(structure.panels.size(), 8u);
}

}  // namespace
}  // namespace rotafab::geometry
