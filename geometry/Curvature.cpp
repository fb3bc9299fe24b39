#include "geometry/Curvature.h"

#include <cmath>
#include <numbers>

namespace rotafab::geometry {

double cornerAngle(const PolygonMesh& mesh, int face, int corner) {
  const auto& f = mesh.faces[face];
  const int n = static_cast<int>(f.size());
  const Point3& here = mesh.positions[f[corner]];
  const Eigen::Vector3d toPrevious = mesh.positions[f[(corner + n - 1) % n]] - here;
  const Eigen::Vector3d toNext = mesh.positions[f[(corner + 1) % n]] - here;
  return std::atan2(toPrevious.cross(toNext).norm(), toPrevious.dot(toNext));
}

double faceDefect(const PolygonMesh& mesh, int face) {
  const int n = static_cast<int>(mesh.faces[face].size());
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += cornerAngle(mesh, face, i);
  return sum - (n - 2) * std::numbers::pi;
}

namespace {

// The corner angle at origin(d) in face(d): d is that face's corner.
double angleAtDart(const PolygonMesh& mesh, const RotationSystem& rs, Dart d) {
  const int f = rs.face(d);
  const auto& face = mesh.faces[f];
  for (int i = 0; i < static_cast<int>(face.size()); ++i)
    if (face[i] == rs.origin(d)) return cornerAngle(mesh, f, i);
  return 0.0;
}

}  // namespace

double vertexDefect(const PolygonMesh& mesh, const RotationSystem& rs, int vertex) {
  double sum = 0.0;
  for (Dart d : rs.dartsAround(vertex))
    if (!rs.isBoundary(d)) sum += angleAtDart(mesh, rs, d);
  return (rs.isBoundaryVertex(vertex) ? std::numbers::pi : 2.0 * std::numbers::pi) - sum;
}

double totalVertexDefect(const PolygonMesh& mesh, const RotationSystem& rs) {
  double total = 0.0;
  for (int v = 0; v < mesh.vertexCount(); ++v) total += vertexDefect(mesh, rs, v);
  return total;
}

double totalFaceDefect(const PolygonMesh& mesh) {
  double total = 0.0;
  for (int f = 0; f < mesh.faceCount(); ++f) total += faceDefect(mesh, f);
  return total;
}

double holeAndMaterialDefect(const PolygonMesh& mesh, const std::vector<char>& isHole) {
  std::vector<double> materialAngle(mesh.positions.size(), 0.0);
  double total = 0.0;
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (isHole[f]) continue;
    for (int i = 0; i < static_cast<int>(mesh.faces[f].size()); ++i) {
      materialAngle[mesh.faces[f][i]] += cornerAngle(mesh, f, i);
    }
    total += faceDefect(mesh, f);
  }
  for (int f = 0; f < mesh.faceCount(); ++f) {
    if (!isHole[f]) continue;
    const auto& face = mesh.faces[f];
    double holeAngles = 0.0;
    for (int v : face) holeAngles += 2.0 * std::numbers::pi - materialAngle[v];
    total += holeAngles - (static_cast<double>(face.size()) - 2.0) * std::numbers::pi;
  }
  return total;
}

}  // namespace rotafab::geometry
