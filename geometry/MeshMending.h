#pragma once
// Local mends of a design whose bands have no room for a fastener: rather
// than growing the whole structure until its narrowest band has room (a few
// slivers of a scan made CGAL's cow 338 in long), the short edge or the
// sliver face that makes the band narrow is collapsed into its neighbours,
// where that changes the surface least. A band's length is its edge's, and
// its width is set by the faces on either side (dissertation V.3-V.4): so
// of the band's own edge and the shortest edge of each of its two faces,
// the shortest that may go is collapsed to its midpoint; where none may (a
// collapse would fold a face over), the edge of a sliver beside it is
// flipped (its corners stay, its faces widen); where no flip widens them,
// the two faces beside the band are merged into one panel.
//
// An edge may go when the collapse keeps the topology (the link condition:
// its ends share no neighbour but the corners opposite it in its triangles),
// keeps the boundary where it is (an inner edge between two boundary
// vertices does not go), and turns no face by more than 60 degrees. The
// mend is a repair of the design, named and counted (MeshRepair's
// "collapse-short-edge", with the farthest it moved a vertex,
// "flip-narrow-band", with the farthest it moved the surface, and
// "merge-narrow-band").

#include <array>
#include <vector>

#include "geometry/MeshRepair.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct Mends {
  MeshRepair collapsed{"collapse-short-edge", 0, ""};
  MeshRepair flipped{"flip-narrow-band", 0, ""};
  MeshRepair merged{"merge-narrow-band", 0, ""};
  // Each kind, in the order made (collapses before flips before merges).
  [[nodiscard]] std::array<const MeshRepair*, 3> kinds() const { return {&collapsed, &flipped, &merged}; }
  [[nodiscard]] int count() const { return collapsed.count + flipped.count + merged.count; }
  // Those of a later round added: counts summed, the first kept, the farthest move kept.
  void add(const Mends& later);
};

// Whether `repair` is one of the mends above (a repair of the design, not of a broken mesh).
inline bool isMend(const MeshRepair& repair) {
  return repair.kind == "collapse-short-edge" || repair.kind == "flip-narrow-band" ||
         repair.kind == "merge-narrow-band";
}

// `--repair auto`'s last repair: each face of zero area (its corners
// collinear, as CAD programs' STL files have them) collapsed away, the
// nearer end of its shortest side that may go into the other (so no vertex
// moves but the one that goes, and the boundary keeps its place). Returns
// the repair, "collapse-degenerate-face", "first" naming the face in the
// file's numbering, `moved` the farthest a vertex went (in the mesh's units).
MeshRepair collapseDegenerateFaces(PolygonMesh& mesh);

// Collapses, for each edge of `places` (its two vertices in `mesh`), the
// shortest edge that may go among it and the shortest of each face beside
// it; where none may, the flip of it or of the longest side of a face
// beside it that most widens the thinner of its two triangles (toward the
// Delaunay triangulation, keeping the vertices where they are); where none
// widens them (and `merges`), the two faces beside it become one, if they
// turn from each other by less than 30 degrees (its band is gone: the panel
// bends there instead); where none may, the shortest edge that may go of
// the faces beside it, then of the edges at its ends (a thin tube's ring or
// a flap's rim, where the link condition or a face turned over keeps the
// nearer ones), none longer than the mesh's mean edge. An edge whose
// vertex an earlier mend of this call moved waits for the next call. Faces left with fewer than three corners
// go, and vertices no face uses. Returns the mends (count 0: none could be
// made), each "first" naming the first edge by its vertices in the file's
// numbering.
// With `flipsFirst`, the flip is tried before any collapse: a flip keeps
// every vertex where it is, and a weave's crossing has room as its edge's
// region is wide (its two face centres far from the edge, eq. 4.2-4.11),
// which a flip toward the Delaunay triangulation gives it.
Mends mendNarrowPlaces(PolygonMesh& mesh, const std::vector<std::array<int, 2>>& places, bool merges = true,
                       bool flipsFirst = false);

}  // namespace rotafab::geometry
