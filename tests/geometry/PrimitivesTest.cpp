// The meshes built in code are the fixtures of every other suite: check their
// counts, and that they come out manifold and oriented outwards as promised.

#include "geometry/Primitives.h"

#include <gtest/gtest.h>

#include "geometry/io/ObjWriter.h"
#include "support/MeshSupport.h"
#include "support/TestSupport.h"

namespace rotafab::geometry {
namespace {

struct Expected {
  const char* name;
  PolygonMesh mesh;
  int vertices, edges, faces, boundaryLoops, genus;
};

std::vector<Expected> expectations() {
  return {
      {"tetrahedron", tetrahedron(), 4, 6, 4, 0, 0},
      {"cube", cube(), 8, 12, 6, 0, 0},
      {"octahedron", octahedron(), 6, 12, 8, 0, 0},
      {"dodecahedron", dodecahedron(), 20, 30, 12, 0, 0},
      {"icosahedron", icosahedron(), 12, 30, 20, 0, 0},
      {"truncated icosahedron", truncatedIcosahedron(), 60, 90, 32, 0, 0},
      {"torus", torus(8, 5), 40, 80, 40, 0, 1},
      {"genus-2 slab", genusTwoSlab(), 48, 100, 50, 0, 2},
      {"disc", disc(7), 8, 14, 7, 1, 0},
  };
}

TEST(Primitives, CountsGenusAndOrientation) {
  for (auto& e : expectations()) {
    SCOPED_TRACE(e.name);
    PolygonMesh mesh = e.mesh;
    const MeshAnalysis analysis = analyzeMesh(mesh);
    EXPECT_TRUE(analysis.usable()) << (analysis.problems.empty() ? "" : analysis.problems[0].message);
    EXPECT_EQ(analysis.topology.vertices, e.vertices);
    EXPECT_EQ(analysis.topology.edges, e.edges);
    EXPECT_EQ(analysis.topology.faces, e.faces);
    EXPECT_EQ(analysis.topology.boundaryLoops, e.boundaryLoops);
    EXPECT_EQ(analysis.topology.genus, e.genus);
    // Built outward and consistent: the analysis must not have changed a face.
    EXPECT_EQ(analysis.flippedFaces, 0);
    EXPECT_EQ(mesh.faces, e.mesh.faces);
  }
}

TEST(Primitives, SoccerBallHasTwelvePentagonsAndTwentyHexagons) {
  const PolygonMesh ball = truncatedIcosahedron();
  int pentagons = 0, hexagons = 0;
  for (const auto& face : ball.faces) {
    pentagons += face.size() == 5;
    hexagons += face.size() == 6;
  }
  EXPECT_EQ(pentagons, 12);
  EXPECT_EQ(hexagons, 20);
}

TEST(Primitives, MoebiusStripIsNotOrientable) {
  const MeshTopology t = test::topologyOf(moebiusStrip(12));
  EXPECT_FALSE(t.orientable);
  EXPECT_TRUE(t.manifold);
  EXPECT_EQ(t.boundaryLoops, 1);
  EXPECT_FALSE(t.genus.has_value());
}

// examples/ holds what rotafab-make-examples writes; a change to a generator
// must come with the regenerated files.
TEST(Primitives, CommittedExamplesAreWhatTheGeneratorWrites) {
  test::TempDir dir;
  const auto result = test::run(std::string(ROTAFAB_MAKE_EXAMPLES) + " " + dir.path().string());
  ASSERT_EQ(result.status, 0) << result.err;
  for (const char* name : {"soccer-ball.obj", "torus.obj", "genus2.obj", "cube.obj"}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(test::readFile(dir.path() / name),
              test::readFile(std::filesystem::path(ROTAFAB_SOURCE_DIR) / "examples" / name));
  }
}

}  // namespace
}  // namespace rotafab::geometry
