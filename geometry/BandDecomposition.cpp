#include "geometry/BandDecomposition.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "geometry/CornerCutting.h"

namespace rotafab::geometry {

Point3 faceNormal(const PolygonMesh& mesh, int face) {
  std::vector<Point3> corners;
  for (int v : mesh.faces[static_cast<size_t>(face)]) corners.push_back(mesh.positions[static_cast<size_t>(v)]);
  return newellNormal(corners);
}

Point3 newellNormal(const std::vector<Point3>& polygon) {
  Point3 normal = Point3::Zero();
  for (size_t i = 0; i < polygon.size(); ++i) normal += polygon[i].cross(polygon[(i + 1) % polygon.size()]);
  const double length = normal.norm();
  return length > 0 ? Point3(normal / length) : Point3::Zero();
}

namespace {

// The face on the closed side of a boundary edge.
int borderingFace(const RotationSystem& rs, int edge) { return std::max(rs.face(2 * edge), rs.face(2 * edge + 1)); }

Point3 midpoint(const PolygonMesh& mesh, const RotationSystem& rs, int edge) {
  return (mesh.positions[rs.origin(2 * edge)] + mesh.positions[rs.target(2 * edge)]) / 2;
}

}  // namespace

BandDecomposition bandDecomposition(const PolygonMesh& mesh, const RotationSystem& rs, std::optional<double> tension) {
  BandDecomposition result;
  result.vertexBands.resize(mesh.faceCount());
  for (int f = 0; f < mesh.faceCount(); ++f) result.vertexBands[f].corners.resize(mesh.faces[f].size());
  result.cornerOfDart.assign(rs.dartCount(), -1);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    Dart d = rs.faceDart(f);
    for (size_t n = 0; n < mesh.faces[f].size(); ++n, d = rs.faceNext(d)) result.cornerOfDart[d] = static_cast<int>(n);
  }
  std::vector<Point3> centroids(mesh.faceCount());
  for (int f = 0; f < mesh.faceCount(); ++f) centroids[f] = faceCentroid(mesh, f);

  // V.1.1 on the dual: each vertex's dual polygon, cut at its corners.
  for (int x = 0; x < mesh.vertexCount(); ++x) {
    const std::vector<Dart> darts = rs.dartsAround(x);
    std::vector<Point3> polygon;
    std::vector<Dart> cornerDart;  // the dart of each polygon corner that is a face's corner, else -1
    if (!rs.isBoundaryVertex(x)) {
      for (Dart d : darts) polygon.push_back(centroids[rs.face(d)]), cornerDart.push_back(d);
    } else {
      // darts[0] is on the open side: the faces run from darts[1] to the last.
      for (size_t i = 1; i < darts.size(); ++i) {
        polygon.push_back(centroids[rs.face(darts[i])]);
        cornerDart.push_back(darts[i]);
      }
      int before = RotationSystem::edgeOf(darts.front()), after = -1;
      for (Dart d : darts) {
        if (RotationSystem::edgeOf(d) != before && rs.isBoundaryEdge(RotationSystem::edgeOf(d))) {
          after = RotationSystem::edgeOf(d);
        }
      }
      if (after < 0) after = before;
      // The gap closes between the last face and the first: through the
      // midpoint of the boundary edge of the last face, the vertex, and the
      // midpoint of that of the first.
      if (borderingFace(rs, before) != rs.face(darts.back())) std::swap(before, after);
      polygon.push_back(midpoint(mesh, rs, before));
      polygon.push_back(mesh.positions[x]);
      polygon.push_back(midpoint(mesh, rs, after));
      cornerDart.insert(cornerDart.end(), {-1, -1, -1});
    }
    const int sides = static_cast<int>(polygon.size());
    // An interior vertex of valence 2 (two faces sharing two sides in a row)
    // has a dual polygon of two corners: eq. 5.2 needs three, so each corner
    // moves a share 1 - a towards the other (Doo-Sabin's a for N = 2).
    Eigen::MatrixXd weights(sides, sides);
    if (sides == 2) {
      const double a = tension.value_or(dooSabinTension(2));
      weights << a, 1 - a, 1 - a, a;
    } else {
      weights = cornerCuttingWeights(sides, tension.value_or(dooSabinTension(sides)));
    }
    for (int n = 0; n < sides; ++n) {
      if (cornerDart[n] < 0) continue;
      Point3 p = Point3::Zero();
      for (int m = 0; m < sides; ++m) p += weights(n, m) * polygon[m];
      const Dart d = cornerDart[n];
      result.vertexBands[rs.face(d)].corners[result.cornerOfDart[d]] = p;
    }
  }

  // V.2: each vertex band onto its least-squares plane.
  for (int f = 0; f < mesh.faceCount(); ++f) {
    VertexBand& band = result.vertexBands[f];
    Point3 centroid = Point3::Zero();
    for (const Point3& p : band.corners) centroid += p;
    centroid /= static_cast<double>(band.corners.size());
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const Point3& p : band.corners) scatter += (p - centroid) * (p - centroid).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
    Point3 normal = solver.eigenvectors().col(0);  // the least eigenvalue's
    Point3 turning = newellNormal(band.corners);
    if (turning.isZero()) {
      std::vector<Point3> face;
      for (int v : mesh.faces[f]) face.push_back(mesh.positions[v]);
      turning = newellNormal(face);
    }
    if (normal.dot(turning) < 0) normal = -normal;
    for (Point3& p : band.corners) {
      const double off = (p - centroid).dot(normal);
      result.largestProjection = std::max(result.largestProjection, std::abs(off));
      p -= off * normal;
    }
    band.normal = normal;
    band.centroid = centroid;
  }
  return result;
}

}  // namespace rotafab::geometry
