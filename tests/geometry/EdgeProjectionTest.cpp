// The projection method's edge regions (dissertation IV.1.2, eq. 4.12-4.16;
// docs/WEAVE.md, A4-A5): the plane through each edge's midpoint holds the
// edge and the projected face centres, its normal lies between the two
// faces' and is normal to the edge, the region's corners turn
// counter-clockwise seen from outside, and two faces folded onto each
// other are refused naming their edge.
#include "geometry/EdgeProjection.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "geometry/BandDecomposition.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"

namespace rotafab::geometry {
namespace {

struct Prepared {
  PolygonMesh mesh;
  RotationSystem rs;
};

Prepared prepared(PolygonMesh mesh) {
  requireUsable(analyzeMesh(mesh));
  RotationSystem rs = RotationSystem::fromMesh(mesh);
  return {std::move(mesh), std::move(rs)};
}

TEST(EdgeProjection, ThePlaneHoldsTheEdgeAndTheProjectedCentresAndTheRegionTurnsCounterClockwise) {
  std::vector<std::pair<const char*, PolygonMesh>> meshes{
      {"cube", cube()}, {"soccer ball", truncatedIcosahedron()}, {"torus", torus(9, 6)}, {"genus-2", genusTwoSlab()}};
  meshes.emplace_back("bunny", importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj").mesh);
  for (auto& [name, mesh] : meshes) {
    SCOPED_TRACE(name);
    const auto [oriented, rs] = prepared(mesh);
    const auto regions = edgeRegions(oriented, rs);
    ASSERT_EQ(regions.size(), static_cast<size_t>(rs.edgeCount()));
    for (int e = 0; e < rs.edgeCount(); ++e) {
      const EdgeRegion& r = regions[static_cast<size_t>(e)];
      const Point3 along = (r.end - r.start).normalized();
      const double scale = (r.end - r.start).norm();
      EXPECT_NEAR(r.normal.norm(), 1.0, 1e-12);
      EXPECT_NEAR(r.normal.dot(along), 0.0, 1e-12) << "edge " << e;
      EXPECT_TRUE(r.midpoint.isApprox((r.start + r.end) / 2));
      for (const Point3& p : {r.start, r.end, r.leftCentre, r.rightCentre}) {
        EXPECT_NEAR((p - r.midpoint).dot(r.normal), 0.0, 1e-9 * scale) << "edge " << e;
      }
      // Each projected centre is its face's centre moved along N_e only.
      const int left = rs.face(2 * e), right = rs.face(2 * e + 1);
      EXPECT_LT((faceCentroid(oriented, left) - r.leftCentre).cross(r.normal).norm(), 1e-9 * scale);
      EXPECT_LT((faceCentroid(oriented, right) - r.rightCentre).cross(r.normal).norm(), 1e-9 * scale);
      // N_e points out, as the faces' normals do.
      EXPECT_GT(r.normal.dot(faceNormal(oriented, left) + faceNormal(oriented, right)), 0.0) << "edge " << e;
      // start, right centre, end, left centre: counter-clockwise about N_e.
      const Point3 turn =
          (r.rightCentre - r.start).cross(r.end - r.start) + (r.end - r.start).cross(r.leftCentre - r.start);
      EXPECT_GT(turn.dot(r.normal), 0.0) << "edge " << e;
      // The bilinear map's corners.
      EXPECT_TRUE(r.at(0, 0).isApprox(r.start));
      EXPECT_TRUE(r.at(1, 1).isApprox(r.end));
      EXPECT_TRUE(r.at(0, 1).isApprox(r.leftCentre));
      EXPECT_TRUE(r.at(1, 0).isApprox(r.rightCentre));
    }
  }
}

TEST(EdgeProjection, OnACubeTheNormalIsTheFacesNormalsMeanAndOnAFlatPairTheirs) {
  const auto [mesh, rs] = prepared(cube());
  Point3 centre = Point3::Zero();
  for (const Point3& p : mesh.positions) centre += p / static_cast<double>(mesh.positions.size());
  for (const EdgeRegion& r : edgeRegions(mesh, rs)) {
    // The two faces' normals are axes; their mean, normalised, points away from the centre, at 45 degrees.
    EXPECT_GT(r.normal.dot(r.midpoint - centre), 0.0);
    EXPECT_NEAR(r.normal.cwiseAbs().maxCoeff(), std::sqrt(0.5), 1e-12);
  }
  // A box of two cubes side by side: where two coplanar faces meet, N_e is
  // their plane's normal and projecting moves nothing.
  const auto box = prepared(voxelSurface(2, 1, 1, [](int, int, int) { return true; }));
  int flat = 0;
  const auto regions = edgeRegions(box.mesh, box.rs);
  for (int e = 0; e < box.rs.edgeCount(); ++e) {
    const EdgeRegion& r = regions[static_cast<size_t>(e)];
    const Point3 leftCentre = faceCentroid(box.mesh, box.rs.face(2 * e));
    if ((leftCentre - r.leftCentre).norm() > 1e-12) continue;
    ++flat;
    EXPECT_TRUE(faceCentroid(box.mesh, box.rs.face(2 * e + 1)).isApprox(r.rightCentre));
    EXPECT_NEAR(r.normal.cwiseAbs().maxCoeff(), 1.0, 1e-12);
  }
  EXPECT_EQ(flat, 4) << "the four edges between the two cubes' coplanar sides";
}

TEST(EdgeProjection, FacesFoldedOntoEachOtherAreRefusedNamingTheEdge) {
  // A tetrahedron pressed flat: every edge's two faces lie in one plane,
  // and along three of them they fold back onto each other.
  PolygonMesh flat;
  flat.positions = {{0, 0, 0}, {3, 0, 0}, {0, 3, 0}, {0.8, 0.7, 0}};
  flat.faces = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  const RotationSystem rs = RotationSystem::fromMesh(flat);
  try {
    (void)edgeRegions(flat, rs);
    ADD_FAILURE() << "a flat tetrahedron was projected";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).rfind("edge ", 0), 0u) << error.what();
    EXPECT_NE(std::string(error.what()).find("its two faces fold back onto each other"), std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace rotafab::geometry
