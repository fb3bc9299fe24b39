#pragma once
// Meshes as the geometry tests want them: at construction size, and their topology in one call.

#include "geometry/BandStructure.h"
#include "geometry/ConstructionScale.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/PolygonMesh.h"
#include "support/TestContext.h"

namespace rotafab::test {

// A mesh scaled as `make` scales it by default (mean edge 2 in).
inline geometry::PolygonMesh atConstructionSize(geometry::PolygonMesh mesh) {
  geometry::analyzeMesh(mesh);
  const double scale = geometry::constructionScale(mesh, std::nullopt, std::nullopt);
  for (geometry::Point3& p : mesh.positions) p *= scale;
  return mesh;
}

// A mesh at the size `make` builds it when no size is given: the mean edge
// 2 in, larger where a band would otherwise have no room for a fastener of
// `fastener` (geometry::buildBandStructureWithRoom()).
inline geometry::PolygonMesh atBuildableSize(geometry::PolygonMesh mesh, double fastener = 0.125) {
  mesh = atConstructionSize(std::move(mesh));
  geometry::BandOptions options;
  options.fastener = fastener;
  geometry::buildBandStructureWithRoom(mesh, options, context());
  return mesh;
}

// Appends `other` to `mesh`, its vertices moved by `offset` (a separate
// component unless a vertex lands on one of `mesh`'s and is welded).
inline void append(geometry::PolygonMesh& mesh, const geometry::PolygonMesh& other, const geometry::Point3& offset) {
  const int base = mesh.vertexCount();
  for (const auto& p : other.positions) mesh.positions.push_back(p + offset);
  for (auto face : other.faces) {
    for (int& v : face) v += base;
    mesh.faces.push_back(face);
  }
}

inline geometry::MeshTopology topologyOf(geometry::PolygonMesh mesh) { return geometry::analyzeMesh(mesh).topology; }

}  // namespace rotafab::test
