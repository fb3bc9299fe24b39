#include "geometry/EdgeProjection.h"

#include <fmt/format.h>

#include <stdexcept>

#include "geometry/BandDecomposition.h"

namespace rotafab::geometry {

std::vector<EdgeRegion> edgeRegions(const PolygonMesh& mesh, const RotationSystem& rs) {
  std::vector<Point3> normals(mesh.faces.size()), centres(mesh.faces.size());
  for (int f = 0; f < mesh.faceCount(); ++f) {
    normals[static_cast<size_t>(f)] = faceNormal(mesh, f);
    centres[static_cast<size_t>(f)] = faceCentroid(mesh, f);
  }
  std::vector<EdgeRegion> regions;
  regions.reserve(static_cast<size_t>(rs.edgeCount()));
  for (int e = 0; e < rs.edgeCount(); ++e) {
    const Dart d = 2 * e;
    const int vs = rs.origin(d), vt = rs.target(d);
    const auto name = [&] { return fmt::format("edge {} ({}-{})", e + 1, vs + 1, vt + 1); };
    if (rs.isBoundaryEdge(e)) throw std::invalid_argument(name() + " is on a boundary: it has one face");
    const size_t left = static_cast<size_t>(rs.face(d)),
                 right = static_cast<size_t>(rs.face(RotationSystem::reverse(d)));
    EdgeRegion region;
    region.start = mesh.positions[static_cast<size_t>(vs)];
    region.end = mesh.positions[static_cast<size_t>(vt)];
    region.midpoint = (region.start + region.end) / 2;
    const Point3 along = (region.end - region.start).normalized();
    const Point3 sum = normals[left] + normals[right];
    const Point3 across = sum - sum.dot(along) * along;
    // Two faces folded flat onto each other, or a face of no area: no plane.
    if (!(across.norm() > 1e-6)) {
      throw FoldedEdgeError(name() + ": its two faces fold back onto each other, so no plane lies between them",
                            static_cast<int>(left), static_cast<int>(right), std::array{vs, vt});
    }
    region.normal = across.normalized();
    const auto projected = [&](const Point3& p) {
      return Point3(p - (p - region.midpoint).dot(region.normal) * region.normal);
    };
    region.leftCentre = projected(centres[left]);
    region.rightCentre = projected(centres[right]);
    regions.push_back(region);
  }
  return regions;
}

}  // namespace rotafab::geometry
