#pragma once
// The dual mesh (dissertation V.2, fig. 48): one dual vertex per face, at the
// face's centre of mass (the mean of its corners); one dual face per interior
// vertex, through the faces around it in rotation order, oriented like the
// primal. A boundary vertex gets no dual face (its fan does not close).

#include "geometry/PolygonMesh.h"
#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

struct DualMesh {
  PolygonMesh mesh;
  std::vector<int> primalVertexOfFace;  // dual face -> the primal vertex it surrounds
};

DualMesh dualMesh(const PolygonMesh& mesh, const RotationSystem& rs);

}  // namespace rotafab::geometry
