#include "geometry/DevelopableBands.h"

#include <cmath>
#include <numbers>

namespace rotafab::geometry {

std::vector<std::array<int, 3>> EdgeBand::triangles() const {
  const int k = segments();
  std::vector<std::array<int, 3>> result;
  for (int i = 0; i < k; ++i) {
    const int u = i, uNext = i + 1, v = k + 1 + i, vNext = k + 2 + i;
    result.push_back({u, v, uNext});
    result.push_back({v, vNext, uNext});
  }
  return result;
}

const Point3& EdgeBand::point(int index) const {
  const int k = segments();
  return index <= k ? railU[index] : railV[index - k - 1];
}

namespace {

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

// The cubic Hermite curve from p0 (tangent m0) to p1 (tangent m1) at s in [0, 1].
Point3 hermite(const Point3& p0, const Point3& m0, const Point3& p1, const Point3& m1, double s) {
  const double s2 = s * s, s3 = s2 * s;
  return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * m1;
}

}  // namespace

std::vector<EdgeBand> developableBands(const RotationSystem& rs, const BandDecomposition& bands, int samples) {
  samples = std::max(1, samples);
  std::vector<EdgeBand> result(rs.edgeCount());
  for (int e = 0; e < rs.edgeCount(); ++e) {
    if (rs.isBoundaryEdge(e)) continue;
    EdgeBand& band = result[e];
    band.edge = e;
    const Dart a = 2 * e, b = 2 * e + 1;  // a: u -> v with face A on its left; b: v -> u with face B
    band.faceA = rs.face(a);
    band.faceB = rs.face(b);
    const VertexBand& vbA = bands.vertexBands[band.faceA];
    const VertexBand& vbB = bands.vertexBands[band.faceB];
    // The sides: on A from u to v; on B the corners at u and at v.
    const Point3 startU = bands.corner(rs, a), startV = bands.corner(rs, rs.faceNext(a));
    const Point3 endU = bands.corner(rs, rs.faceNext(b)), endV = bands.corner(rs, b);
    const Point3 sideDirection = ((startV - startU) + (endV - endU)).normalized();
    // Out of A's side, in A's plane; and out of B's side (v -> u on B), in B's plane.
    const Point3 outOfA = (startV - startU).cross(vbA.normal).normalized();
    const Point3 outOfB = (endU - endV).cross(vbB.normal).normalized();

    const Point3 meet = vbA.normal.cross(vbB.normal);
    const double planeAngle = degrees(std::asin(std::min(1.0, meet.norm())));
    const bool parallel = planeAngle < kParallelDegrees && vbA.normal.dot(vbB.normal) > 0;
    Point3 across = sideDirection;  // the direction the Hermite rails leave their planes across
    if (parallel) {
      band.kind = BandCase::ParallelPlanes;
    } else if (planeAngle < kParallelDegrees) {
      band.kind = BandCase::Bilinear;  // folded back on itself: no tangent sweep
    } else {
      const Point3 line = meet.normalized();
      const double offSides = degrees(std::acos(std::min(1.0, std::abs(line.dot(sideDirection)))));
      band.kind = offSides < kAlongBandDegrees ? BandCase::AlongIntersection : BandCase::Bilinear;
      across = line;
    }
    const auto rail = [&](const Point3& from, const Point3& to) {
      std::vector<Point3> points;
      if (band.kind == BandCase::Bilinear) {
        for (int i = 0; i <= samples; ++i) points.push_back(from + (to - from) * (static_cast<double>(i) / samples));
        return points;
      }
      // Tangent to A's plane across the sweep, leaving A; tangent to B's, entering B.
      Point3 leave = vbA.normal.cross(across).normalized();
      if (leave.dot(outOfA) < 0) leave = -leave;
      Point3 enter = vbB.normal.cross(across).normalized();
      if (enter.dot(outOfB) > 0) enter = -enter;
      const double chord = (to - from).norm();
      for (int i = 0; i <= samples; ++i) {
        points.push_back(hermite(from, leave * chord, to, enter * chord, static_cast<double>(i) / samples));
      }
      points.front() = from, points.back() = to;
      return points;
    };
    band.railU = rail(startU, endU);
    band.railV = rail(startV, endV);
  }
  return result;
}

}  // namespace rotafab::geometry
