#pragma once
// Developable edge bands (dissertation V.3). The corner-cut edge band is a
// quadrilateral in space, rarely planar; it becomes a strip between two
// rails, sampled at the same parameters, cut into triangles: a polyhedral
// surface, so it unfolds exactly (V.4). Rail U runs from the corner at the
// edge's origin u on the first face's vertex band to the corner at u on the
// second's, rail V likewise at the other end v. Its ends are the two vertex
// bands' sides, so a band joins its vertex bands without a step.
//
// The three cases of V.3 decide the rails' shape. Let n_A, n_B be the two
// vertex bands' normals and D the mean direction of their two sides:
//   1. the planes are parallel (angle below kParallelDegrees): Hermite
//      rails leaving each plane along it, across D;
//   2. the planes meet along a line L at an angle to D below
//      kAlongBandDegrees: Hermite rails leaving each plane along it,
//      across L (so that the band is tangent to both planes, a smooth
//      transition, as the dissertation's sweep of a segment parallel to L);
//   3. otherwise: straight rails, the bilinear patch of the two sides as a
//      strip of thin triangles (no segment is parallel to both planes, so
//      a tangent sweep would run along the sides).
// A Hermite rail starts and ends with a tangent as long as the chord between
// its ends (the usual cardinal choice), pointing out of the first vertex
// band and into the second, so that the band never folds back over them.

#include <vector>

#include "geometry/BandDecomposition.h"

namespace rotafab::geometry {

// V.3's thresholds: planes nearer parallel than this are case 1; an
// intersection line nearer the sides' direction than this is case 2. A
// Hermite rail leaves its plane across L, so up to this angle off the
// side's normal: past 20 degrees the rails of a short band would lean
// along it.
constexpr double kParallelDegrees = 1.0;
constexpr double kAlongBandDegrees = 20.0;

enum class BandCase { ParallelPlanes = 1, AlongIntersection = 2, Bilinear = 3 };

struct EdgeBand {
  int edge = -1;
  int faceA = -1, faceB = -1;  // the faces on the left of darts 2e (u -> v) and 2e + 1 (v -> u)
  BandCase kind = BandCase::Bilinear;
  std::vector<Point3> railU, railV;  // from face A's side to face B's, samples + 1 points each

  // The triangles of the strip, as indices into the points railU[0..k],
  // railV[0..k] numbered 0..k and k+1..2k+1: quad i is (U_i, V_i, U_i+1) and
  // (V_i, V_i+1, U_i+1). Both copies of the band use these same triangles.
  [[nodiscard]] std::vector<std::array<int, 3>> triangles() const;
  [[nodiscard]] const Point3& point(int index) const;
  [[nodiscard]] int segments() const { return static_cast<int>(railU.size()) - 1; }
};

// One band per interior edge (indexed by edge; boundary edges have edge = -1
// and no rails). `samples`: segments along each rail (at least 1).
std::vector<EdgeBand> developableBands(const RotationSystem& rs, const BandDecomposition& bands, int samples = 8);

}  // namespace rotafab::geometry
