#pragma once
// A crumpled torus: torus(8, 6) with every vertex moved by up to 1.2 units
// along each axis (a fixed pseudo-random pattern, the same on every
// machine), at three times the construction scale. One of its panels would
// overlap itself when unfolded (V.4): the test mesh of panel splitting.

#include <cmath>

#include "geometry/ConstructionScale.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/Primitives.h"

namespace rotafab::test {

inline geometry::PolygonMesh crumpledTorus() {
  geometry::PolygonMesh mesh = geometry::torus(8, 6);
  const auto noise = [](int vertex, int axis) {
    const double x = std::sin(vertex * 12.9898 + axis * 78.233 + 7 * 37.719) * 43758.5453;
    return x - std::floor(x) - 0.5;
  };
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    for (int axis = 0; axis < 3; ++axis) mesh.positions[v][axis] += 2.4 * noise(v, axis);
  }
  geometry::analyzeMesh(mesh);
  const double scale = 3 * geometry::constructionScale(mesh, std::nullopt, std::nullopt);
  for (geometry::Point3& p : mesh.positions) p *= scale;
  return mesh;
}

}  // namespace rotafab::test
