#pragma once
// Generalized corner cutting (dissertation V.1.1, eq. 5.1 and 5.2): every
// corner n of an N-sided face gets a new vertex v'_n = sum_m a_{n,m} v_m with
//   a_{n,n} = a,   a_{n,m} = (3 + 2 cos(2 (n - m) pi / N)) (1 - a) / (3N - 5).
// The tension `a` defaults per face to Doo-Sabin, a = 1/4 + 5 / (4N). Each old
// face becomes a smaller similar face, each interior edge a quadrilateral, each
// interior vertex a face with as many sides as its valence: the band
// decomposition of the surface (fig. 47). On an open mesh, boundary edges and
// boundary vertices get no face.
//
// Requires 0 < a < 1 (all coefficients positive, eq. 5.2); the dissertation
// advises a > 5/12 so that the smallest eigenvalue stays positive.

#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "geometry/PolygonMesh.h"
#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

// a = 1/4 + 5/(4N): Doo-Sabin for an N-sided face.
double dooSabinTension(int sides);

// The N x N matrix a_{n,m} of eq. 5.2. Throws std::invalid_argument unless
// N >= 3 and 0 < a < 1.
Eigen::MatrixXd cornerCuttingWeights(int sides, double tension);

struct CornerCutMesh {
  PolygonMesh mesh;
  std::vector<int> vertexOfDart;  // dart -> the new vertex at its origin's corner in its face (-1 on a boundary dart)
  std::vector<int> faceOfFace;    // old face -> its shrunken copy
  std::vector<int> faceOfEdge;    // old edge -> its quadrilateral (-1 on a boundary edge)
  std::vector<int> faceOfVertex;  // old vertex -> its face (-1 on a boundary vertex)
};

// `tension`: one value for every face, or Doo-Sabin per face when empty.
CornerCutMesh cornerCut(const PolygonMesh& mesh, const RotationSystem& rs,
                        std::optional<double> tension = std::nullopt);

}  // namespace rotafab::geometry
