// Band structures end to end in geometry (dissertation V.5): fastener holes,
// labels and flood-fill numbering on the panels of buildBandStructure().

#include "geometry/BandStructure.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <regex>
#include <set>

#include "geometry/BandDecomposition.h"
#include "geometry/DevelopableBands.h"
#include "geometry/FastenerHoles.h"
#include "geometry/FloodFill.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshRepair.h"
#include "geometry/PanelUnfolding.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/CrumpledMesh.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

using test::atConstructionSize;

PolygonMesh imported(const std::filesystem::path& path) {
  return test::atBuildableSize(importMesh(path.string()).mesh);
}

// Two cubes that share an edge (non-manifold), as --repair auto leaves them:
// two closed cubes, each with its own copy of the edge.
PolygonMesh cubesSharingAnEdgeRepaired() {
  PolygonMesh mesh = cube();
  test::append(mesh, cube(), Point3(2, 2, 0));
  cleanMesh(mesh);
  EXPECT_EQ(repairMesh(mesh).size(), 1u);
  return test::atBuildableSize(mesh);
}

// Meshes made here, the bunny, and two that other programs wrote: Geomview's
// tube of quads (open, two boundary loops) and CGAL's double torus with three
// holes (genus 2, open, triangles); and a mesh repaired by --repair auto.
// Each is made only when asked for.
std::map<std::string, std::function<PolygonMesh()>> meshMakers() {
  std::map<std::string, std::function<PolygonMesh()>> makers = {
      {"soccer ball", [] { return test::atBuildableSize(truncatedIcosahedron()); }},
      {"torus", [] { return test::atBuildableSize(torus(10, 6)); }},
      {"genus 2", [] { return test::atBuildableSize(genusTwoSlab()); }},
      {"disc", [] { return test::atBuildableSize(disc(7)); }},
      {"tref.off", [] { return imported(test::publicMesh("/usr/share/geomview/geom/tref.off")); }},
      {"double-torus-3-holes.off",
       [] { return imported(test::publicMesh(test::cgalMesh("double-torus-3-holes.off"))); }},
      {"cubes sharing an edge, repaired", cubesSharingAnEdgeRepaired}};
#ifndef ROTAFAB_SANITIZED
  // Its 3,674 panels take a minute a test under the sanitizers, which the
  // smaller meshes above run through the same code.
  makers["bunny"] = [] { return imported(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj"); };
#endif
  return makers;
}

PolygonMesh namedMesh(const std::string& name) { return meshMakers().at(name)(); }

std::map<std::string, PolygonMesh> meshes() {
  std::map<std::string, PolygonMesh> made;
  for (const auto& [name, make] : meshMakers()) made.emplace(name, make());
  return made;
}

// Both copies of every band carry its holes: the same number, the same
// distances apart, and at the same points in space.
TEST(BandStructure, HolesOfBothCopiesCoincideInSpace) {
  for (auto& [name, mesh] : meshes()) {
    const RotationSystem rs = RotationSystem::fromMesh(mesh);
    const BandDecomposition decomposition = bandDecomposition(mesh, rs);
    const auto bands = developableBands(rs, decomposition);
    std::vector<FlatPanel> panels;
    for (int f = 0; f < mesh.faceCount(); ++f) panels.push_back(unfoldPanel(rs, decomposition, bands, f));
    const auto holes = placeFastenerHoles(bands, panels, 0.125, test::context());
    for (const EdgeBand& band : bands) {
      if (band.edge < 0) continue;
      const BandHoles& h = holes[band.edge];
      ASSERT_FALSE(h.holes.empty()) << name << ": edge " << band.edge;
      const FlatBand* a = bandCopy(panels[band.faceA], band.edge);
      const FlatBand* b = bandCopy(panels[band.faceB], band.edge);
      ASSERT_TRUE(a && b);
      for (size_t i = 0; i < h.holes.size(); ++i) {
        // In space the hole is one point of the band; on each panel it lies
        // where that point unfolds to: as far from its triangle's corners as in space.
        const Point2 onA = h.holes[i].onPanel(*a), onB = h.holes[i].onPanel(*b);
        const Point3 point = h.holes[i].inSpace(band);
        for (int corner : h.holes[i].corners) {
          const double inSpace = (band.point(corner) - point).norm();
          EXPECT_NEAR((a->points[corner] - onA).norm(), inSpace, 1e-9) << name << ": edge " << band.edge;
          EXPECT_NEAR((b->points[corner] - onB).norm(), inSpace, 1e-9) << name << ": edge " << band.edge;
        }
        for (size_t j = 0; j < i; ++j) {
          const double onPanelA = (h.holes[j].onPanel(*a) - onA).norm();
          const double onPanelB = (h.holes[j].onPanel(*b) - onB).norm();
          EXPECT_NEAR(onPanelA, onPanelB, 1e-9) << name << ": edge " << band.edge;
        }
        // Each hole's distances to the band's four corner points are the same on both copies.
        const int k = band.segments();
        for (int corner : {0, k, k + 1, 2 * k + 1}) {
          EXPECT_NEAR((a->points[corner] - onA).norm(), (b->points[corner] - onB).norm(), 1e-9) << name;
        }
      }
    }
  }
}

TEST(BandStructure, HolesKeepTheirClearanceAndTheBandsTheirFasteners) {
  for (auto& [name, mesh] : meshes()) {
    BandOptions options;
    const Structure s = buildBandStructure(mesh, options, test::context());
    ASSERT_EQ(s.panels.size(), static_cast<size_t>(mesh.faceCount())) << name;
    std::map<int, std::vector<std::pair<int, std::vector<Point2>>>> holesOfEdge;  // edge -> (panel, holes)
    int holes = 0;
    for (const Panel& panel : s.panels) {
      std::map<int, std::vector<Point2>> mine;
      for (const PanelHole& hole : panel.holes) {
        mine[hole.edge].push_back(hole.xy);
        ++holes;
        EXPECT_TRUE(insidePolygon(panel.outline, hole.xy)) << name << ": panel " << panel.id;
        EXPECT_GE(distanceToOutline(panel.outline, hole.xy), kLeastClearance * options.fastener - 1e-9)
            << name << ": panel " << panel.id << ", edge " << hole.edge;
      }
      for (auto& [edge, points] : mine) holesOfEdge[edge].emplace_back(panel.id, points);
    }
    EXPECT_EQ(holes, 2 * s.fasteners) << name;
    EXPECT_EQ(static_cast<int>(holesOfEdge.size()), s.edges) << name;
    for (const auto& [edge, copies] : holesOfEdge) {
      ASSERT_EQ(copies.size(), 2u) << name << ": edge " << edge;
      ASSERT_EQ(copies[0].second.size(), copies[1].second.size()) << name << ": edge " << edge;
      if (copies[0].second.size() == 2) {
        EXPECT_NEAR((copies[0].second[0] - copies[0].second[1]).norm(),
                    (copies[1].second[0] - copies[1].second[1]).norm(), 1e-9)
            << name << ": edge " << edge;
      }
    }
  }
}

// Wide enough bands (the soccer ball's and the torus's at 2 in edges) all get
// two holes, 1.5 diameters clear: fasteners = 2 x interior edges.
TEST(BandStructure, WideBandsGetTwoHolesWithTheFullClearance) {
  for (const char* name : {"soccer ball", "torus"}) {
    const PolygonMesh mesh = namedMesh(name);
    BandOptions options;
    const Structure s = buildBandStructure(mesh, options, test::context());
    EXPECT_EQ(s.fasteners, 2 * s.edges) << name;
    for (const Panel& panel : s.panels) {
      for (const PanelHole& hole : panel.holes) {
        EXPECT_GE(distanceToOutline(panel.outline, hole.xy), kClearance * options.fastener - 1e-9) << name;
        for (const PanelHole& other : panel.holes) {
          if (&other != &hole) {
            EXPECT_GE((other.xy - hole.xy).norm(), (kClearance + 1) * options.fastener - 1e-9) << name;
          }
        }
      }
    }
    EXPECT_TRUE(s.warnings.empty()) << name << ": " << s.warnings.front();
  }
}

// A cube at 2 in edges has bands 1/3 in wide: one hole each, reported.
TEST(BandStructure, NarrowBandsGetOneHoleAndAWarning) {
  BandOptions options;
  const Structure s = buildBandStructure(atConstructionSize(cube()), options, test::context());
  EXPECT_EQ(s.fasteners, s.edges);
  ASSERT_FALSE(s.warnings.empty());
  EXPECT_NE(s.warnings.front().find("12 bands are too narrow"), std::string::npos) << s.warnings.front();
  options.fastener = 0.5;  // no room even for one
  EXPECT_THROW(buildBandStructure(atConstructionSize(cube()), options, test::context()), std::invalid_argument);
}

TEST(BandStructure, LabelsStayInsideTheirPanelsClearOfHolesAndEachOther) {
  for (auto& [name, mesh] : meshes()) {
    BandOptions options;
    const Structure s = buildBandStructure(mesh, options, test::context());
    int missing = 0;
    for (const Panel& panel : s.panels) {
      std::set<int> edgeLabels;
      for (const PanelLabel& label : panel.labels) {
        for (const Point2& corner : label.box.corners()) {
          EXPECT_TRUE(insidePolygon(panel.outline, corner)) << name << ": panel " << panel.id << " " << label.text;
        }
        for (const auto& stroke : label.strokes) {
          for (const Point2& p : stroke) EXPECT_TRUE(insidePolygon(panel.outline, p)) << name;
        }
        for (const PanelHole& hole : panel.holes) {
          EXPECT_GE(label.box.distanceTo(hole.xy), hole.diameter / 2) << name << ": panel " << panel.id;
        }
        if (label.role == LabelRole::Edge) edgeLabels.insert(label.edge);
        if (label.role == LabelRole::Panel) {
          EXPECT_EQ(label.text, labelText(std::to_string(panel.id)));
        }
      }
      missing += static_cast<int>(panel.joins.size() - edgeLabels.size());
    }
    // A band too small for its number even at the smallest size goes without,
    // and the warning counts every one of them.
    int reported = 0;
    std::smatch count;
    for (const std::string& warning : s.warnings) {
      if (std::regex_search(warning, count, std::regex(R"(^(\d+) labels? (is|are) not etched)")))
        reported = std::stoi(count[1]);
    }
    EXPECT_EQ(missing, reported) << name;
    if (name == "soccer ball" || name == "torus" || name == "genus 2") {
      EXPECT_EQ(missing, 0) << name;
    }
  }
  const Structure ball = buildBandStructure(namedMesh("soccer ball"), BandOptions{}, test::context());
  EXPECT_EQ(ball.panels[5].labels.back().text, "6.");  // panel 6 is marked against reading as 9
}

// Flood fill: panel 1 is the lowest face; each later panel joins one
// numbered before it, but the first of another piece of the mesh, which is
// the lowest face not yet reached; numbers are a breadth-first order.
TEST(BandStructure, PanelsAreNumberedBreadthFirstFromTheLowestFace) {
  for (auto& [name, mesh] : meshes()) {
    BandOptions options;
    const Structure s = buildBandStructure(mesh, options, test::context());
    EXPECT_EQ(s.panels.front().source.face, mesh.sourceFaceIndex(lowestFace(mesh, 1))) << name;
    int previousParent = 0, pieces = 1;
    for (const Panel& panel : s.panels) {
      if (panel.id == 1) continue;
      const auto earliest = std::min_element(panel.joins.begin(), panel.joins.end(),
                                             [](const PanelJoin& a, const PanelJoin& b) { return a.panel < b.panel; });
      if (earliest == panel.joins.end() || earliest->panel > panel.id) {
        // A piece of its own: it starts from its lowest face.
        std::map<int, int> faceOfSource;
        for (int f = 0; f < mesh.faceCount(); ++f) faceOfSource[mesh.sourceFaceIndex(f)] = f;
        const double height = faceCentroid(mesh, faceOfSource.at(panel.source.face)).y();
        for (const Panel& later : s.panels) {
          if (later.id <= panel.id) continue;
          EXPECT_LE(height, faceCentroid(mesh, faceOfSource.at(later.source.face)).y())
              << name << ": panel " << panel.id << " starts a piece but is not its lowest face";
        }
        previousParent = panel.id;
        ++pieces;
        continue;
      }
      const int parent = earliest->panel;
      EXPECT_LT(parent, panel.id) << name << ": panel " << panel.id << " joins no panel placed before it";
      EXPECT_GE(parent, previousParent) << name << ": not breadth-first at panel " << panel.id;
      previousParent = parent;
    }
    EXPECT_EQ(pieces, test::topologyOf(mesh).components) << name << ": a piece starts only where one begins";
    options.start = s.panels[3].source.face;
    EXPECT_EQ(buildBandStructure(mesh, options, test::context()).panels.front().source.face, options.start) << name;
  }
  BandOptions bad;
  bad.start = 100000;
  EXPECT_THROW(buildBandStructure(namedMesh("torus"), bad, test::context()), std::invalid_argument);
}

TEST(BandStructure, UnfoldingKeepsTheArea) {
  for (auto& [name, mesh] : meshes()) {
    const Structure s = buildBandStructure(mesh, BandOptions{}, test::context());
    for (const Panel& panel : s.panels) {
      double flat = 0;
      for (size_t i = 0; i < panel.outline.size(); ++i) {
        const Point2& a = panel.outline[i];
        const Point2& b = panel.outline[(i + 1) % panel.outline.size()];
        flat += (a.x() * b.y() - b.x() * a.y()) / 2;
      }
      EXPECT_NEAR(flat, panel.area, 1e-6 * panel.area) << name << ": panel " << panel.id;
    }
  }
}

// V.4: a panel that would overlap itself is split at a band: the band is cut
// off with a tab over the vertex band, fastened back through one extra hole.
TEST(BandStructure, APanelThatWouldOverlapItselfIsSplitAtABand) {
  const PolygonMesh mesh = test::crumpledTorus();
  BandOptions options;
  const Structure s = buildBandStructure(mesh, options, test::context());
  int pieces = 0, holes = 0;
  for (const Panel& panel : s.panels) {
    holes += static_cast<int>(panel.holes.size());
    for (const PanelPiece& piece : panel.pieces) {
      ++pieces;
      holes += static_cast<int>(piece.holes.size());
      EXPECT_EQ(piece.name, std::to_string(panel.id) + "a");
      double twice = 0;
      for (size_t i = 0; i < piece.outline.size(); ++i) {
        const Point2& a = piece.outline[i];
        const Point2& b = piece.outline[(i + 1) % piece.outline.size()];
        twice += a.x() * b.y() - b.x() * a.y();
      }
      EXPECT_GT(twice, 0) << "piece " << piece.name << " runs clockwise";
      EXPECT_FALSE(crossesItself(piece.outline)) << "piece " << piece.name;
      EXPECT_FALSE(crossesItself(panel.outline)) << "panel " << panel.id;
      // The tab's hole is on both the piece and the panel, clear of both outlines.
      const PanelHole& tab = piece.holes.back();
      EXPECT_EQ(tab.edge, 0);
      EXPECT_TRUE(std::any_of(panel.holes.begin(), panel.holes.end(),
                              [&](const PanelHole& h) { return h.edge == 0 && (h.xy - tab.xy).norm() < 1e-12; }));
      EXPECT_GE(distanceToOutline(piece.outline, tab.xy), kClearance * options.fastener - 1e-9);
      EXPECT_GE(distanceToOutline(panel.outline, tab.xy), kClearance * options.fastener - 1e-9);
      EXPECT_TRUE(insidePolygon(panel.outline, tab.xy));
      // The band's own holes went with it; its edge is not on the panel any more.
      EXPECT_GE(piece.holes.size(), 2u);
      for (const PanelHole& hole : panel.holes) EXPECT_NE(hole.edge, piece.edge);
      std::set<std::string> roles;
      for (const PanelLabel& label : piece.labels) roles.insert(std::string(roleName(label.role)));
      EXPECT_EQ(roles, (std::set<std::string>{"edge", "piece"}));
    }
  }
  EXPECT_GE(pieces, 1) << "the crumpled torus no longer needs a split: the test proves nothing";
  EXPECT_EQ(holes, 2 * s.fasteners);  // a hole on each copy of a band, and on both sides of a tab
}

// Where the size at which every band has room would not fit the bed, make
// builds with glueBandsWithoutRoom: a band without room gets no hole on
// either copy and is listed to be glued; the others keep their holes.
TEST(BandStructure, BandsWithoutRoomAreGluedWhenAsked) {
  const PolygonMesh mesh = test::crumpledTorus();
  BandOptions options;
  options.fastener = 0.25;  // too large for a few of its narrowest bands
  EXPECT_THROW(buildBandStructure(mesh, options, test::context()), NoRoomForHoleError);
  options.glueBandsWithoutRoom = true;
  const Structure s = buildBandStructure(mesh, options, test::context());
  ASSERT_FALSE(s.glued.empty());
  const std::set<int> glued(s.glued.begin(), s.glued.end());
  std::map<int, int> holesOfEdge;
  int holes = 0;
  for (const Panel& panel : s.panels) {
    for (const PanelHole& hole : panel.holes) ++holesOfEdge[hole.edge], ++holes;
    for (const PanelPiece& piece : panel.pieces) {
      for (const PanelHole& hole : piece.holes) ++holesOfEdge[hole.edge], ++holes;
    }
  }
  for (int edge : glued) EXPECT_EQ(holesOfEdge.count(edge), 0u) << "edge " << edge;
  EXPECT_EQ(holesOfEdge.size() + glued.size(), static_cast<size_t>(s.edges) + holesOfEdge.count(0));
  EXPECT_EQ(holes, 2 * s.fasteners);
  EXPECT_TRUE(std::any_of(s.warnings.begin(), s.warnings.end(), [&](const std::string& w) {
    return w.find("so no hole: glue them") != std::string::npos;
  })) << "the builders are told";
  // In the steps, a glued band's join has no fasteners.
  for (const AssemblyStep& step : s.steps) {
    for (const AssemblyJoin& join : step.joins) EXPECT_EQ(join.fasteners == 0, glued.count(join.edge) == 1);
  }
}

}  // namespace
}  // namespace rotafab::geometry
