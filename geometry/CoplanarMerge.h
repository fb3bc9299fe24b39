#pragma once
// Faces as the designer meant them: an STL holds triangles only, so a cube
// comes as 12 triangles and would be built as 12 panels. Adjacent faces that
// lie within an angle of one plane are merged into one polygon face, where
// the merged face is a simple polygon (a region that would have a hole, or
// pinch at a vertex, or fold over itself in the plane, is left as it is).
//
// A region grows from a seed face (in face order) across shared edges to
// faces whose normal is within the angle of the seed's, so that every face
// of a region is within the angle of one plane, the seed's. A vertex inside
// a merged region goes, and so does one left on a straight side between just
// two merged faces; every other vertex on an outline is kept (a neighbour
// shares it).

#include <unordered_map>

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct CoplanarMerge {
  int facesBefore = 0;
  int facesAfter = 0;
  int regions = 0;       // merged faces made of more than one face
  int straightened = 0;  // vertices taken out of straight sides between two merged faces
  // A face merged into another, by source index: the source index of the merged face (its seed's).
  std::unordered_map<int, int> mergedInto;
};

// The mesh must be an oriented manifold (analyzeMesh() has found no
// problem); `degrees` > 0. Merged faces keep their seed's source index.
CoplanarMerge mergeCoplanarFaces(PolygonMesh& mesh, double degrees);

}  // namespace rotafab::geometry
