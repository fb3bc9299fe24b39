#pragma once
// Filling the holes of an open mesh (`--holes`, docs/CONTRACT.md, "make").
// Both ways walk each boundary loop in the rotation system (III.1.2's face
// tracing continued over the boundary), so that what closes it is oriented like the faces
// around it:
// - `fill` caps a loop with one polygon face;
// - `patch` closes it with triangles about as long as the loop's own edges,
//   (longer for a hole of thousands of corners: about 20,000 triangles
//   at most), after Liepa, "Filling holes in meshes" (SGP 2003): a least-area
//   triangulation of the loop, refined until no edge is much longer than
//   the loop's, its edges flipped towards Delaunay, and its new vertices
//   faired (umbrella smoothing with the loop held). A weave's ribbons run
//   from each edge towards its faces' centres, so one face across a wide or
//   bent hole makes its panels as wide as the hole, or folds it back over
//   its neighbours; a patch keeps them like the rest.

#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

// Caps every boundary loop with one face; returns how many. A cap has no
// face in the file: its `sourceFace` is -1 (the manifest says "cap"). The
// mesh must be an orientable manifold (analyzeMesh()); analyse it again after.
int fillHoles(PolygonMesh& mesh);

// Closes every boundary loop with a patch of triangles; returns how many
// loops. Its faces' `sourceFace` is -1 (caps, as above), its new vertices'
// `sourceVertex` -1. The same preconditions as fillHoles().
int patchHoles(PolygonMesh& mesh);

}  // namespace rotafab::geometry
