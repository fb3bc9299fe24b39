#include "geometry/DualMesh.h"

namespace rotafab::geometry {

DualMesh dualMesh(const PolygonMesh& mesh, const RotationSystem& rs) {
  DualMesh dual;
  dual.mesh.positions.reserve(mesh.faces.size());
  for (int f = 0; f < mesh.faceCount(); ++f) dual.mesh.positions.push_back(faceCentroid(mesh, f));
  for (int v = 0; v < mesh.vertexCount(); ++v) {
    if (rs.isBoundaryVertex(v)) continue;
    // Counter-clockwise around v keeps the primal's orientation.
    std::vector<int> face;
    for (Dart d : rs.dartsAround(v)) face.push_back(rs.face(d));
    dual.mesh.faces.push_back(std::move(face));
    dual.primalVertexOfFace.push_back(v);
  }
  return dual;
}

}  // namespace rotafab::geometry
