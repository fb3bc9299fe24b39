#include "geometry/CornerCutting.h"

#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rotafab::geometry {

double dooSabinTension(int sides) { return 0.25 + 5.0 / (4.0 * sides); }

Eigen::MatrixXd cornerCuttingWeights(int sides, double tension) {
  if (sides < 3)
    throw std::invalid_argument(fmt::format("corner cutting needs a face of 3 or more sides, not {}", sides));
  if (!(tension > 0.0 && tension < 1.0)) {
    throw std::invalid_argument(
        fmt::format("the tension a must lie strictly between 0 and 1 (eq. 5.2), not {}", tension));
  }
  Eigen::MatrixXd weights(sides, sides);
  for (int n = 0; n < sides; ++n) {
    for (int m = 0; m < sides; ++m) {
      const double M = 3.0 + 2.0 * std::cos(2.0 * (n - m) * std::numbers::pi / sides);
      weights(n, m) = n == m ? tension : M * (1.0 - tension) / (3.0 * sides - 5.0);
    }
  }
  return weights;
}

CornerCutMesh cornerCut(const PolygonMesh& mesh, const RotationSystem& rs, std::optional<double> tension) {
  CornerCutMesh result;
  result.vertexOfDart.assign(rs.dartCount(), -1);
  // Step 1 (eq. 5.1): a new vertex per corner; the corner of face f at origin(d) is dart d.
  for (int f = 0; f < mesh.faceCount(); ++f) {
    const auto& face = mesh.faces[f];
    const int sides = static_cast<int>(face.size());
    const Eigen::MatrixXd weights = cornerCuttingWeights(sides, tension.value_or(dooSabinTension(sides)));
    std::vector<int> shrunk;
    Dart corner = rs.faceDart(f);  // leaves face[0]; faceNext follows the face's corners
    for (int n = 0; n < sides; ++n, corner = rs.faceNext(corner)) {
      Point3 p = Point3::Zero();
      for (int m = 0; m < sides; ++m) p += weights(n, m) * mesh.positions[face[m]];
      const int vertex = result.mesh.vertexCount();
      result.mesh.positions.push_back(p);
      result.vertexOfDart[corner] = vertex;
      shrunk.push_back(vertex);
    }
    // Step 2: the shrunken copy of the face.
    result.faceOfFace.push_back(result.mesh.faceCount());
    result.mesh.faces.push_back(std::move(shrunk));
  }
  // Edge quads, reversed along the shared sides of the two face copies.
  result.faceOfEdge.assign(rs.edgeCount(), -1);
  for (int e = 0; e < rs.edgeCount(); ++e) {
    if (rs.isBoundaryEdge(e)) continue;
    const Dart h = 2 * e, g = 2 * e + 1;
    result.faceOfEdge[e] = result.mesh.faceCount();
    result.mesh.faces.push_back({result.vertexOfDart[rs.faceNext(h)], result.vertexOfDart[h],
                                 result.vertexOfDart[rs.faceNext(g)], result.vertexOfDart[g]});
  }
  // Step 3: a face per interior vertex through its corners, counter-clockwise.
  result.faceOfVertex.assign(mesh.positions.size(), -1);
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (rs.isBoundaryVertex(v)) continue;
    std::vector<int> face;
    for (Dart d : rs.dartsAround(v)) face.push_back(result.vertexOfDart[d]);
    result.faceOfVertex[v] = result.mesh.faceCount();
    result.mesh.faces.push_back(std::move(face));
  }
  return result;
}

}  // namespace rotafab::geometry
