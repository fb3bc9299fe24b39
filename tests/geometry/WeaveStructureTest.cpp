// A plain-woven structure end to end (dissertation ch. IV; docs/WEAVE.md,
// M9-M11): one panel per edge, panel k over edge k; each edge number `up` on
// one panel and `down` on two (the woven rule, docs/CONTRACT.md,
// "manifest.json (version 1)"), with an underlined neighbour number naming a
// panel under it; two holes per crossing on each of its three panels, the three
// of each position on one line through the stacked ribbons; every crossing
// fastened once, with two fasteners, at the step of its last panel.
#include "geometry/WeaveStructure.h"

#include <gtest/gtest.h>

#include <map>
#include <set>

#include "core/Polygon2.h"
#include "geometry/FastenerHoles.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"
#include "support/MeshSupport.h"
#include "support/TestContext.h"

namespace rotafab::geometry {
namespace {

// A flat point of a woven panel back in space: the panel's outline is one
// rail forwards and the other backwards, row by row, and its surface a quad
// per row, (P_r+1, P_r, Q_r, Q_r+1), whose fan from its first corner is the
// strip's triangles (P_r, Q_r, P_r+1), (Q_r, Q_r+1, P_r+1).
std::optional<Point3> inSpace(const Panel& panel, const Point2& xy) {
  const size_t rows = panel.outline.size() / 2;
  std::vector<Point2> a(panel.outline.begin(), panel.outline.begin() + static_cast<long>(rows));
  std::vector<Point2> b(panel.outline.rbegin(), panel.outline.rbegin() + static_cast<long>(rows));
  // Which flat rail is P: the one whose first side is as long as P's in space.
  const Point3 &p0 = panel.surface[0][1], &p1 = panel.surface[0][0];
  if (std::abs((a[1] - a[0]).norm() - (p1 - p0).norm()) > std::abs((b[1] - b[0]).norm() - (p1 - p0).norm())) {
    std::swap(a, b);
  }
  for (size_t r = 0; r + 1 < rows; ++r) {
    const std::array<std::array<Point2, 3>, 2> flat{{{a[r], b[r], a[r + 1]}, {b[r], b[r + 1], a[r + 1]}}};
    for (size_t t = 0; t < 2; ++t) {
      const auto& f = flat[t];
      const double area = core::cross(f[1] - f[0], f[2] - f[0]);
      const double w1 = core::cross(xy - f[0], f[2] - f[0]) / area, w2 = core::cross(f[1] - f[0], xy - f[0]) / area;
      if (w1 < -1e-9 || w2 < -1e-9 || w1 + w2 > 1 + 1e-9) continue;
      const auto& q = panel.surface[r];
      const std::array<Point3, 3> s =
          t == 0 ? std::array<Point3, 3>{q[1], q[2], q[0]} : std::array<Point3, 3>{q[2], q[3], q[0]};
      return (1 - w1 - w2) * s[0] + w1 * s[1] + w2 * s[2];
    }
  }
  return std::nullopt;
}

Structure wovenStructure(PolygonMesh mesh, WeaveOptions options = {}) {
  mesh = test::atConstructionSize(std::move(mesh));
  requireUsable(analyzeMesh(mesh));
  return buildWeaveStructure(mesh, options, test::context());
}

TEST(WeaveStructure, TheSoccerBallIsNinetyPanelsEachOverItsEdgeAndUnderTwo) {
  const WeaveOptions options;
  const Structure s = wovenStructure(truncatedIcosahedron(), options);
  ASSERT_EQ(s.panels.size(), 90U);
  EXPECT_EQ(s.kind, StructureKind::Weave);
  EXPECT_EQ(s.edges, 90);
  EXPECT_EQ(s.fasteners, 180);
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
  std::map<int, int> up, down;
  std::set<int> cycles;
  for (const Panel& panel : s.panels) {
    SCOPED_TRACE(panel.id);
    EXPECT_EQ(panel.source.edge, panel.id);
    cycles.insert(panel.source.cycle);
    std::map<LabelRole, int> roles;
    for (const PanelLabel& label : panel.labels) {
      ++roles[label.role];
      if (label.role == LabelRole::Up) {
        EXPECT_EQ(label.edge, panel.id);
        ++up[label.edge];
      }
      if (label.role == LabelRole::Down) ++down[label.edge];
    }
    EXPECT_EQ(roles[LabelRole::Up], 1);
    EXPECT_EQ(roles[LabelRole::Down], 2);
    EXPECT_EQ(roles[LabelRole::Neighbor], 1);
    EXPECT_GT(core::signedArea(panel.outline), 0);
    EXPECT_FALSE(core::crossesItself(panel.outline));
    // Its holes: two at each of its three crossings.
    std::map<int, int> holes;
    for (const PanelHole& hole : panel.holes) ++holes[hole.edge];
    EXPECT_EQ(holes.size(), 3U);
    for (const auto& [edge, count] : holes) EXPECT_EQ(count, 2) << "edge " << edge;
    EXPECT_EQ(holes.count(panel.id), 1U);
  }
  // docs/CONTRACT.md, "manifest.json (version 1)": each edge index `up` on one
  // panel and `down` on two.
  for (int e = 1; e <= 90; ++e) {
    EXPECT_EQ(up[e], 1) << e;
    EXPECT_EQ(down[e], 2) << e;
  }
  // Petrie walks of the truncated icosahedron: ten threads of 18.
  EXPECT_EQ(cycles.size(), 10U);
}

TEST(WeaveStructure, TheNeighbourNumberNamesAPanelUnderTheCrossing) {
  const Structure s = wovenStructure(truncatedIcosahedron());
  std::map<int, std::set<int>> panelsAt;
  for (const Panel& panel : s.panels) {
    for (const PanelHole& hole : panel.holes) panelsAt[hole.edge].insert(panel.id);
  }
  for (const Panel& panel : s.panels) {
    for (const PanelLabel& label : panel.labels) {
      if (label.role != LabelRole::Neighbor) continue;
      EXPECT_NE(label.edge, panel.id);
      EXPECT_EQ(panelsAt[panel.id].count(label.edge), 1U) << "panel " << panel.id;
      // Underlined: one stroke more than its digits.
      EXPECT_FALSE(label.strokes.empty());
    }
  }
}

// A woven panel's centre line in space, row by row, in the order its rows
// run along the thread (its quads (P_r+1, P_r, Q_r, Q_r+1)).
std::vector<Point3> centreLine(const Panel& panel) {
  std::vector<Point3> line;
  for (const auto& q : panel.surface) line.push_back(0.5 * (q[1] + q[2]));
  line.push_back(0.5 * (panel.surface.back()[0] + panel.surface.back()[3]));
  return line;
}

size_t nearestRow(const std::vector<Point3>& line, const Point3& p) {
  size_t best = 0;
  for (size_t r = 1; r < line.size(); ++r) {
    if ((line[r] - p).squaredNorm() < (line[best] - p).squaredNorm()) best = r;
  }
  return best;
}

// The A12 rule (docs/WEAVE.md 1.12) from the panels alone: for the panel P
// over edge e, N_e points from the panels under e up to P (the up ribbon
// lies above them); the under thread runs from the down panel that ends at
// e to the one that starts there; the underlined number is the one met
// first turning counter-clockwise about N_e from the way P runs.
TEST(WeaveStructure, TheNeighbourNumberIsTheUnderPanelMetFirstCounterClockwise) {
  for (auto& [name, mesh] : std::vector<std::pair<const char*, PolygonMesh>>{
           {"cube", cube()}, {"soccer ball", truncatedIcosahedron()}, {"torus", torus(9, 6)}}) {
    SCOPED_TRACE(name);
    const Structure s = wovenStructure(mesh);
    // Where each panel meets edge e in space: the mean of its holes there.
    const auto holesAt = [](const Panel& panel, int edge) {
      Point3 sum = Point3::Zero();
      int count = 0;
      for (const PanelHole& hole : panel.holes) {
        if (hole.edge != edge) continue;
        const auto p = inSpace(panel, hole.xy);
        if (p) sum += *p, ++count;
      }
      return count ? std::optional<Point3>(sum / count) : std::nullopt;
    };
    int checked = 0;
    for (const Panel& over : s.panels) {
      SCOPED_TRACE(over.id);
      const int e = over.id;
      const auto top = holesAt(over, e);
      ASSERT_TRUE(top);
      const std::vector<Point3> overLine = centreLine(over);
      const size_t u = nearestRow(overLine, *top);
      const Point3 overRuns = overLine[std::min(u + 1, overLine.size() - 1)] - overLine[u == 0 ? 0 : u - 1];
      const Panel *before = nullptr, *after = nullptr;
      Point3 underRuns = Point3::Zero(), normal = Point3::Zero();
      for (const Panel& down : s.panels) {
        if (&down == &over) continue;
        const auto bottom = holesAt(down, e);
        if (!bottom) continue;
        normal += *top - *bottom;
        const std::vector<Point3> line = centreLine(down);
        const size_t r = nearestRow(line, *bottom);
        // e at its last rows: the thread arrives at e on it.
        (r > line.size() / 2 ? before : after) = &down;
        underRuns += line[std::min(r + 1, line.size() - 1)] - line[r == 0 ? 0 : r - 1];
      }
      ASSERT_TRUE(before && after) << "edge " << e << " has no down panel on each side";
      const int expected = overRuns.cross(underRuns).dot(normal) > 0 ? after->id : before->id;
      int underlined = 0;
      for (const PanelLabel& label : over.labels) {
        if (label.role == LabelRole::Neighbor) underlined = label.edge;
      }
      EXPECT_EQ(underlined, expected) << "before " << before->id << ", after " << after->id;
      ++checked;
    }
    EXPECT_EQ(checked, static_cast<int>(s.panels.size()));
  }
}

TEST(WeaveStructure, TheHolesOfACrossingLineUpThroughItsThreePanels) {
  WeaveOptions options;
  for (auto& [name, mesh] : std::vector<std::pair<const char*, PolygonMesh>>{
           {"cube", cube()}, {"soccer ball", truncatedIcosahedron()}, {"torus", torus(9, 6)}}) {
    SCOPED_TRACE(name);
    const Structure s = wovenStructure(mesh, options);
    // Per edge, the holes of each panel in space.
    std::map<int, std::vector<std::vector<Point3>>> at;
    for (const Panel& panel : s.panels) {
      std::map<int, std::vector<Point3>> mine;
      for (const PanelHole& hole : panel.holes) {
        const auto p = inSpace(panel, hole.xy);
        ASSERT_TRUE(p) << "a hole of panel " << panel.id << " is off it";
        mine[hole.edge].push_back(*p);
      }
      // The panel over edge k is panel k: first.
      for (auto& [edge, points] : mine) {
        auto& list = at[edge];
        list.insert(edge == panel.id ? list.begin() : list.end(), points);
      }
    }
    for (const auto& [edge, panels] : at) {
      ASSERT_EQ(panels.size(), 3U);
      for (const auto& pair : panels) ASSERT_EQ(pair.size(), 2U);
      // The panels under it share the strip there: their holes are the same
      // points. The panel over it has each hole on the same line along N_e,
      // above: 2h at the crossing's centre, and at the holes, either side of
      // it, as far as the Bézier rails have bowed towards the next crossing.
      for (const Point3& hole : panels[1]) {
        const double same = std::min((panels[2][0] - hole).norm(), (panels[2][1] - hole).norm());
        EXPECT_LT(same, 1e-9) << "edge " << edge;
        const double over = std::min((panels[0][0] - hole).norm(), (panels[0][1] - hole).norm());
        EXPECT_GT(over, options.shape.offset / 2) << "edge " << edge;
        EXPECT_LE(over, 3 * options.shape.offset) << "edge " << edge;
      }
      // Each pair apart by the least clearance's spacing, at the least.
      for (const auto& pair : panels) {
        EXPECT_GE((pair[0] - pair[1]).norm(), (kLeastClearance + 1) * options.fastener * (1 - 1e-9));
      }
    }
  }
}

TEST(WeaveStructure, EveryCrossingIsFastenedOnceWithTwoFastenersAtItsLastPanel) {
  const Structure s = wovenStructure(truncatedIcosahedron());
  std::map<int, int> fastened;
  int total = 0;
  for (const AssemblyStep& step : s.steps) {
    for (const AssemblyJoin& join : step.joins) {
      ++fastened[join.edge];
      total += join.fasteners;
      EXPECT_EQ(join.fasteners, 2);
      EXPECT_LT(join.panel, step.panel + (join.edge == step.panel ? 0 : 1));
    }
  }
  EXPECT_EQ(fastened.size(), 90U);
  EXPECT_EQ(total, s.fasteners);
  // The first thread's panels come first, each over the next crossing of it.
  EXPECT_EQ(s.panels.front().source.cycle, 1);
}

TEST(WeaveStructure, ASingleCycleWeaveIsOneThreadOfFacesLessOnePanels) {
  WeaveOptions options;
  options.cycles = WeaveCycles::Single;
  const Structure s = wovenStructure(cube(), options);
  EXPECT_EQ(s.panels.size(), 5U);
  for (const Panel& panel : s.panels) EXPECT_EQ(panel.source.cycle, 1);
}

TEST(WeaveStructure, APanelThatWouldOverlapItselfIsCutIntoLappedPiecesThatDoNot) {
  // One thread round the torus: at the leaves of its tree it curls round a
  // face, and two of its panels would overlap themselves.
  WeaveOptions options;
  options.cycles = WeaveCycles::Single;
  const Structure s = wovenStructure(importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/torus.obj").mesh, options);
  int pieces = 0, laps = 0;
  for (const Panel& panel : s.panels) {
    SCOPED_TRACE(panel.id);
    EXPECT_FALSE(core::crossesItself(panel.outline));
    for (const PanelHole& hole : panel.holes) laps += hole.edge == 0 ? 1 : 0;
    for (const PanelPiece& piece : panel.pieces) {
      ++pieces;
      EXPECT_EQ(piece.name.substr(0, std::to_string(panel.id).size()), std::to_string(panel.id));
      EXPECT_FALSE(core::crossesItself(piece.outline));
      EXPECT_GT(core::signedArea(piece.outline), 0);
      EXPECT_EQ(piece.fastening, PieceFastening::Tab);
      for (const PanelHole& hole : piece.holes) laps += hole.edge == 0 ? 1 : 0;
      // Its name etched on it, inside it and clear of its holes, so that
      // the builder can tell whose piece it is.
      int named = 0;
      for (const PanelLabel& label : piece.labels) {
        if (label.role != LabelRole::Piece) continue;
        ++named;
        EXPECT_EQ(label.text, piece.name);
        EXPECT_FALSE(label.strokes.empty());
        for (const Point2& corner : label.box.corners()) EXPECT_TRUE(core::insidePolygon(piece.outline, corner));
        for (const PanelHole& hole : piece.holes) EXPECT_GT(label.box.distanceTo(hole.xy), hole.diameter / 2);
      }
      EXPECT_EQ(named, 1) << piece.name;
    }
  }
  EXPECT_GT(pieces, 0);
  EXPECT_EQ(laps, 2 * pieces);  // a lap's hole on both parts it joins
  // Each piece's fastener counted once, with the crossings' two each.
  int crossingFasteners = 0;
  for (const AssemblyStep& step : s.steps) {
    for (const AssemblyJoin& join : step.joins) crossingFasteners += join.fasteners;
  }
  EXPECT_EQ(s.fasteners, crossingFasteners + pieces);
}

TEST(WeaveStructure, AFastenerTooLargeForTwoHolesGivesOneAndTooLargeForOneGrowsTheMesh) {
  // The soccer ball's crossings at a 2 in mean edge: room for two 1/8 in
  // holes; for one 1/2 in hole each, at the crossing's centre; for no
  // 1 in hole, until the mesh is larger.
  WeaveOptions options;
  options.fastener = 0.5;
  const Structure one = wovenStructure(truncatedIcosahedron(), options);
  EXPECT_EQ(one.fasteners, 90);
  ASSERT_FALSE(one.warnings.empty());
  EXPECT_NE(one.warnings.front().find("90 crossings are too small for two 0.5 in holes"), std::string::npos)
      << one.warnings.front();
  for (const Panel& panel : one.panels) EXPECT_EQ(panel.holes.size(), 3U);

  PolygonMesh mesh = test::atConstructionSize(truncatedIcosahedron());
  requireUsable(analyzeMesh(mesh));
  options.fastener = 1;
  const GrownStructure grown = buildWeaveStructureWithRoom(mesh, options, test::context());
  EXPECT_GT(grown.grown, 1);
  EXPECT_EQ(grown.structure.panels.size(), 90U);
  EXPECT_TRUE(grown.structure.glued.empty());
}

TEST(WeaveStructure, AnOffsetOnTheScaleOfTheEdgesIsWarnedOfByName) {
  // The soccer ball at construction size: edges of 2 in. Ribbons 0.6 in
  // apart at each crossing do not hold each other; 0.1 in apart they do.
  WeaveOptions options;
  options.names = [](Parameter p) { return p == Parameter::Offset ? std::string("--offset") : parameterInWords(p); };
  options.shape.offset = 0.3;
  const Structure wide = wovenStructure(truncatedIcosahedron(), options);
  ASSERT_EQ(wide.warnings.size(), 1U);
  EXPECT_NE(wide.warnings[0].find("--offset 0.3 in"), std::string::npos) << wide.warnings[0];
  EXPECT_NE(wide.warnings[0].find("0.6 in apart"), std::string::npos) << wide.warnings[0];
  options.shape.offset = 0.05;
  EXPECT_TRUE(wovenStructure(truncatedIcosahedron(), options).warnings.empty());
}

}  // namespace
}  // namespace rotafab::geometry
