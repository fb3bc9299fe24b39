#pragma once
// The projection method's edge regions (dissertation IV.1.2, eq. 4.12-4.16):
// each edge's region, the quadrilateral of its two end vertices and the
// centres of its two faces, projected onto the plane through the edge's
// midpoint with normal N_e, where the woven ribbons' quadrilaterals are
// cut (docs/WEAVE.md, 1.2-1.5).
//
// Readings (docs/WEAVE.md, A4 and A5): eq. 4.13 averages the two faces'
// unit normals and calls the result unit, which it is not, and the edge
// lies in the plane only when N_e is normal to it; so N_e is the sum of
// the two faces' Newell normals with its component along the edge taken
// out, normalised. Eq. 4.15-4.16 give the projected centres relative to
// the midpoint; here they are points.

#include <array>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/PolygonMesh.h"
#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

struct EdgeRegion {
  Point3 midpoint;  // P_m (4.12)
  Point3 normal;    // N_e, unit, normal to the edge
  // The projected region's corners: the edge's ends (in the plane
  // already), and the centres (4.1) of the faces on the left and right of
  // dart 2e seen from outside, projected (4.15, 4.16).
  Point3 start, end, leftCentre, rightCentre;

  // The region's bilinear map (docs/WEAVE.md, 1.5): (0,0) the start,
  // (1,1) the end, (0,1) the left centre, (1,0) the right centre; the edge
  // is the diagonal s = u.
  [[nodiscard]] Point3 at(double s, double u) const {
    return (1 - s) * (1 - u) * start + s * (1 - u) * rightCentre + (1 - s) * u * leftCentre + s * u * end;
  }
};

// An edge whose two faces fold back onto each other (their normals' sum
// has nothing across the edge: no plane to project on); the faces' indices.
class FoldedEdgeError : public std::invalid_argument {
 public:
  FoldedEdgeError(const std::string& what, int leftFace, int rightFace, std::array<int, 2> ends)
      : std::invalid_argument(what), leftFace(leftFace), rightFace(rightFace), ends(ends) {}
  int leftFace, rightFace;
  std::array<int, 2> ends;  // the edge's two vertices
};

// Per edge of `rs` (built from `mesh`). Throws FoldedEdgeError naming the
// edge when its two faces fold back onto each other, std::invalid_argument
// when it lies on a boundary.
std::vector<EdgeRegion> edgeRegions(const PolygonMesh& mesh, const RotationSystem& rs);

}  // namespace rotafab::geometry
