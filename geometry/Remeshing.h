#pragma once
// Even panels for a panel count (`make --panels N`, docs/CONTRACT.md,
// "Command line"): the mesh remeshed to about N triangles of nearly even size
// and shape, so that no sliver decides the size of the whole structure (a
// band's room for its fastener is set by its narrowest face, ch. V.4).
//
// Isotropic remeshing after Botsch and Kobbelt, "A Remeshing Approach to
// Multiresolution Modeling", SGP 2004: for a target edge length L, repeat
// (1) split every edge longer than 4/3 L at its midpoint, (2) collapse every
// edge shorter than 4/5 L unless that makes an edge longer than 4/3 L,
// (3) flip edges toward valence 6 (4 on the boundary), (4) relax each vertex
// toward the area-weighted centroid of its neighbours within its tangent
// plane, (5) project it back onto the input surface. L is chosen from the
// surface's area so that equilateral triangles of side L would number N,
// then corrected from the count got until it is within a few percent.
//
// What the designer drew is kept: no collapse breaks the link condition (the
// genus, components and boundary stay), no collapse or flip turns a face by
// more than 60 degrees or cuts off a tip, the boundary and sharp creases
// (edges whose faces turn by more than 60 degrees) are features: their
// vertices move only along them, where they meet (corners) they do not
// move, and no flip crosses them. Tips (much angle deficit near a vertex)
// stay where they are, and a vertex on a ridge (an ear's rim) relaxes only
// along it: relaxed freely, both would shrink and no projection would bring
// them back. A feature finer than half the length (two creases side by
// side) is merged rather than kept with slivers. Last, the count is made
// the one asked by splitting the longest edges or collapsing the shortest,
// and the slivers left are collapsed or flipped away.

#include "core/WorkContext.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct Remeshing {
  int asked = 0;                 // the faces asked for
  int facesBefore = 0;           // as given
  int facesAfter = 0;            // as left
  bool remeshed = false;         // false: it had about the faces asked already (within kKeptAsDrawn), kept as drawn
  int creaseEdges = 0;           // of the input, kept as creases (its boundary not counted)
  int tips = 0;                  // points of much curvature (an ear's tip) kept where they were
  double largestMove = 0;        // the farthest a vertex of either surface lies from the other
  double smallestAreaRatio = 0;  // the smallest face's area over the median face's
};

// Within this share of the count asked, the mesh is kept as drawn.
inline constexpr double kKeptAsDrawn = 0.05;

// Remeshes `mesh` (an oriented manifold: analyzeMesh() found no problem) to
// about `faces` triangles of even size and shape. Each face keeps the source
// face of the input under its centre (a hole's cap stays -1); the vertices
// have no source vertex (they are new points of the surface). Reports
// progress as "remesh"; throws core::Cancelled, std::invalid_argument when
// `faces` < 1.
Remeshing remeshEvenly(PolygonMesh& mesh, int faces, const core::WorkContext& context);

}  // namespace rotafab::geometry
