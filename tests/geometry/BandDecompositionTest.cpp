// Band decomposition structures (dissertation V.1-V.4): vertex bands, developable
// edge bands and unfolded vertex panels, on closed meshes of genus 0, 1 and 2,
// open surfaces and mixed polygon faces.

#include "geometry/BandDecomposition.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <string>

#include "geometry/Curvature.h"
#include "geometry/DevelopableBands.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/PanelUnfolding.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

// An open grid of n x n quads over [-1, 1]^2 lifted to z = height(x, y),
// counter-clockwise seen from +z.
PolygonMesh heightField(int n, const std::function<double(double, double)>& height) {
  PolygonMesh mesh;
  for (int j = 0; j <= n; ++j) {
    for (int i = 0; i <= n; ++i) {
      const double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
      mesh.positions.emplace_back(x, y, height(x, y));
    }
  }
  const auto at = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) mesh.faces.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
  }
  return mesh;
}

struct UnfoldedBands {
  PolygonMesh mesh;
  RotationSystem rs;
  BandDecomposition decomposition;
  std::vector<EdgeBand> bands;
  std::vector<FlatPanel> panels;
};

UnfoldedBands build(PolygonMesh mesh) {
  const MeshAnalysis analysis = analyzeMesh(mesh);
  EXPECT_TRUE(analysis.usable());
  UnfoldedBands s{mesh, RotationSystem::fromMesh(mesh), {}, {}, {}};
  s.decomposition = bandDecomposition(s.mesh, s.rs);
  s.bands = developableBands(s.rs, s.decomposition);
  for (int f = 0; f < s.mesh.faceCount(); ++f) s.panels.push_back(unfoldPanel(s.rs, s.decomposition, s.bands, f));
  return s;
}

// The test meshes: genus 0, 1 and 2, open surfaces (one with saddles
// everywhere), mixed pentagons and hexagons, the bunny (triangles, many
// saddles), and meshes other programs wrote (tests/data/external/README.md):
// Geomview's open tube of quads and its abstract polyhedron, CGAL's double
// torus with three holes and its cube of mixed polygons, an STL of OpenSCAD's.
std::map<std::string, PolygonMesh> testMeshes() {
  std::map<std::string, PolygonMesh> meshes{
      {"cube", cube()},
      {"octahedron", octahedron()},
      {"soccer ball", truncatedIcosahedron()},
      {"torus", torus(12, 8)},
      {"genus 2", genusTwoSlab()},
      {"disc", disc(9)},
      {"monkey saddle", heightField(8, [](double x, double y) { return 0.6 * (x * x * x - 3 * x * y * y); })},
      {"voxels", voxelSurface(3, 3, 2, [](int x, int y, int z) { return !(x == 1 && y == 1 && z == 1); })},
  };
  meshes["bunny"] = importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj").mesh;
  // The bunny is about 0.15 units across: scale it to its construction size (mean edge 2 in).
  for (Point3& p : meshes["bunny"].positions) p *= 400;
  for (const std::string& where :
       std::vector<std::string>{"/usr/share/geomview/geom/tref.off", "/usr/share/geomview/geom/abstr.off",
                                test::cgalMesh("double-torus-3-holes.off"), test::cgalMesh("cube_poly.off"),
                                "/usr/share/openscad/testdata/scad/3D/features/import.stl"}) {
    const auto path = test::publicMesh(where);
    meshes[path.filename().string()] = test::atConstructionSize(importMesh(path.string()).mesh);
  }
  return meshes;
}

double relative(double a, double b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-12}); }

TEST(BandDecomposition, OnePanelPerFaceAndTwoCopiesOfEveryInteriorBand) {
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    ASSERT_EQ(s.panels.size(), static_cast<size_t>(s.mesh.faceCount())) << name;
    std::vector<int> copies(s.rs.edgeCount(), 0);
    for (const FlatPanel& panel : s.panels) {
      for (const FlatBand& band : panel.bands) ++copies[band.edge];
    }
    for (int e = 0; e < s.rs.edgeCount(); ++e) {
      EXPECT_EQ(copies[e], s.rs.isBoundaryEdge(e) ? 0 : 2) << name << ": edge " << e;
    }
  }
}

TEST(BandDecomposition, VertexBandsArePlanarAndFaceOutwards) {
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    for (int f = 0; f < s.mesh.faceCount(); ++f) {
      const VertexBand& vb = s.decomposition.vertexBands[f];
      std::vector<Point3> face;
      for (int v : s.mesh.faces[f]) face.push_back(s.mesh.positions[v]);
      // On the face's outer side, within 60 degrees of its mean plane's
      // normal; CGAL's double torus has a warped pentagon (face 82) whose
      // mean plane is 64 degrees from its band's.
      const double least = name == "double-torus-3-holes.off" ? 0.25 : 0.5;
      EXPECT_GT(vb.normal.dot(newellNormal(face)), least) << name << ": face " << f;
      EXPECT_GT(vb.normal.dot(newellNormal(vb.corners)), 0.999) << name << ": face " << f << " turns the wrong way";
      for (const Point3& p : vb.corners) EXPECT_LT(std::abs((p - vb.centroid).dot(vb.normal)), 1e-9) << name;
    }
  }
}

// Every unfolded length equals its length in space (V.4 is an isometry), so
// areas are kept too.
TEST(BandDecomposition, UnfoldingKeepsEveryLength) {
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    for (const FlatPanel& panel : s.panels) {
      const auto& corners = s.decomposition.vertexBands[panel.face].corners;
      const size_t n = corners.size();
      double area3 = 0;
      for (size_t i = 0; i < n; ++i) {
        EXPECT_LT(relative((panel.vertexBand[(i + 1) % n] - panel.vertexBand[i]).norm(),
                           (corners[(i + 1) % n] - corners[i]).norm()),
                  1e-9)
            << name;
        area3 += (corners[i] - s.decomposition.vertexBands[panel.face].centroid)
                     .cross(corners[(i + 1) % n] - s.decomposition.vertexBands[panel.face].centroid)
                     .norm() /
                 2;
      }
      for (const FlatBand& flat : panel.bands) {
        const EdgeBand& band = s.bands[flat.edge];
        for (const auto& t : band.triangles()) {
          for (int a = 0; a < 3; ++a) {
            const int p = t[a], q = t[(a + 1) % 3];
            ASSERT_LT(relative((flat.points[p] - flat.points[q]).norm(), (band.point(p) - band.point(q)).norm()), 1e-6)
                << name << ": face " << panel.face << ", band of edge " << flat.edge;
          }
          area3 += (band.point(t[1]) - band.point(t[0])).cross(band.point(t[2]) - band.point(t[0])).norm() / 2;
        }
      }
      EXPECT_LT(relative(signedArea(panel.outline), area3), 1e-6) << name << ": face " << panel.face;
    }
  }
}

// The two copies of a band, developed from opposite ends, are congruent and
// not mirrored: holes placed on one are where they are on the other.
TEST(BandDecomposition, BothCopiesOfABandAreCongruent) {
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    std::map<int, std::vector<const FlatBand*>> copies;
    for (const FlatPanel& panel : s.panels) {
      for (const FlatBand& band : panel.bands) copies[band.edge].push_back(&band);
    }
    for (const auto& [edge, pair] : copies) {
      ASSERT_EQ(pair.size(), 2u);
      EXPECT_NE(pair[0]->fromA, pair[1]->fromA);
      const auto& a = pair[0]->points;
      const auto& b = pair[1]->points;
      for (size_t i = 0; i < a.size(); ++i) {
        for (size_t j = i + 1; j < a.size(); ++j) {
          EXPECT_NEAR((a[i] - a[j]).norm(), (b[i] - b[j]).norm(), 1e-9 * (1 + (a[i] - a[j]).norm())) << name;
        }
        // Same turning: the signed area of any three points agrees.
        if (i + 2 < a.size()) {
          const auto turn = [&](const std::vector<Point2>& p) {
            return (p[i + 1] - p[i]).x() * (p[i + 2] - p[i]).y() - (p[i + 1] - p[i]).y() * (p[i + 2] - p[i]).x();
          };
          EXPECT_NEAR(turn(a), turn(b), 1e-9 * (1 + std::abs(turn(a)))) << name;
        }
      }
    }
  }
}

// The dissertation's students found edge bands flipped at saddle vertices
// (V.5). A band is flipped when, in space, it turns its inside out between
// the two vertex bands it joins: its first triangle must face the way its
// first vertex band does, its last the way the second does, each the way
// the one before it does, and none away from both (past the bisector of the
// two normals). Or when, laid flat, it folds back over its vertex band.
// Checked on every band that touches a saddle vertex (negative defect), and
// on every other.
TEST(BandDecomposition, NoBandIsFlippedAtSaddles) {
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    int saddleBands = 0;
    for (int e = 0; e < s.rs.edgeCount(); ++e) {
      const EdgeBand& band = s.bands[e];
      if (band.edge < 0) continue;
      const int u = s.rs.origin(2 * e), v = s.rs.target(2 * e);
      const bool atSaddle = (!s.rs.isBoundaryVertex(u) && vertexDefect(s.mesh, s.rs, u) < -1e-9) ||
                            (!s.rs.isBoundaryVertex(v) && vertexDefect(s.mesh, s.rs, v) < -1e-9);
      saddleBands += atSaddle;
      const Point3& nA = s.decomposition.vertexBands[band.faceA].normal;
      const Point3& nB = s.decomposition.vertexBands[band.faceB].normal;
      const auto where = [&, &name = name] {
        return fmt::format("{}: band of edge {}{} between faces {} and {}", name, e, atSaddle ? " at a saddle" : "",
                           band.faceA, band.faceB);
      };
      // The triangles run clockwise seen from outside: the outward normal is the reversed cross product.
      std::vector<Point3> normals;
      for (const auto& t : band.triangles()) {
        normals.push_back(
            (band.point(t[2]) - band.point(t[0])).cross(band.point(t[1]) - band.point(t[0])).normalized());
      }
      ASSERT_GT(normals.front().dot(nA), 0) << where() << " leaves face A inside out";
      ASSERT_GT(normals.back().dot(nB), 0) << where() << " reaches face B inside out";
      for (size_t i = 0; i < normals.size(); ++i) {
        if (i > 0) {
          ASSERT_GT(normals[i].dot(normals[i - 1]), 0) << where() << " turns over at triangle " << i;
        }
        ASSERT_GT(normals[i].dot(nA + nB), 0) << where() << " faces away from both vertex bands";
      }
    }
    if (name == "torus" || name == "genus 2" || name == "monkey saddle" || name == "bunny") {
      EXPECT_GT(saddleBands, 0) << name << " has no saddle: the test would prove nothing";
    }
    for (const FlatPanel& panel : s.panels) {
      for (const auto& [i, j] : overlappingPieces(panel)) {
        if (i == j && i >= 0) {
          ADD_FAILURE() << name << ": face " << panel.face << ": the band of edge " << panel.bands[i].edge
                        << " folds over";
        } else if (i == j) {
          ADD_FAILURE() << name << ": face " << panel.face << ": its vertex band crosses itself";
        }
      }
    }
  }
}

// V.3's cases: a flat disc has parallel planes everywhere (case 1); a cube's
// faces meet along lines parallel to the bands' sides (case 2); the bunny
// has all three. Hermite rails start and end on the vertex bands' planes,
// leaving them along the planes.
TEST(BandDecomposition, HermiteBandsAreTangentToBothVertexBands) {
  int hermite = 0;
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    std::map<BandCase, int> kinds;
    for (const EdgeBand& band : s.bands) kinds[band.kind] += band.edge >= 0;
    if (name == "disc") {
      EXPECT_EQ(kinds[BandCase::ParallelPlanes], 9) << name;  // its 9 spokes, all in one plane
    }
    if (name == "cube") {
      EXPECT_EQ(kinds[BandCase::AlongIntersection], 12) << name;
    }
    if (name == "bunny") {
      EXPECT_GT(kinds[BandCase::ParallelPlanes], 0);
      EXPECT_GT(kinds[BandCase::AlongIntersection], 0);
      EXPECT_GT(kinds[BandCase::Bilinear], 0);
    }
    for (const EdgeBand& band : s.bands) {
      if (band.edge < 0 || band.kind == BandCase::Bilinear) continue;
      ++hermite;
      const VertexBand& a = s.decomposition.vertexBands[band.faceA];
      const VertexBand& b = s.decomposition.vertexBands[band.faceB];
      for (const auto* rail : {&band.railU, &band.railV}) {
        const int k = static_cast<int>(rail->size()) - 1;
        const Point3 leave = ((*rail)[1] - (*rail)[0]).normalized();
        const Point3 enter = ((*rail)[k] - (*rail)[k - 1]).normalized();
        // A chord of the curve: within the angle a segment of 1/k of it turns.
        EXPECT_LT(std::abs(leave.dot(a.normal)), 0.35) << name;
        EXPECT_LT(std::abs(enter.dot(b.normal)), 0.35) << name;
      }
    }
  }
  EXPECT_GT(hermite, 0) << "no mesh has a Hermite band: the test would prove nothing";
}

TEST(BandDecomposition, PanelsOfTheTestMeshesDoNotOverlapThemselves) {
  for (auto& [name, mesh] : testMeshes()) {
    const UnfoldedBands s = build(mesh);
    for (const FlatPanel& panel : s.panels) {
      EXPECT_TRUE(overlappingPieces(panel).empty()) << name << ": face " << panel.face;
    }
  }
}

// The overlap check is not blind: a band laid across the vertex band, and a
// vertex band that crosses itself, are both found.
TEST(BandDecomposition, OverlapsAreFound) {
  UnfoldedBands s = build(cube());
  FlatPanel panel = s.panels.front();
  ASSERT_TRUE(overlappingPieces(panel).empty());
  FlatPanel crossed = panel;
  // Band 0 moved so that its far end lies on the middle of the vertex band.
  Point2 middle = Point2::Zero();
  for (const Point2& p : panel.vertexBand) middle += p / static_cast<double>(panel.vertexBand.size());
  const auto& o = crossed.bands[0].outline;
  const Point2 shift = middle - (o[o.size() / 2] + o[o.size() / 2 - 1]) / 2;
  for (Point2& p : crossed.bands[0].outline) p += shift;
  EXPECT_FALSE(overlappingPieces(crossed).empty());
  FlatPanel twisted = panel;
  std::swap(twisted.vertexBand[0], twisted.vertexBand[1]);
  const auto found = overlappingPieces(twisted);
  EXPECT_NE(std::find(found.begin(), found.end(), std::pair{-1, -1}), found.end());
}

// An interior vertex of valence 2 (a cube with one edge split in two: its two
// faces share two sides in a row) has a dual polygon of two corners.
TEST(BandDecomposition, ValenceTwoVerticesAreBuilt) {
  PolygonMesh mesh = cube();
  const int a = mesh.faces[0][0], b = mesh.faces[0][1];
  const int middle = mesh.vertexCount();
  mesh.positions.push_back((mesh.positions[a] + mesh.positions[b]) / 2);
  for (auto& face : mesh.faces) {
    for (size_t i = 0; i < face.size(); ++i) {
      const int p = face[i], q = face[(i + 1) % face.size()];
      if ((p == a && q == b) || (p == b && q == a)) {
        face.insert(face.begin() + static_cast<long>(i) + 1, middle);
        break;
      }
    }
  }
  const UnfoldedBands s = build(mesh);
  EXPECT_EQ(s.panels.size(), 6u);
  for (const FlatPanel& panel : s.panels) {
    EXPECT_TRUE(overlappingPieces(panel).empty()) << "face " << panel.face;
    for (const Point2& p : panel.outline) EXPECT_TRUE(p.allFinite());
  }
}

}  // namespace
}  // namespace rotafab::geometry
