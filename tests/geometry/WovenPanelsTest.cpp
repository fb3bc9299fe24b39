// Woven panels (dissertation IV.3-IV.4; docs/WEAVE.md, 1.9-1.10, A9):
// one panel per twisted edge, up at it; each edge is down on two panels,
// consecutive on a thread, which overlap over its middle row; the
// unfolding keeps every triangle's sides (so lengths and area), puts the
// outside up, and leaves no outline crossing itself.
#include "geometry/WovenPanels.h"

#include <gtest/gtest.h>

#include <map>

#include "core/Polygon2.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"

namespace rotafab::geometry {
namespace {

struct PanelledMesh {
  int edges = 0;
  std::vector<EdgeRegion> regions;
  std::vector<Ribbon> ribbons;
  std::vector<WovenPanel> panels;
};

constexpr RibbonShape kShape{.width = 0.8, .curve = 0.6, .offset = 0.02, .samples = 8};

PanelledMesh panelled(PolygonMesh mesh, WeaveCycles cycles = WeaveCycles::All, int overlap = 4) {
  requireUsable(analyzeMesh(mesh));
  RotationSystem rs = RotationSystem::fromMesh(mesh);
  twistForWeave(rs, cycles);
  PanelledMesh result;
  result.edges = rs.edgeCount();
  result.regions = edgeRegions(mesh, rs);
  result.ribbons = weaveRibbons(rs, traceThreads(rs), result.regions, kShape);
  result.panels = wovenPanels(result.ribbons, result.regions, overlap);
  return result;
}

std::vector<std::pair<const char*, PolygonMesh>> panelMeshes() {
  std::vector<std::pair<const char*, PolygonMesh>> meshes{
      {"tetrahedron", tetrahedron()},          {"cube", cube()},       {"dodecahedron", dodecahedron()},
      {"soccer ball", truncatedIcosahedron()}, {"torus", torus(9, 6)}, {"genus-2", genusTwoSlab()}};
  meshes.emplace_back("bunny", importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj").mesh);
  return meshes;
}

TEST(WovenPanels, OnePanelUpAtEachEdgeAndEachEdgeDownOnTwoPanelsThatOverlapThere) {
  for (auto& [name, mesh] : panelMeshes()) {
    SCOPED_TRACE(name);
    const PanelledMesh p = panelled(mesh);
    ASSERT_EQ(p.panels.size(), static_cast<size_t>(p.edges));
    std::vector<int> up(static_cast<size_t>(p.edges), 0), down(static_cast<size_t>(p.edges), 0);
    for (const WovenPanel& panel : p.panels) {
      ++up[static_cast<size_t>(panel.upEdge)];
      for (int e : panel.downEdges) ++down[static_cast<size_t>(e)];
    }
    EXPECT_EQ(std::count(up.begin(), up.end(), 1), p.edges);
    EXPECT_EQ(std::count(down.begin(), down.end(), 2), p.edges);
    // Consecutive panels of a thread: the end of one is the start of the next, over 2 x 4 + 1 rows.
    for (size_t i = 0; i < p.panels.size(); ++i) {
      const WovenPanel& a = p.panels[i];
      const WovenPanel& b = p.panels[(i + 1) % p.panels.size()];
      if (a.thread != b.thread) continue;
      ASSERT_EQ(a.downEdges[1], b.downEdges[0]);
      for (int k = 0; k <= 8; ++k) {
        const int inA = a.rows() - 9 + k;
        EXPECT_TRUE(a.railP[static_cast<size_t>(inA)].isApprox(b.railP[static_cast<size_t>(k)]));
        EXPECT_TRUE(a.railQ[static_cast<size_t>(inA)].isApprox(b.railQ[static_cast<size_t>(k)]));
      }
      EXPECT_EQ(a.downRows[1], a.rows() - 5);
      EXPECT_EQ(b.downRows[0], 4);
    }
  }
}

TEST(WovenPanels, UnfoldingKeepsEveryTrianglesSidesPutsTheOutsideUpAndNoOutlineCrossesItself) {
  for (auto& [name, mesh] : panelMeshes()) {
    SCOPED_TRACE(name);
    for (const WeaveCycles cycles : {WeaveCycles::All, WeaveCycles::Single}) {
      const PanelledMesh p = panelled(mesh, cycles);
      int crossing = 0;
      for (const WovenPanel& panel : p.panels) {
        const int rows = panel.rows();
        double flatArea = 0;
        for (int i = 0; i + 1 < rows; ++i) {
          for (const std::array<int, 3>& t :
               {std::array<int, 3>{i, rows + i, i + 1}, std::array<int, 3>{rows + i, rows + i + 1, i + 1}}) {
            for (int s = 0; s < 3; ++s) {
              const int a = t[static_cast<size_t>(s)], b = t[static_cast<size_t>((s + 1) % 3)];
              const double inSpace = (panel.corner(a) - panel.corner(b)).norm();
              EXPECT_NEAR((panel.flatCorner(a) - panel.flatCorner(b)).norm(), inSpace, 1e-9 * (1 + inSpace));
            }
            flatArea += std::abs(core::cross(panel.flatCorner(t[1]) - panel.flatCorner(t[0]),
                                             panel.flatCorner(t[2]) - panel.flatCorner(t[0]))) /
                        2;
          }
        }
        EXPECT_NEAR(flatArea, panel.area, 1e-9 * panel.area);
        // The outside up: the first triangle past the up row turns the same way flat as about N_e in space.
        const int u = panel.upRow;
        const Point3& n = p.regions[static_cast<size_t>(panel.upEdge)].normal;
        const double inSpace =
            (panel.corner(rows + u) - panel.corner(u)).cross(panel.corner(u + 1) - panel.corner(u)).dot(n);
        const double flat = core::cross(panel.flatCorner(rows + u) - panel.flatCorner(u),
                                        panel.flatCorner(u + 1) - panel.flatCorner(u));
        EXPECT_GT(inSpace * flat, 0);
        const auto outline = panel.outline();
        EXPECT_GT(core::signedArea(outline), 0);
        if (core::crossesItself(outline)) ++crossing;
      }
      // A single thread's panels run round the faces at the leaves of the
      // dual tree and can cross themselves: the structure cuts those
      // (docs/WEAVE.md, section 4). Every thread of a full weave has short
      // panels that do not.
      if (cycles == WeaveCycles::All) {
        EXPECT_EQ(crossing, 0);
      }
    }
  }
}

TEST(WovenPanels, TheLineAlongTheNormalThroughACrossingMeetsItsThreePanels) {
  const PanelledMesh p = panelled(truncatedIcosahedron());
  std::map<int, std::vector<const WovenPanel*>> atEdge;
  for (const WovenPanel& panel : p.panels) {
    atEdge[panel.upEdge].push_back(&panel);
    for (int e : panel.downEdges) atEdge[e].push_back(&panel);
  }
  for (const auto& [edge, panels] : atEdge) {
    ASSERT_EQ(panels.size(), 3U);
    const EdgeRegion& r = p.regions[static_cast<size_t>(edge)];
    const Point3 centre = r.at(0.5, 0.5);
    std::vector<double> heights;
    for (const WovenPanel* panel : panels) {
      const int row = panel->upEdge == edge         ? panel->upRow
                      : panel->downEdges[0] == edge ? panel->downRows[0]
                                                    : panel->downRows[1];
      const StripPoint hit = stripPointOnLine(*panel, row - 4, row + 4, centre, r.normal);
      EXPECT_EQ(hit.miss, 0);
      heights.push_back((hit.inSpace(*panel) - centre).dot(r.normal));
    }
    // The over panel 2h above the two under ones.
    std::sort(heights.begin(), heights.end());
    EXPECT_NEAR(heights[0], -kShape.offset, 1e-9);
    EXPECT_NEAR(heights[1], -kShape.offset, 1e-9);
    EXPECT_NEAR(heights[2], kShape.offset, 1e-9);
  }
}

}  // namespace
}  // namespace rotafab::geometry
