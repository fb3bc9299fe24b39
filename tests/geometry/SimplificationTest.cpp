// A panel count the builders choose (geometry/Simplification.h): the mesh
// simplified to about the faces asked keeps its shape (Hausdorff distance to
// the original, measured by tests/support/Hausdorff.h), its genus, its
// components and its boundary, and every face left still names a face of
// the file.

#include "geometry/Simplification.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <map>
#include <numbers>
#include <set>

#include "geometry/MeshAnalysis.h"
#include "geometry/io/MeshImport.h"
#include "support/Hausdorff.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"

namespace rotafab::geometry {
namespace {

PolygonMesh example(const std::string& name) {
  PolygonMesh mesh = importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/" + name).mesh;
  analyzeMesh(mesh);
  return mesh;
}

// A height field of n x n quads over the unit square, open along its edge,
// with a bump in the middle so that the quadrics have something to keep.
PolygonMesh bumpyGrid(int n) {
  PolygonMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = double(i) / n, y = double(j) / n;
      mesh.positions.emplace_back(x, y, 0.2 * std::exp(-20 * ((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5))));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      mesh.faces.push_back({a, a + 1, a + n + 2, a + n + 1});
    }
  }
  return mesh;
}

std::set<std::array<double, 3>> boundaryPoints(const PolygonMesh& mesh) {
  std::map<std::pair<int, int>, int> sides;
  for (const auto& face : mesh.faces) {
    for (size_t i = 0; i < face.size(); ++i) {
      const int a = face[i], b = face[(i + 1) % face.size()];
      ++sides[{std::min(a, b), std::max(a, b)}];
    }
  }
  std::set<std::array<double, 3>> points;
  for (const auto& [edge, count] : sides) {
    if (count != 1) continue;
    for (int v : {edge.first, edge.second}) {
      const Point3& p = mesh.positions[v];
      points.insert({p.x(), p.y(), p.z()});
    }
  }
  return points;
}

TEST(Simplification, TheBunnyAt2000FacesKeepsItsShapeAndGenus) {
  const PolygonMesh original = example("bunny.obj");
  ASSERT_EQ(original.faceCount(), 3674);
  PolygonMesh mesh = original;
  const Simplification result = simplifyMesh(mesh, 2000, test::context());
  EXPECT_EQ(result.facesBefore, 3674);
  EXPECT_EQ(result.facesAfter, mesh.faceCount());
  EXPECT_NEAR(mesh.faceCount(), 2000, 100);
  EXPECT_FALSE(result.triangulated);

  const MeshTopology before = test::topologyOf(original);
  const MeshAnalysis after = analyzeMesh(mesh);
  EXPECT_TRUE(after.usable());
  EXPECT_EQ(after.topology.genus, before.genus);
  EXPECT_EQ(after.topology.components, 1);
  EXPECT_EQ(after.topology.boundaryLoops, 0);
  EXPECT_EQ(after.flippedFaces, 0) << "the faces keep the orientation they had";

  const double diagonal = boundingBoxDiagonal(original);
  const double distance = test::hausdorffDistance(original, mesh);
  EXPECT_LT(distance, 0.01 * diagonal) << "Hausdorff distance " << distance << " of a diagonal of " << diagonal;

  std::set<int> sources;
  for (int f = 0; f < mesh.faceCount(); ++f) sources.insert(mesh.sourceFaceIndex(f));
  EXPECT_EQ(sources.size(), size_t(mesh.faceCount())) << "each face left is one triangle of the file";
  EXPECT_GE(*sources.begin(), 0);
  EXPECT_LT(*sources.rbegin(), 3674);
}

TEST(Simplification, FarBelowItsFacesTheBunnyStillKeepsItsShape) {
  // 3,674 to 600: most of the way by multiple choice, the rest by the queue.
  const PolygonMesh original = example("bunny.obj");
  PolygonMesh mesh = original;
  simplifyMesh(mesh, 600, test::context());
  EXPECT_NEAR(mesh.faceCount(), 600, 30);
  const MeshAnalysis after = analyzeMesh(mesh);
  EXPECT_TRUE(after.usable());
  EXPECT_EQ(after.topology.genus, 0);
  EXPECT_EQ(after.topology.components, 1);
  const double distance = test::hausdorffDistance(original, mesh);
  EXPECT_LT(distance, 0.02 * boundingBoxDiagonal(original)) << distance / boundingBoxDiagonal(original);
}

TEST(Simplification, TheSameMeshAndCountGiveTheSameFacesEveryTime) {
  // Multiple choice picks edges at random: the same picks every time.
  const PolygonMesh original = example("bunny.obj");
  PolygonMesh first = original, second = original;
  simplifyMesh(first, 600, test::context());
  std::srand(12345);  // whatever else ran before
  simplifyMesh(second, 600, test::context());
  EXPECT_EQ(first.faces, second.faces);
  EXPECT_EQ(first.positions, second.positions);
}

TEST(Simplification, TheHausdorffCheckSeesAShapeThatMoved) {
  // The check above can fail: the bunny moved by 2% of its diagonal is 2% away.
  const PolygonMesh original = example("bunny.obj");
  PolygonMesh moved = original;
  const double diagonal = boundingBoxDiagonal(original);
  for (Point3& p : moved.positions) p.x() += 0.02 * diagonal;
  EXPECT_GT(test::hausdorffDistance(original, moved, 1), 0.015 * diagonal);
}

TEST(Simplification, PolygonsAreSplitAndTheTorusKeepsItsHole) {
  const PolygonMesh original = example("torus.obj");  // 288 quads, genus 1
  PolygonMesh mesh = original;
  const Simplification result = simplifyMesh(mesh, 200, test::context());
  EXPECT_TRUE(result.triangulated);
  EXPECT_NEAR(mesh.faceCount(), 200, 10);
  for (const auto& face : mesh.faces) EXPECT_EQ(face.size(), 3u);
  const MeshAnalysis after = analyzeMesh(mesh);
  EXPECT_TRUE(after.usable());
  EXPECT_EQ(after.topology.genus, 1);
  EXPECT_EQ(after.topology.components, 1);
  EXPECT_LT(test::hausdorffDistance(original, mesh), 0.05 * boundingBoxDiagonal(original));
}

TEST(Simplification, TheBoundaryStaysWhereItWas) {
  const PolygonMesh original = bumpyGrid(24);  // 576 quads, 96 boundary vertices
  PolygonMesh mesh = original;
  simplifyMesh(mesh, 300, test::context());
  EXPECT_NEAR(mesh.faceCount(), 300, 15);
  EXPECT_EQ(boundaryPoints(mesh), boundaryPoints(original));
  const MeshTopology topology = test::topologyOf(mesh);
  EXPECT_EQ(topology.boundaryLoops, 1);
  EXPECT_EQ(topology.genus, 0);
  EXPECT_LT(test::hausdorffDistance(original, mesh), 0.01 * boundingBoxDiagonal(original));
}

TEST(Simplification, AMeshWithNoMoreFacesThanAskedIsLeftAsItIs) {
  const PolygonMesh original = example("torus.obj");
  PolygonMesh mesh = original;
  const Simplification result = simplifyMesh(mesh, 288, test::context());
  EXPECT_FALSE(result.simplified());
  EXPECT_EQ(mesh.faces, original.faces);
  EXPECT_THROW(simplifyMesh(mesh, 0, test::context()), std::invalid_argument);
}

TEST(Simplification, AClosedSurfaceThatWouldFoldFlatIsRefused) {
  // An octahedron asked for 4 faces: the collapses, each within its limits,
  // would leave four points in a plane, covered twice.
  PolygonMesh mesh;
  mesh.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  mesh.faces = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  ASSERT_TRUE(analyzeMesh(mesh).usable());
  PolygonMesh asked = mesh;
  try {
    simplifyMesh(asked, 4, test::context());
    ADD_FAILURE() << "simplified to " << asked.faceCount() << " faces";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("at 4 faces the surface would fold onto itself"), std::string::npos)
        << error.what();
  }
  PolygonMesh six = mesh;
  simplifyMesh(six, 6, test::context());
  EXPECT_EQ(test::topologyOf(six).genus, 0);
}

TEST(Simplification, ACancelStopsIt) {
  PolygonMesh mesh = example("bunny.obj");
  test::TestContext context(1);
  context.cancellation().cancel();
  EXPECT_THROW(simplifyMesh(mesh, 500, context), core::Cancelled);
}

TEST(Simplification, ItReportsProgress) {
  PolygonMesh mesh = example("bunny.obj");
  test::TestContext context(1);
  simplifyMesh(mesh, 1000, context);
  const auto progress = context.progress();
  ASSERT_FALSE(progress.empty());
  EXPECT_EQ(progress.back().step, "simplify");
  EXPECT_GT(progress.back().done, 0u);
  EXPECT_LE(progress.back().done, progress.back().total);
}

double triangleArea(const PolygonMesh& mesh, const std::array<int, 3>& t, const Point3& normal) {
  const Point3 &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
  return 0.5 * (b - a).cross(c - a).dot(normal);  // signed: negative if it turns the wrong way
}

TEST(Simplification, ANonConvexFaceIsCoveredByItsTriangles) {
  // An L-shaped hexagon and a five-pointed star (10 corners) in a tilted plane.
  PolygonMesh mesh;
  const Point3 u = Point3(1, 0, 1).normalized(), v = Point3(0, 1, 0), normal = u.cross(v);
  auto add = [&](const std::vector<std::pair<double, double>>& outline) {
    std::vector<int> face;
    for (const auto& [x, y] : outline) {
      face.push_back(mesh.vertexCount());
      mesh.positions.push_back(u * x + v * y);
    }
    mesh.faces.push_back(face);
  };
  add({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});  // area 3
  std::vector<std::pair<double, double>> star;
  for (int k = 0; k < 10; ++k) {
    const double angle = std::numbers::pi / 2 + k * std::numbers::pi / 5, r = k % 2 == 0 ? 1.0 : 0.4;
    star.emplace_back(5 + r * std::cos(angle), r * std::sin(angle));
  }
  add(star);
  double starArea = 0;
  for (size_t k = 0; k < star.size(); ++k) {
    const auto& [x0, y0] = star[k];
    const auto& [x1, y1] = star[(k + 1) % star.size()];
    starArea += 0.5 * (x0 * y1 - x1 * y0);
  }
  const std::vector<double> areas = {3.0, starArea};
  for (int f = 0; f < 2; ++f) {
    const auto triangles = faceTriangles(mesh, f);
    EXPECT_EQ(triangles.size(), mesh.faces[f].size() - 2);
    double sum = 0;
    for (const auto& t : triangles) {
      const double area = triangleArea(mesh, t, normal);
      EXPECT_GT(area, 0) << "face " << f << ": a triangle turns the wrong way or is empty";
      sum += area;
    }
    EXPECT_NEAR(sum, areas[f], 1e-9) << "face " << f;
  }
}

}  // namespace
}  // namespace rotafab::geometry
