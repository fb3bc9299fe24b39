#include "geometry/DualMesh.h"

namespace rotafab::geometry {

DualMesh dualMesh(const PolygonMesh& mesh, const RotationSystem& rs) {
  DualMesh dual;
  dual.mesh.positions.reserve(mesh.faces.size());
  for (int f = 0; f < mesh.faceCount(); ++f) dual.mesh.positions.push_back(faceCentroid(mesh, f));
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (rs.isBoundaryVertex(v)) continue;
    // rotateBack turns counter-clockwise seen from outside, so the faces come
    // in the order that keeps the primal's orientation.
    std::vector<int> face;
    const Dart first = rs.dartFrom(v);
    Dart d = first;
    do {
      face.push_back(rs.face(d));
      d = rs.rotateBack(d);
    } while (d != first);
    dual.mesh.faces.push_back(std::move(face));
    dual.primalVertexOfFace.push_back(v);
  }
  return dual;
}

}  // namespace rotafab::geometry
