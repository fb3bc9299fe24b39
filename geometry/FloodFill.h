#pragma once
// Flood-fill numbering (dissertation V.5): the panels are numbered, cut and
// assembled in breadth-first order over the faces, from a start face, so
// that neighbours get numbers close to each other and the builders join
// each panel to ones already placed. Neighbours are across interior edges,
// visited in each face's own corner order (deterministic for a given mesh).
// A mesh of several pieces goes on from the lowest face not yet reached.

#include <vector>

#include "geometry/RotationSystem.h"

namespace rotafab::geometry {

// The face whose centroid is lowest along `up` (0 x, 1 y, 2 z), the first on a tie:
// the base the structure is built up from.
int lowestFace(const PolygonMesh& mesh, int up);

struct FloodFillOrder {
  std::vector<int> faceOfPanel;  // panel number - 1 -> face
  std::vector<int> panelOfFace;  // face -> panel number - 1
};

// Throws std::invalid_argument when `start` is not a face of the mesh.
FloodFillOrder floodFill(const PolygonMesh& mesh, const RotationSystem& rs, int start, int up);

}  // namespace rotafab::geometry
