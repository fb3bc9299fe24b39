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
#include "geometry/MeshImport.h"
#include "geometry/Primitives.h"

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
          EXPECT_TRUE(near(segmentPoint(previous, pass, side, 1), segmentPoint(pass, next, side, 0), tolerance));
          const Point3 in =
              (segmentPoint(previous, pass, side, 1) - segmentPoint(previous, pass, side, 1 - kStep)) / kStep;
          const Point3 out = (segmentPoint(pass, next, side, kStep) - segmentPoint(pass, next, side, 0)) / kStep;
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

TEST(WeaveRibbons, NearACrossingTheRibbonsKeepTheirHeightsAndChangeThemPastTheCorner) {
  // For the first and last third of each segment the ribbon stands at its
  // crossing's height, ±h along N_e, so the ribbon over and the ribbon
  // under stay 2h apart as far as they overlap; between, it rises or sinks.
  const RibbonShape shape{.width = 0.8, .curve = 0.6, .offset = 0.05, .samples = 6};
  const WovenMesh w = woven(truncatedIcosahedron());
  for (const Ribbon& ribbon : weaveRibbons(w.rs, w.threads, w.regions, shape)) {
    const size_t n = ribbon.passes.size();
    for (size_t k = 0; k < n; ++k) {
      const RibbonPass &here = ribbon.passes[k], &next = ribbon.passes[(k + 1) % n];
      const Point3 normal = here.lift.normalized();
      const Point3 atCrossing = segmentPoint(here, next, 0, 0);
      // The height above the crossing's plane at a third of the way: the cubic of the projected points lies in
      // that plane only while it is in the quad, so compare with the same point without the lift.
      const double t = 0.3;
      const Point3 lifted = segmentPoint(here, next, 0, t);
      const std::array<Point3, 4> projected{here.middle[0] - here.lift, here.tail[0] - here.lift,
                                            next.head[0] - next.lift, next.middle[0] - next.lift};
      EXPECT_TRUE(near(lifted - bezierPoint(projected, t), here.lift, 1e-12)) << "pass " << k;
      EXPECT_NEAR((atCrossing - w.regions[static_cast<size_t>(here.edge)].midpoint).dot(normal), shape.offset, 1e-9);
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
