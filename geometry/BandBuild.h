#pragma once
// The band structure's build, shared by its two halves: BandStructure.cpp
// (the decomposition, the panels unfolded and mended, the edges numbered,
// the holes) and BandPanels.cpp (each panel whole: its outline, holes,
// labels and folds). Internal to geometry/: BandStructure.h is the interface.

#include <fmt/format.h>

#include <string>
#include <vector>

#include "geometry/BandDecomposition.h"
#include "geometry/BandStructure.h"
#include "geometry/DevelopableBands.h"
#include "geometry/FastenerHoles.h"
#include "geometry/FloodFill.h"
#include "geometry/HersheyFont.h"
#include "geometry/PanelUnfolding.h"
#include "geometry/RotationSystem.h"

namespace rotafab::geometry::band {

// One build's shared state (V.1-V.3): the band decomposition of the mesh,
// its developable bands, each face's panel unfolded, and the flood fill's
// order; the edges numbered once the overlaps are mended.
struct BandBuild {
  BandBuild(const PolygonMesh& mesh, const BandOptions& options) : mesh(mesh), options(options) {}

  const PolygonMesh& mesh;
  const BandOptions& options;
  RotationSystem rs;
  BandDecomposition decomposition;
  std::vector<EdgeBand> bands;
  std::vector<FlatPanel> flat;
  FloodFillOrder order;
  std::vector<int> edgeNumber;  // per edge, in the order the flood fill meets them; 0 for a boundary edge

  // Faces as a user finds them in the file; a face capping a hole (--holes fill) has no number there.
  [[nodiscard]] std::string faceName(int f) const {
    return mesh.sourceFaceIndex(f) >= 0 ? fmt::format("face {}", mesh.sourceFaceIndex(f))
                                        : std::string("the face filling a hole");
  }
  // The error with the vertices of its bands' edges in the mesh (not the file's numbers).
  [[nodiscard]] NoRoomForHoleError withPlaces(NoRoomForHoleError error) const {
    error.places.clear();
    for (int e : error.edges) error.places.push_back({rs.origin(2 * e), rs.target(2 * e)});
    return error;
  }
  // Edges as a user finds them in the file: by their two vertices.
  [[nodiscard]] std::string edgeName(int e) const {
    return fmt::format("the edge between vertices {} and {}", mesh.sourceVertexIndex(rs.origin(2 * e)),
                       mesh.sourceVertexIndex(rs.target(2 * e)));
  }
};

// A label that fits nowhere even at kSmallestLabel, and the edge whose band
// (or, for a panel's number, one of whose bands) the design could be
// mended at to give it room.
struct Unetched {
  std::string what;  // "edge 12 on panel 3", "piece 3a", "panel number 3"
  int edge = -1;
};

// Panel `number` (from 0) of the flood fill's order whole: its bands,
// holes, labels and folds to score; the labels that fit nowhere go in
// `unetched`.
Panel bandPanel(const BandBuild& b, const std::vector<BandHoles>& holes, const HersheyFont& font, int number,
                std::vector<Unetched>& unetched);

// Labels that fit nowhere: the bands they belong to have no room
// (NoRoomForHoleError::forLabels(), mended or refused as bands without room
// for a hole are: a builder finds the matching panel by its numbers,
// dissertation V.5); where the user asked for glue instead of mending, a
// warning in `result`.
void refuseUnetched(const BandBuild& b, const std::vector<std::vector<Unetched>>& unetchedOf, Structure& result);

}  // namespace rotafab::geometry::band
