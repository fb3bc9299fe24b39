#pragma once
// Meshes as the geometry tests want them: at construction size, and their topology in one call.

#include "geometry/ConstructionScale.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::test {

// A mesh scaled as `make` scales it by default (mean edge 2 in).
inline geometry::PolygonMesh atConstructionSize(geometry::PolygonMesh mesh) {
  geometry::analyzeMesh(mesh);
  const double scale = geometry::constructionScale(mesh, std::nullopt, std::nullopt);
  for (geometry::Point3& p : mesh.positions) p *= scale;
  return mesh;
}

inline geometry::MeshTopology topologyOf(geometry::PolygonMesh mesh) { return geometry::analyzeMesh(mesh).topology; }

}  // namespace rotafab::test
