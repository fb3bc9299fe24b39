// Ribbons that pass through each other (dissertation ch. VII): at the
// widest ribbons the torus's do, and the width the detector gives clears
// them all; at the default width, narrowed edge by edge where they would
// meet, no example's do (checked by a test of every triangle against every
// other, apart from the detector's grid), and the weave stays dense.
#include "geometry/RibbonCollisions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"

namespace rotafab::geometry {
namespace {

struct Woven {
  RotationSystem rs;
  WeaveThreads threads;
  std::vector<EdgeRegion> regions;
};

Woven wovenAtConstructionSize(PolygonMesh mesh) {
  mesh = test::atConstructionSize(std::move(mesh));
  requireUsable(analyzeMesh(mesh));
  RotationSystem rs = RotationSystem::fromMesh(mesh);
  twistForWeave(rs, WeaveCycles::All);
  WeaveThreads threads = traceThreads(rs);
  std::vector<EdgeRegion> regions = edgeRegions(mesh, rs);
  return {std::move(rs), std::move(threads), std::move(regions)};
}

RibbonCollisions collisionsAt(const Woven& w, const RibbonShape& shape) {
  return ribbonCollisions(w.rs, w.threads, w.regions, weaveRibbons(w.rs, w.threads, w.regions, shape), shape,
                          test::context());
}

TEST(RibbonCollisions, TheWidestRibbonsOfTheTorusMeetTheirNeighboursAndTheWidthGivenClearsThem) {
  const Woven w = wovenAtConstructionSize(importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/torus.obj").mesh);
  RibbonShape shape;
  shape.width = 1;
  shape.offset = 0.0125;
  const RibbonCollisions widest = collisionsAt(w, shape);
  ASSERT_FALSE(widest.pairs.empty());
  for (const RibbonCollision& pair : widest.pairs) {
    EXPECT_GT(pair.clearWidth, 0);
    EXPECT_LT(pair.clearWidth, 1);
  }
  ASSERT_GT(widest.clearWidth, 0.5);
  ASSERT_LT(widest.clearWidth, 1);
  shape.width = widest.clearWidth;
  EXPECT_TRUE(collisionsAt(w, shape).pairs.empty());
}

// Whether segment pq crosses triangle abc, by signed volumes (not the
// detector's ray-triangle test): p and q on either side of its plane, and
// pq on the same side of each of its three edges.
double volume(const Point3& a, const Point3& b, const Point3& c, const Point3& d) {
  return (b - a).cross(c - a).dot(d - a);
}
bool crosses(const Point3& p, const Point3& q, const Point3& a, const Point3& b, const Point3& c) {
  const double scale = (b - a).cross(c - a).norm() * (q - p).norm();
  const double vp = volume(a, b, c, p), vq = volume(a, b, c, q);
  if (!(vp * vq < 0) || std::abs(vp) < 1e-9 * scale || std::abs(vq) < 1e-9 * scale) return false;
  const double s1 = volume(p, q, a, b), s2 = volume(p, q, b, c), s3 = volume(p, q, c, a);
  return (s1 > 0 && s2 > 0 && s3 > 0) || (s1 < 0 && s2 < 0 && s3 < 0);
}

// Every strip triangle against every other but its strip's own within a
// row: the number of pairs that pass through each other.
int stripsThroughEachOther(const std::vector<Ribbon>& ribbons) {
  struct Triangle {
    size_t ribbon, row;
    std::array<Point3, 3> corner;
    Point3 low, high;
  };
  std::vector<Triangle> triangles;
  for (size_t r = 0; r < ribbons.size(); ++r) {
    const Ribbon& ribbon = ribbons[r];
    const size_t n = ribbon.railP.size();
    for (size_t i = 0; i < n; ++i) {
      const size_t j = (i + 1) % n;
      for (const auto& corner : {std::array<Point3, 3>{ribbon.railP[i], ribbon.railQ[i], ribbon.railP[j]},
                                 std::array<Point3, 3>{ribbon.railQ[i], ribbon.railQ[j], ribbon.railP[j]}}) {
        triangles.push_back({r, i, corner, corner[0].cwiseMin(corner[1]).cwiseMin(corner[2]),
                             corner[0].cwiseMax(corner[1]).cwiseMax(corner[2])});
      }
    }
  }
  int through = 0;
  for (size_t x = 0; x < triangles.size(); ++x) {
    for (size_t y = x + 1; y < triangles.size(); ++y) {
      const Triangle &a = triangles[x], &b = triangles[y];
      if ((a.high.array() < b.low.array()).any() || (b.high.array() < a.low.array()).any()) continue;
      if (a.ribbon == b.ribbon) {
        const size_t n = ribbons[a.ribbon].railP.size(), apart = a.row > b.row ? a.row - b.row : b.row - a.row;
        if (std::min(apart, n - apart) <= 1) continue;
      }
      bool meet = false;
      for (int i = 0; i < 3 && !meet; ++i) {
        const int k = (i + 1) % 3;
        meet = crosses(a.corner[i], a.corner[k], b.corner[0], b.corner[1], b.corner[2]) ||
               crosses(b.corner[i], b.corner[k], a.corner[0], a.corner[1], a.corner[2]);
      }
      through += meet ? 1 : 0;
    }
  }
  return through;
}

TEST(RibbonCollisions, AtTheDefaultWidthTheRibbonsAreNarrowedWhereTheyWouldMeetAndNoneDo) {
  std::vector<std::pair<const char*, PolygonMesh>> meshes{
      {"cube", cube()}, {"soccer ball", truncatedIcosahedron()}, {"genus-2", genusTwoSlab()}};
  for (const char* name : {"torus.obj", "genus2.obj"}) {
    meshes.emplace_back(name, importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/" + name).mesh);
  }
  for (auto& [name, mesh] : meshes) {
    SCOPED_TRACE(name);
    RibbonShape shape;
    shape.offset = 0.0125;
    const Woven w = wovenAtConstructionSize(std::move(mesh));
    // At the default width the soccer ball's and the torus's meet, where
    // the regions turn sharply about a corner they share (their degree-3
    // vertices and the torus's saddles).
    const int atDefault = stripsThroughEachOther(weaveRibbons(w.rs, w.threads, w.regions, shape));
    const ClearedRibbons cleared = narrowUntilClear(w.rs, w.threads, w.regions, shape, test::context());
    EXPECT_TRUE(cleared.left.pairs.empty());
    EXPECT_EQ(stripsThroughEachOther(cleared.ribbons), 0);
    EXPECT_EQ(cleared.narrowed > 0, atDefault > 0) << atDefault << " at the default width";
    // Dense still (fig. 15): no edge below 0.6 here.
    for (const double width : cleared.edgeWidths) EXPECT_GE(width, 0.6);
    const std::vector<Ribbon> again = weaveRibbons(w.rs, w.threads, w.regions, shape, cleared.edgeWidths);
    EXPECT_EQ(again[0].railP, cleared.ribbons[0].railP);
  }
  const Woven soccer = wovenAtConstructionSize(truncatedIcosahedron());
  RibbonShape shape;
  shape.offset = 0.0125;
  EXPECT_GT(stripsThroughEachOther(weaveRibbons(soccer.rs, soccer.threads, soccer.regions, shape)), 0);
}

TEST(RibbonCollisions, TheBunnysRibbonsAreNarrowedOnlyAsFarAsTheyMustBe) {
  RibbonShape shape;
  shape.offset = 0.0125;
  const Woven w = wovenAtConstructionSize(importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj").mesh);
  const ClearedRibbons cleared = narrowUntilClear(w.rs, w.threads, w.regions, shape, test::context());
  EXPECT_TRUE(cleared.left.pairs.empty());
  std::vector<double> widths = cleared.edgeWidths;
  std::sort(widths.begin(), widths.end());
  EXPECT_GE(widths[widths.size() / 2], 0.55);  // the median: a dense weave still
}

}  // namespace
}  // namespace rotafab::geometry
