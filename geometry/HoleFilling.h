#pragma once
// Filling the holes of an open mesh (SPEC `--holes fill`): each boundary
// loop is capped by one polygon face, along the loop's own walk in the
// rotation system (III.1.2's face tracing continued over the boundary), so
// that the cap is oriented like the faces around it.

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// Caps every boundary loop; returns how many. A cap has no face in the file:
// its `sourceFace` is -1 (the manifest says "cap"). The mesh must be an
// orientable manifold (analyzeMesh()); analyse it again after.
int fillHoles(PolygonMesh& mesh);

}  // namespace rotafab::geometry
