// The woven ribbons (dissertation IV.1-IV.2; docs/WEAVE.md, 1.4-1.8 and
// section 4): each crossing's over quad is eq. 4.2-4.11 as printed but with
// w in the second pass, lifted by +h; the under quad is its transpose,
// lowered by -h, with the same centre; consecutive passes of a thread meet
// at the corner they share, with their vertex-side rails meeting at the
// vertex; the Bézier rails are C1 at every quad's middle (eq. 4.17); a
// single-cycle weave's untwisted passes join up the same way.
#include "geometry/WeaveRibbons.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"
#include "geometry/io/MeshImport.h"

namespace rotafab::geometry {
namespace {

struct WovenMesh {
  PolygonMesh mesh;
  RotationSystem rs;
  WeaveThreads threads;
  std::vector<EdgeRegion> regions;
};

WovenMesh woven(PolygonMesh mesh, WeaveCycles cycles = WeaveCycles::All) {
  requireUsable(analyzeMesh(mesh));
  RotationSystem rs = RotationSystem::fromMesh(mesh);
  twistForWeave(rs, cycles);
  WeaveThreads threads = traceThreads(rs);
  std::vector<EdgeRegion> regions = edgeRegions(mesh, rs);
  return {std::move(mesh), std::move(rs), std::move(threads), std::move(regions)};
}

std::vector<std::pair<const char*, PolygonMesh>> ribbonMeshes() {
  std::vector<std::pair<const char*, PolygonMesh>> meshes{{"tetrahedron", tetrahedron()},
                                                          {"cube", cube()},
                                                          {"soccer ball", truncatedIcosahedron()},
                                                          {"torus", torus(9, 6)},
                                                          {"genus-2", genusTwoSlab()}};
  meshes.emplace_back("bunny", importMesh(std::string(ROTAFAB_SOURCE_DIR) + "/examples/bunny.obj").mesh);
  return meshes;
}

bool near(const Point3& a, const Point3& b, double tolerance) { return (a - b).norm() <= tolerance; }

TEST(WeaveRibbons, TheOverQuadIsEquationsFourTwoToFourElevenWithTheWidthAndTheUnderQuadItsTranspose) {
  const WovenMesh w = woven(truncatedIcosahedron());
  const RibbonShape shape{.width = 0.7, .curve = 0.4, .offset = 0.03, .samples = 4};
  const double c = shape.curve, wd = shape.width;
  for (int e = 0; e < w.rs.edgeCount(); ++e) {
    SCOPED_TRACE(e);
    const EdgeRegion& r = w.regions[static_cast<size_t>(e)];
    // Eq. 4.2-4.11 literally, on the projected corners, with w in 4.6-4.9 (A1).
    const Point3 &vs = r.start, &vt = r.end, &cl = r.leftCentre, &cr = r.rightCentre;
    const Point3 C0 = vs * (1 + c) / 2 + cr * (1 - c) / 2, C2 = vs * (1 - c) / 2 + cr * (1 + c) / 2;
    const Point3 D0 = cl * (1 + c) / 2 + vt * (1 - c) / 2, D2 = cl * (1 - c) / 2 + vt * (1 + c) / 2;
    const Point3 A0 = C0 * (1 + wd) / 2 + D0 * (1 - wd) / 2, B0 = C0 * (1 - wd) / 2 + D0 * (1 + wd) / 2;
    const Point3 A2 = C2 * (1 + wd) / 2 + D2 * (1 - wd) / 2, B2 = C2 * (1 - wd) / 2 + D2 * (1 + wd) / 2;
    const Point3 A1 = (A0 + A2) / 2, B1 = (B0 + B2) / 2;
    const Point3 lift = shape.offset * r.normal;

    const StepRef up = w.threads.up[static_cast<size_t>(e)], down = w.threads.down[static_cast<size_t>(e)];
    const ThreadStep& upStep = w.threads.threads[static_cast<size_t>(up.thread)].steps[static_cast<size_t>(up.step)];
    const ThreadStep& downStep =
        w.threads.threads[static_cast<size_t>(down.thread)].steps[static_cast<size_t>(down.step)];
    const RibbonPass over = ribbonPass(w.rs, r, upStep, shape);
    const RibbonPass under = ribbonPass(w.rs, r, downStep, shape);
    const double tolerance = 1e-12 * (vt - vs).norm();
    // The thread may run the over strand either way: its head is A0 B0 or B2 A2.
    if (upStep.dart == 2 * e) {
      EXPECT_TRUE(near(over.head[0], A0 + lift, tolerance) && near(over.head[1], B0 + lift, tolerance));
      EXPECT_TRUE(near(over.tail[0], A2 + lift, tolerance) && near(over.tail[1], B2 + lift, tolerance));
      EXPECT_TRUE(near(over.middle[0], A1 + lift, tolerance) && near(over.middle[1], B1 + lift, tolerance));
    } else {
      EXPECT_TRUE(near(over.head[0], B2 + lift, tolerance) && near(over.head[1], A2 + lift, tolerance));
      EXPECT_TRUE(near(over.tail[0], B0 + lift, tolerance) && near(over.tail[1], A0 + lift, tolerance));
      EXPECT_TRUE(near(over.middle[0], B1 + lift, tolerance) && near(over.middle[1], A1 + lift, tolerance));
    }
    // The under quad: c along u, w along s (A2), lowered by h.
    const auto corner = [&](double s, double u) -> Point3 { return r.at(s, u) - lift; };
    const std::array<Point3, 4> transposed{corner((1 - wd) / 2, (1 - c) / 2), corner((1 + wd) / 2, (1 - c) / 2),
                                           corner((1 - wd) / 2, (1 + c) / 2), corner((1 + wd) / 2, (1 + c) / 2)};
    for (const Point3& p : {under.head[0], under.head[1], under.tail[0], under.tail[1]}) {
      int matches = 0;
      for (const Point3& q : transposed) matches += near(p, q, tolerance) ? 1 : 0;
      EXPECT_EQ(matches, 1);
    }
    // One centre, the over quad 2h above the under along N_e.
    const Point3 overCentre = (over.middle[0] + over.middle[1]) / 2;
    const Point3 underCentre = (under.middle[0] + under.middle[1]) / 2;
    EXPECT_TRUE(near(overCentre - underCentre, 2 * lift, tolerance));
    // The over strand goes from the start's corner in the left face to the end's in the right, or back.
    const FaceCorner leftStart{w.rs.face(2 * e), w.rs.origin(2 * e)},
        rightEnd{w.rs.face(2 * e + 1), w.rs.target(2 * e)};
    EXPECT_TRUE((over.from == leftStart && over.to == rightEnd) || (over.from == rightEnd && over.to == leftStart));
  }
}

TEST(WeaveRibbons, WithWholeQuadsConsecutivePassesMeetAtTheVertexTheyTurnAbout) {
  // c = w = 1 and h near 0: a quad is its whole projected region, and the
  // vertex-side rail of one pass's tail and of the next pass's head is the
  // vertex itself (it lies in both projection planes); the centre-side
  // corners are the face's centre projected on two planes.
  const RibbonShape whole{.width = 1, .curve = 1, .offset = 1e-12, .samples = 2};
  for (const WeaveCycles cycles : {WeaveCycles::All, WeaveCycles::Single}) {
    for (auto& [name, mesh] : ribbonMeshes()) {
      SCOPED_TRACE(std::string(name) + (cycles == WeaveCycles::All ? " all" : " single"));
      const WovenMesh w = woven(mesh, cycles);
      const auto ribbons = weaveRibbons(w.rs, w.threads, w.regions, whole);
      ASSERT_EQ(ribbons.size(), w.threads.threads.size());
      if (cycles == WeaveCycles::Single) {
        EXPECT_EQ(ribbons.size(), 1U);
      }
      for (const Ribbon& ribbon : ribbons) {
        const size_t n = ribbon.passes.size();
        for (size_t k = 0; k < n; ++k) {
          const RibbonPass &pass = ribbon.passes[k], &next = ribbon.passes[(k + 1) % n];
          ASSERT_EQ(pass.to, next.from) << "pass " << k;
          const Point3& vertex = w.mesh.positions[static_cast<size_t>(pass.to.vertex)];
          const double tolerance = 1e-9 * (1 + vertex.norm());
          int meetingSides = 0;
          for (int side = 0; side < 2; ++side) {
            if (near(pass.tail[side], vertex, tolerance) && near(next.head[side], vertex, tolerance)) ++meetingSides;
          }
          EXPECT_EQ(meetingSides, 1) << "pass " << k << " to " << k + 1;
        }
      }
    }
  }
}

TEST(WeaveRibbons, TheBezierRailsAreC1AtEveryQuadsMiddleAndPassThroughIt) {
  const RibbonShape shape{.width = 0.8, .curve = 0.6, .offset = 0.05, .samples = 6};
  for (auto& [name, mesh] : ribbonMeshes()) {
    SCOPED_TRACE(name);
    const WovenMesh w = woven(mesh);
    for (const Ribbon& ribbon : weaveRibbons(w.rs, w.threads, w.regions, shape)) {
      const int n = static_cast<int>(ribbon.passes.size());
      ASSERT_EQ(ribbon.railP.size(), static_cast<size_t>(n * shape.samples));
      for (int k = 0; k < n; ++k) {
        const RibbonPass& pass = ribbon.passes[static_cast<size_t>(k)];
        const double tolerance = 1e-12 * (1 + pass.middle[0].norm());
        EXPECT_TRUE(near(ribbon.railP[static_cast<size_t>(k * shape.samples)], pass.middle[0], tolerance));
        EXPECT_TRUE(near(ribbon.railQ[static_cast<size_t>(k * shape.samples)], pass.middle[1], tolerance));
        // The sampled curves themselves, lift included: one point and one
        // derivative either side of each middle (central differences).
        const RibbonPass& previous = ribbon.passes[static_cast<size_t>((k + n - 1) % n)];
        const RibbonPass& next = ribbon.passes[static_cast<size_t>((k + 1) % n)];
        constexpr double kStep = 1e-5;
        for (int side = 0; side < 2; ++side) {
          EXPECT_TRUE(near(segmentPoint(previous, pass, segmentTurn(previous, pass), side, 1),
                           segmentPoint(pass, next, segmentTurn(pass, next), side, 0), tolerance));
          const Point3 in = (segmentPoint(previous, pass, segmentTurn(previous, pass), side, 1) -
                             segmentPoint(previous, pass, segmentTurn(previous, pass), side, 1 - kStep)) /
                            kStep;
          const Point3 out = (segmentPoint(pass, next, segmentTurn(pass, next), side, kStep) -
                              segmentPoint(pass, next, segmentTurn(pass, next), side, 0)) /
                             kStep;
          EXPECT_TRUE(near(in, out, 1e-3 * (1 + in.norm()))) << "pass " << k;
          EXPECT_GT(in.norm(), 0);
          // The control polygon of eq. 4.17: A1 the midpoint of A0 A2, so equal tangents at A1.
          const auto before = segmentControls(ribbon, (k + n - 1) % n, side), after = segmentControls(ribbon, k, side);
          EXPECT_TRUE(near(bezierDerivative(before, 1), bezierDerivative(after, 0),
                           1e-12 * (1 + in.norm() + pass.middle[0].norm())));
        }
      }
    }
  }
}

// The other strand's rail `side` at a crossing, as a line in its plane: through its quad's middle and tail.
bool beyondRail(const RibbonPass& other, int side, const Point3& point, const Point3& inside) {
  const auto s = static_cast<size_t>(side);
  const Point3 a = other.middle[s], b = other.tail[s], n = other.lift.normalized();
  const double here = (point - a).cross(b - a).dot(n), there = (inside - a).cross(b - a).dot(n);
  return here * there <= 0;
}

// Over (or under) the other strand of its crossings, at both ends of every
// segment: each sampled rail point at exactly +h or -h over the crossing's
// plane; where the segment turns, outside the other strand (beyond one of
// its rails, as seen along N_e from its quad's centre), unless the segment
// is too short to turn between its crossings' strands (kLeastTurn): those
// are counted in `forced`.
void expectFlatOverTheOtherStrand(const WovenMesh& w, const RibbonShape& shape, int& forced, int& segments) {
  const std::vector<Ribbon> ribbons = weaveRibbons(w.rs, w.threads, w.regions, shape);
  std::vector<std::vector<const RibbonPass*>> atEdge(w.regions.size());
  for (const Ribbon& ribbon : ribbons) {
    for (const RibbonPass& pass : ribbon.passes) atEdge[static_cast<size_t>(pass.edge)].push_back(&pass);
  }
  const auto otherAt = [&](const RibbonPass& pass) -> const RibbonPass& {
    const auto& both = atEdge[static_cast<size_t>(pass.edge)];
    return *(both[0] == &pass ? both[1] : both[0]);
  };
  const auto heightOver = [&](const RibbonPass& pass, const Point3& point) {
    return (point - w.regions[static_cast<size_t>(pass.edge)].midpoint).dot(pass.lift.normalized());
  };
  for (const Ribbon& ribbon : ribbons) {
    const size_t n = ribbon.passes.size();
    for (size_t k = 0; k < n; ++k) {
      const RibbonPass &here = ribbon.passes[k], &next = ribbon.passes[(k + 1) % n];
      ASSERT_EQ(atEdge[static_cast<size_t>(here.edge)].size(), 2U);
      const SegmentTurn turn = segmentTurn(here, next);
      ++segments;
      const bool tooShort = turn.arrive - turn.leave <= kLeastTurn + 1e-9;
      forced += tooShort ? 1 : 0;
      for (int side = 0; side < 2; ++side) {
        for (int i = 0; i <= 8; ++i) {
          const double leaving = turn.leave * i / 8, arriving = 1 - (1 - turn.arrive) * i / 8;
          EXPECT_NEAR(heightOver(here, segmentPoint(here, next, turn, side, leaving)), shape.offset, 1e-9)
              << "pass " << k << " t " << leaving;
          EXPECT_NEAR(heightOver(next, segmentPoint(here, next, turn, side, arriving)), shape.offset, 1e-9)
              << "pass " << k << " t " << arriving;
        }
        if (tooShort) continue;
        for (const auto& [pass, t] : {std::pair{&here, turn.leave + 1e-9}, std::pair{&next, turn.arrive - 1e-9}}) {
          const RibbonPass& other = otherAt(*pass);
          const Point3 point = segmentPoint(here, next, turn, side, t),
                       centre = (other.middle[0] + other.middle[1]) / 2;
          EXPECT_TRUE(beyondRail(other, 0, point, centre) || beyondRail(other, 1, point, centre))
              << "pass " << k << " side " << side << " t " << t;
        }
      }
    }
  }
}

TEST(WeaveRibbons, OverTheOtherStrandARibbonLiesFlatAtItsCrossingsHeightAndTurnsOnlyPastIt) {
  // The strands of a crossing are straight across (the strip's rows), so
  // wherever one lies over the other both stand in the crossing's plane,
  // +h and -h, 2h apart: a ribbon that followed the surface's curve there
  // would sink through the other's rows. Each ribbon turns towards its
  // next crossing only once it is outside the strand it crossed, and is
  // flat again before it reaches the next.
  for (auto& [name, mesh] : ribbonMeshes()) {
    SCOPED_TRACE(name);
    const WovenMesh w = woven(mesh);
    int forced = 0, segments = 0;
    expectFlatOverTheOtherStrand(w, {.width = 0.8, .curve = 0.6, .offset = 0.05, .samples = 6}, forced, segments);
    EXPECT_GT(segments, 0);
    EXPECT_LE(forced * 1000, segments);  // the bunny: 4 of 11 022
    // The widest ribbons: the other strand fills the region, so a ribbon
    // turns only between regions, about the segment's middle (forced),
    // but is flat over the other strand as far as it goes.
    const RibbonShape widest{.width = 1, .curve = 0.6, .offset = 0.05, .samples = 6};
    int forcedWidest = 0;
    segments = 0;
    expectFlatOverTheOtherStrand(w, widest, forcedWidest, segments);
    // Flat at least over most of its own quad (to its tail, about a third
    // of the way), which lies over the other strand at this width.
    for (const Ribbon& ribbon : weaveRibbons(w.rs, w.threads, w.regions, widest)) {
      for (size_t k = 0; k < ribbon.passes.size(); ++k) {
        const SegmentTurn turn = segmentTurn(ribbon.passes[k], ribbon.passes[(k + 1) % ribbon.passes.size()]);
        EXPECT_GE(turn.leave, 0.2) << "pass " << k;
        EXPECT_LE(turn.arrive, 0.8) << "pass " << k;
      }
    }
  }
}

TEST(WeaveRibbons, AShapeOutOfRangeIsRefusedByName) {
  const WovenMesh w = woven(cube());
  const auto refused = [&](RibbonShape shape, const char* name) {
    try {
      weaveRibbons(w.rs, w.threads, w.regions, shape);
      ADD_FAILURE() << name << " accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(name), std::string::npos) << error.what();
    }
  };
  refused({.width = 0}, "width");
  refused({.width = 1.5}, "width");
  refused({.curve = -0.1}, "curve");
  refused({.offset = 0}, "offset");
  refused({.samples = 0}, "samples");
}

}  // namespace
}  // namespace rotafab::geometry
