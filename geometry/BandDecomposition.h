#pragma once
// The band decomposition of a surface (dissertation V.1-V.2): generalized
// corner cutting (eq. 5.1, 5.2) applied to the dual mesh. Each dual vertex
// (= input face f) becomes a vertex band, a polygon with one corner per
// corner of f; each dual edge (= interior input edge) becomes an edge band
// joining the two vertex bands across it; each dual face (= input vertex)
// becomes a gap.
//
// The corner of face f's vertex band at its corner vertex x is corner n of
// x's dual face (the centroids of the faces around x, in rotation order):
// sum_m a_{n,m} c_m, eq. 5.1 with the weights of eq. 5.2 for that dual face.
// The vertex band is then projected onto its least-squares plane (V.2), with
// the plane's normal on the side about which the band's corners turn
// counter-clockwise (its Newell normal; the face's when the band has no
// area), so that every band is counter-clockwise seen from outside: the
// eigenvector's sign alone would mirror some bands.
//
// Open meshes (`--holes keep`, docs/CONTRACT.md, "make"): a boundary vertex
// has no closed dual face; its dual polygon is the fan's centroids closed through the
// midpoints of its two boundary edges and the vertex itself (the usual
// dual with boundary), so every face, boundary or not, gets a whole vertex
// band; boundary edges get no edge band.

#include <optional>
#include <vector>

#include "geometry/PolygonMesh.h"
#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

struct VertexBand {
  std::vector<Point3> corners;  // planar, one per corner of the face, in the face's order
  Point3 normal;                // unit, outward: the corners run counter-clockwise about it
  Point3 centroid;              // of the corners, on the plane
};

struct BandDecomposition {
  std::vector<VertexBand> vertexBands;  // one per input face
  // Dart d (face(d) >= 0) -> the index of the corner of face(d)'s vertex band at origin(d).
  std::vector<int> cornerOfDart;
  // The largest distance a corner moved onto its plane, over all bands (how far from planar corner cutting left them).
  double largestProjection = 0;

  [[nodiscard]] const Point3& corner(const RotationSystem& rs, Dart d) const {
    return vertexBands[rs.face(d)].corners[cornerOfDart[d]];
  }
};

// `tension`: the tension a of eq. 5.2 for every dual face, or Doo-Sabin per
// dual face (a = 1/4 + 5/(4N)) when empty. Throws std::invalid_argument
// unless 0 < a < 1.
BandDecomposition bandDecomposition(const PolygonMesh& mesh, const RotationSystem& rs,
                                    std::optional<double> tension = std::nullopt);

// The unit normal of a polygon by Newell's method (the direction about which
// it turns counter-clockwise); zero for a degenerate polygon.
Point3 newellNormal(const std::vector<Point3>& polygon);
// The Newell normal of a mesh face.
Point3 faceNormal(const PolygonMesh& mesh, int face);

}  // namespace rotafab::geometry
