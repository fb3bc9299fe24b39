#include "geometry/PolygonMesh.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace rotafab::geometry {

Point3 faceCentroid(const PolygonMesh& mesh, int face) {
  Point3 sum = Point3::Zero();
  for (int v : mesh.faces[face]) sum += mesh.positions[v];
  return sum / static_cast<double>(mesh.faces[face].size());
}

double fanArea(const PolygonMesh& mesh, int face) {
  const auto& f = mesh.faces[face];
  double area = 0.0;
  const Point3& origin = mesh.positions[f[0]];
  for (size_t i = 1; i + 1 < f.size(); ++i) {
    area += (mesh.positions[f[i]] - origin).cross(mesh.positions[f[i + 1]] - origin).norm();
  }
  return 0.5 * area;
}

Point3 boundingBoxSize(const PolygonMesh& mesh) {
  if (mesh.positions.empty()) return Point3::Zero();
  Point3 lo = mesh.positions.front(), hi = lo;
  for (const Point3& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return hi - lo;
}

double boundingBoxDiagonal(const PolygonMesh& mesh) { return boundingBoxSize(mesh).norm(); }

std::string formatPoint(const Point3& p) { return fmt::format("({:.6g}, {:.6g}, {:.6g})", p.x(), p.y(), p.z()); }

std::string formatIndexList(std::span<const int> indices) { return fmt::format("({})", fmt::join(indices, ", ")); }

}  // namespace rotafab::geometry
