// Even panels for a panel count (geometry/Remeshing.h): the mesh remeshed
// to about the faces asked has faces of even size, keeps its shape (distances
// measured by tests/support/Hausdorff.h, apart from the code under test), its
// genus, components, boundary and sharp creases, and names a face of the file
// under each face.

#include "geometry/Remeshing.h"
#include "geometry/TriangleMeshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>

#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/Hausdorff.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

PolygonMesh exampleMesh(const std::string& name) {
  PolygonMesh mesh = importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/" + name).mesh;
  analyzeMesh(mesh);
  return mesh;
}

double faceArea(const PolygonMesh& mesh, int face) {
  const auto& f = mesh.faces[face];
  Point3 sum = Point3::Zero();
  for (size_t i = 1; i + 1 < f.size(); ++i) {
    sum += (mesh.positions[f[i]] - mesh.positions[f[0]]).cross(mesh.positions[f[i + 1]] - mesh.positions[f[0]]);
  }
  return sum.norm() / 2;
}

// The smallest face's area over the median's.
double smallestOverMedian(const PolygonMesh& mesh) {
  std::vector<double> areas;
  for (int f = 0; f < mesh.faceCount(); ++f) areas.push_back(faceArea(mesh, f));
  std::sort(areas.begin(), areas.end());
  return areas.front() / areas[areas.size() / 2];
}

// Every triangle, and the largest and mean distances both ways, as shares
// of the input's bounding-box diagonal.
void expectShapeKept(const PolygonMesh& original, const PolygonMesh& remeshed, double largest, double mean) {
  const double diagonal = boundingBoxDiagonal(original);
  const test::SampledDistances there = test::sampledDistances(remeshed, original, 3);
  const test::SampledDistances back = test::sampledDistances(original, remeshed, 3);
  EXPECT_LT(std::max(there.largest, back.largest), largest * diagonal)
      << "largest " << std::max(there.largest, back.largest) / diagonal << " of the diagonal";
  EXPECT_LT((there.mean + back.mean) / 2, mean * diagonal) << "mean " << (there.mean + back.mean) / 2 / diagonal;
}

void expectSameTopology(const PolygonMesh& original, PolygonMesh remeshed) {
  const MeshTopology before = test::topologyOf(original);
  const MeshAnalysis after = analyzeMesh(remeshed);
  EXPECT_TRUE(after.usable());
  EXPECT_EQ(after.topology.genus, before.genus);
  EXPECT_EQ(after.topology.components, before.components);
  EXPECT_EQ(after.topology.boundaryLoops, before.boundaryLoops);
  EXPECT_EQ(after.flippedFaces, 0);
  for (const auto& face : remeshed.faces) EXPECT_EQ(face.size(), 3u);
}

TEST(Remeshing, TheBunnyAt1000PanelsIsEvenAndKeepsItsShape) {
  const PolygonMesh original = exampleMesh("bunny.obj");
  PolygonMesh mesh = original;
  const Remeshing result = remeshEvenly(mesh, 1000, test::context());
  EXPECT_TRUE(result.remeshed);
  EXPECT_EQ(result.facesBefore, 3674);
  EXPECT_EQ(result.facesAfter, mesh.faceCount());
  EXPECT_NEAR(mesh.faceCount(), 1000, 50);
  expectSameTopology(original, mesh);
  expectShapeKept(original, mesh, 0.03, 0.006);
  EXPECT_GE(smallestOverMedian(mesh), 1.0 / 3) << "no sliver";
  EXPECT_NEAR(result.smallestAreaRatio, smallestOverMedian(mesh), 1e-9);
  EXPECT_GT(result.largestMove, 0) << "the ears' rims are not on a surface of 1000 faces";
  EXPECT_LT(result.largestMove, 0.03 * boundingBoxDiagonal(original));
  for (int f = 0; f < mesh.faceCount(); ++f) {
    EXPECT_GE(mesh.sourceFaceIndex(f), 0);
    EXPECT_LT(mesh.sourceFaceIndex(f), 3674);
  }
}

TEST(Remeshing, ACountAboveTheFacesGivenSplitsThem) {
  const PolygonMesh original = exampleMesh("bunny.obj");
  PolygonMesh mesh = original;
  remeshEvenly(mesh, 6000, test::context());
  EXPECT_NEAR(mesh.faceCount(), 6000, 300);
  expectSameTopology(original, mesh);
  expectShapeKept(original, mesh, 0.015, 0.002);
}

TEST(Remeshing, TheCubeKeepsItsCornersAndEdges) {
  const PolygonMesh original = cube();
  PolygonMesh mesh = original;
  const Remeshing result = remeshEvenly(mesh, 300, test::context());
  EXPECT_EQ(result.creaseEdges, 12);
  EXPECT_NEAR(mesh.faceCount(), 300, 15);
  expectSameTopology(original, mesh);
  // Every vertex on the cube's surface; its 8 corners among them.
  Point3 lo = original.positions[0], hi = original.positions[0];
  for (const Point3& p : original.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  int corners = 0;
  for (const Point3& p : mesh.positions) {
    int onFaces = 0;
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_GE(p[axis], lo[axis] - 1e-9);
      EXPECT_LE(p[axis], hi[axis] + 1e-9);
      onFaces += std::abs(p[axis] - lo[axis]) < 1e-9 || std::abs(p[axis] - hi[axis]) < 1e-9 ? 1 : 0;
    }
    EXPECT_GE(onFaces, 1) << formatPoint(p) << " is inside the cube";
    corners += onFaces == 3 ? 1 : 0;
  }
  EXPECT_EQ(corners, 8);
  // No triangle across an edge of the cube: each lies in one of its faces.
  for (const auto& face : mesh.faces) {
    bool inOnePlane = false;
    for (int axis = 0; axis < 3 && !inOnePlane; ++axis) {
      for (const double plane : {lo[axis], hi[axis]}) {
        inOnePlane = inOnePlane || std::all_of(face.begin(), face.end(),
                                               [&](int v) { return std::abs(mesh.positions[v][axis] - plane) < 1e-9; });
      }
    }
    EXPECT_TRUE(inOnePlane);
  }
  EXPECT_GE(smallestOverMedian(mesh), 1.0 / 3);
}

TEST(Remeshing, AnOpenSurfaceKeepsItsBoundaryWhereItWas) {
  // A height field over the unit square: its boundary stays on the square's sides.
  const auto height = [](double x, double y) {
    return 0.2 * std::exp(-20 * ((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)));
  };
  PolygonMesh original;
  const int n = 40;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = double(i) / n, y = double(j) / n;
      original.positions.emplace_back(x, y, height(x, y));
    }
  }
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i;
      original.faces.push_back({a, a + 1, a + n + 2, a + n + 1});
    }
  }
  PolygonMesh mesh = original;
  remeshEvenly(mesh, 400, test::context());
  EXPECT_NEAR(mesh.faceCount(), 400, 20);
  expectSameTopology(original, mesh);
  std::map<std::pair<int, int>, int> sides;
  for (const auto& face : mesh.faces) {
    for (size_t i = 0; i < face.size(); ++i) {
      const int a = face[i], b = face[(i + 1) % face.size()];
      ++sides[{std::min(a, b), std::max(a, b)}];
    }
  }
  for (const auto& [edge, count] : sides) {
    if (count != 1) continue;
    for (int v : {edge.first, edge.second}) {
      const Point3& p = mesh.positions[v];
      const double fromSide = std::min({p.x(), 1 - p.x(), p.y(), 1 - p.y()});
      EXPECT_LT(std::abs(fromSide), 1e-9) << formatPoint(p) << " left the boundary";
      EXPECT_NEAR(p.z(), height(p.x(), p.y()), 1e-4) << "on the input's boundary, piecewise linear";
    }
  }
  expectShapeKept(original, mesh, 0.01, 0.002);
}

TEST(Remeshing, TheTorusKeepsItsHole) {
  const PolygonMesh original = torus(24, 12);
  PolygonMesh mesh = original;
  remeshEvenly(mesh, 500, test::context());
  EXPECT_NEAR(mesh.faceCount(), 500, 25);
  expectSameTopology(original, mesh);
  EXPECT_GE(smallestOverMedian(mesh), 1.0 / 3);
}

// CGAL's machined parts at a weave's 400 panels: a crease that ends up a
// loop of three vertices, each relaxed toward the other two, once shrank
// to a point and left faces of no area (a usable mesh no more).
TEST(Remeshing, MachinedPartsWithSmallCreaseLoopsStayUsable) {
  for (const char* name : {"anchor.off", "handle.off", "couplingdown.off", "oblong.off"}) {
    SCOPED_TRACE(name);
    PolygonMesh original = importMesh(test::publicMesh(test::cgalMesh(name)).string()).mesh;
    analyzeMesh(original);
    PolygonMesh mesh = original;
    EXPECT_TRUE(remeshEvenly(mesh, 267, test::context()).remeshed);
    expectSameTopology(original, mesh);
  }
}

TEST(Remeshing, AMeshWithAboutTheFacesAskedIsKeptAsDrawn) {
  PolygonMesh mesh = torus(12, 12);  // 144 quads
  const PolygonMesh original = mesh;
  const Remeshing result = remeshEvenly(mesh, 150, test::context());
  EXPECT_FALSE(result.remeshed);
  EXPECT_EQ(mesh.faces, original.faces);
  EXPECT_THROW(remeshEvenly(mesh, 0, test::context()), std::invalid_argument);
}

TEST(Remeshing, TheSameMeshAndCountGiveTheSameFacesEveryTime) {
  PolygonMesh first = exampleMesh("bunny.obj"), second = first;
  remeshEvenly(first, 800, test::context());
  remeshEvenly(second, 800, test::context());
  EXPECT_EQ(first.faces, second.faces);
  EXPECT_EQ(first.positions, second.positions);
}

TEST(Remeshing, ACancelStopsIt) {
  PolygonMesh mesh = exampleMesh("bunny.obj");
  test::TestContext context(1);
  context.cancellation().cancel();
  EXPECT_THROW(remeshEvenly(mesh, 1000, context), core::Cancelled);
}

TEST(Remeshing, TheHausdorffCheckSeesAShapeThatMoved) {
  // The checks above can fail: the bunny moved by 2% of its diagonal is 2% away.
  const PolygonMesh original = exampleMesh("bunny.obj");
  PolygonMesh moved = original;
  const double diagonal = boundingBoxDiagonal(original);
  for (Point3& p : moved.positions) p.x() += 0.02 * diagonal;
  EXPECT_GT(test::hausdorffDistance(original, moved, 1), 0.015 * diagonal);
}

TEST(TriangleMeshes, ANonConvexFaceIsCoveredByItsTriangles) {
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
      const double area =
          (mesh.positions[t[1]] - mesh.positions[t[0]]).cross(mesh.positions[t[2]] - mesh.positions[t[0]]).dot(normal) /
          2;
      EXPECT_GT(area, 0) << "face " << f << ": a triangle turns the wrong way or is empty";
      sum += area;
    }
    EXPECT_NEAR(sum, areas[f], 1e-9) << "face " << f;
  }
}

TEST(TriangleMeshes, APolygonWhoseEarsWouldDoubleAnEdgeIsFannedInstead) {
  // A pentagon, and a triangle below it on one of the diagonals its ears
  // use (as a CGAL cow has): those ears would give that edge a third face.
  PolygonMesh pentagon;
  pentagon.positions = {{0, 0, 0}, {1, -1, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, {1, 0, -1}};
  pentagon.faces = {{0, 1, 2, 3, 4}};
  const auto ears = faceTriangles(pentagon, 0);
  std::pair<int, int> diagonal{-1, -1};
  for (const auto& t : ears) {
    for (int i = 0; i < 3; ++i) {
      const int a = t[i], b = t[(i + 1) % 3];
      if ((b - a + 5) % 5 != 1 && (a - b + 5) % 5 != 1) diagonal = {a, b};
    }
  }
  ASSERT_GE(diagonal.first, 0);
  PolygonMesh mesh = pentagon;
  mesh.faces.insert(mesh.faces.begin(), {diagonal.first, diagonal.second, 5});
  triangles::TriMesh tri;
  triangles::SourceNumbers source;
  const triangles::QuietOpenMesh quiet;
  EXPECT_NO_THROW(triangles::toTriangleMesh(mesh, tri, source));
  EXPECT_EQ(tri.n_faces(), 4u);
}
}  // namespace
}  // namespace rotafab::geometry
