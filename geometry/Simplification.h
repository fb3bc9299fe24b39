#pragma once
// A panel count the builders choose (`make --panels N`, docs/CONTRACT.md,
// "Command line"): the mesh is simplified to about N faces before anything is
// built, so that a scan of thousands of triangles becomes a job of the size the
// builders can cut and assemble (the dissertation's bunny, ch. VII, had 2,104
// panels, and the size of the job was its limit).
//
// Quadric edge collapse (Garland and Heckbert, "Surface Simplification Using
// Quadric Error Metrics", SIGGRAPH 1997) by OpenMesh's decimater: each step
// removes the edge whose collapse moves the surface least, one end onto the
// other (no new positions, so every vertex left is a point of the scanned
// surface). A collapse is refused where it would change the topology (the
// link condition of Dey, Edelsbrunner, Guha and Nekhayev 1999), flip a face,
// or leave a sliver, so the components, genus and boundary loops stay as they
// were; vertices on the boundary do not move at all.
//
// Polygon faces are split into triangles first: a polygon whose vertex moves
// is no longer planar, and a panel is cut for a planar face. The result is a
// triangle mesh (`make` merges coplanar faces before, not after, so that the
// count is the one asked).

#include "core/WorkContext.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct Simplification {
  int asked = 0;              // the faces asked for
  int facesBefore = 0;        // as given
  int facesAfter = 0;         // as left (may stay above `asked`: a collapse that would change the topology is refused)
  bool triangulated = false;  // polygon faces were split into triangles first
  [[nodiscard]] bool simplified() const { return facesAfter != facesBefore || triangulated; }
};

// Simplifies `mesh` (an oriented manifold: analyzeMesh() found no problem)
// to about `faces` faces; leaves it as it is when it has no more than that.
// The faces left keep their source face (a triangle of a split polygon, the
// polygon's), the vertices their source vertex. Reports progress as
// "simplify"; throws core::Cancelled, std::invalid_argument when `faces` < 1
// or when the surface would fold onto itself at that count.
Simplification simplifyMesh(PolygonMesh& mesh, int faces, const core::WorkContext& context);

// The triangles of one face (three vertex indices each, in the face's
// winding): ear clipping in the face's plane (Newell's normal), so that a
// simple polygon, convex or not, is covered exactly; a fan from the first
// corner where no ear is found (a polygon that crosses itself).
std::vector<std::array<int, 3>> faceTriangles(const PolygonMesh& mesh, int face);

}  // namespace rotafab::geometry
