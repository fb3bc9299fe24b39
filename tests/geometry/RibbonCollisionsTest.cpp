// Ribbons that push against their neighbours (dissertation ch. VII): at the
// widest ribbons the torus's neighbouring ribbons pass through each other,
// and the width the detector gives clears them all; at the default width
// no example's do.
#include "geometry/RibbonCollisions.h"

#include <gtest/gtest.h>

#include "geometry/MeshAnalysis.h"
#include "geometry/MeshImport.h"
#include "geometry/Primitives.h"
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
    EXPECT_NE(pair.edgeA, pair.edgeB);  // neighbours, not a crossing's own two ribbons
    EXPECT_LT(pair.edgeA, pair.edgeB);
  }
  ASSERT_GT(widest.clearWidth, 0.5);
  ASSERT_LT(widest.clearWidth, 1);
  shape.width = widest.clearWidth;
  EXPECT_TRUE(collisionsAt(w, shape).pairs.empty());
}

TEST(RibbonCollisions, AtTheDefaultWidthNoExamplesRibbonsMeet) {
  std::vector<std::pair<const char*, PolygonMesh>> meshes{
      {"cube", cube()}, {"soccer ball", truncatedIcosahedron()}, {"genus-2", genusTwoSlab()}};
  for (const char* name : {"torus.obj", "genus2.obj", "bunny.obj"}) {
    meshes.emplace_back(name, importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/" + name).mesh);
  }
  for (auto& [name, mesh] : meshes) {
    SCOPED_TRACE(name);
    RibbonShape shape;
    shape.offset = 0.0125;
    EXPECT_TRUE(collisionsAt(wovenAtConstructionSize(std::move(mesh)), shape).pairs.empty());
  }
}

}  // namespace
}  // namespace rotafab::geometry
