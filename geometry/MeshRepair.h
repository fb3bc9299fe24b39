#pragma once
// The repairs that make a mesh from the wild buildable (`make --repair
// auto`), each named and counted with where the first one is, as the file
// numbers its elements. In this order:
//
//   weld                    vertices within a tolerance relative to the
//                           mesh's size (1e-6 of its box's diagonal) become one
//                           (identical positions are welded on import); faces
//                           that collapse with them go: drop-collapsed-face
//   drop-duplicate-face     a face that runs through the same corners as an
//                           earlier one, in either direction
//   split-nonmanifold-edge  an edge of more than two faces is cut open; the
//                           faces that meet around each end of it in one fan
//                           keep a common copy of that end, so each sheet of
//                           faces keeps its own edge and is closed again there
//                           where it wraps around the ends (two solids that
//                           touch along an edge); where it does not (a wall
//                           inside a solid), the sides stay open, and are
//                           counted (leftOpen)
//   split-bowtie            a vertex whose faces form several fans (surfaces
//                           touching at a point) gets one copy per fan
//   collapse-degenerate-face  a face of zero area (collinear corners, as in
//                           CAD programs' STLs) is collapsed away, its
//                           shortest side's nearer end into the other
//                           (MeshMending.h)
//
// The orientation (consistent, and outward on closed components) is then
// made by analyzeMesh() (MeshAnalysis.h), and orientRepair() names it. What
// cannot be repaired (a non-orientable surface, a face that visits a vertex
// twice, an edge still shared by three faces after the cut) stays a problem
// of the analysis.

#include <string>
#include <vector>

#include "core/LengthUnit.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/PolygonMesh.h"

namespace rotafab::geometry {

struct MeshRepair {
  std::string kind;   // as above: the manifest's "repairs"[].kind (docs/CONTRACT.md, "manifest.json (version 1)")
  int count = 0;      // of the elements repaired
  std::string first;  // "vertex 44", "edge (12, 57)", "face 9" (the file's numbering)
  int leftOpen = 0;   // split-nonmanifold-edge: edge sides that no other face closes (an inner wall's)
  double moved = 0;   // a mend of the design (MeshMending.h): the farthest a vertex moved, inches

  // One line for people: "split 2 bow-tie vertices (the first: vertex 44)".
  [[nodiscard]] std::string line(core::LengthUnit unit = {}) const;
};

// Repairs the mesh in place (before analyzeMesh); the repairs made, in order
// (none: empty). Vertex copies keep the source index of the vertex they copy.
std::vector<MeshRepair> repairMesh(PolygonMesh& mesh);

// What repairMesh() would do to a copy of the mesh, and the analysis of
// the result (for `inspect`).
struct RepairPreview {
  std::vector<MeshRepair> repairs;
  MeshAnalysis after;
};
RepairPreview previewRepair(PolygonMesh copy);

// The faces analyzeMesh() reversed, as a repair record ("orient"); empty
// kind when it reversed none.
MeshRepair orientRepair(const MeshAnalysis& analysis, const PolygonMesh& mesh);

}  // namespace rotafab::geometry
