// Writes the example meshes Rotafab makes itself into a folder (default:
// the current one). `examples/` holds their output; a test checks that the
// committed files are what this program writes.

#include <fmt/format.h>

#include <filesystem>
#include <fstream>

#include "geometry/Primitives.h"
#include "geometry/io/ObjWriter.h"

namespace geo = rotafab::geometry;

int main(int argc, char** argv) {
  const std::filesystem::path folder = argc > 1 ? argv[1] : ".";
  struct Example {
    const char* file;
    const char* description;
    geo::PolygonMesh mesh;
  };
  const Example examples[] = {
      {"soccer-ball.obj", "truncated icosahedron (12 pentagons, 20 hexagons), genus 0", geo::truncatedIcosahedron()},
      {"torus.obj", "torus of 24 x 12 quads, genus 1", geo::torus(24, 12)},
      {"genus2.obj", "slab with two square holes, quads, genus 2", geo::genusTwoSlab()},
      {"cube.obj", "cube with 6 quad faces, genus 0", geo::cube()},
  };
  for (const auto& example : examples) {
    const auto path = folder / example.file;
    std::ofstream out(path, std::ios::binary);
    geo::writeObj(out, example.mesh, fmt::format("{} (written by rotafab-make-examples)", example.description));
    if (!out) {
      fmt::print(stderr, "error: {}: cannot write\n", path.string());
      return 1;
    }
  }
  return 0;
}
