#pragma once
// A band decomposition structure, end to end in geometry (dissertation ch. V):
// vertex bands (V.1-V.2), developable edge bands (V.3), unfolded panels
// (V.4), fastener holes, labels and flood-fill numbering (V.5). The output is
// one panel per input face, flat and ready for the planner, in assembly
// order, and the 3D surface of each for rendering (Structure.h).

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "core/WorkContext.h"
#include "geometry/Parameters.h"
#include "geometry/PolygonMesh.h"
#include "geometry/Structure.h"

namespace rotafab::geometry {

struct BandOptions {
  std::optional<double> tension;  // eq. 5.2's a for every dual face; Doo-Sabin per face when empty
  int samples = 8;                // segments along each band
  double fastener = 0.125;        // hole diameter, inches
  std::optional<int> start;       // flood-fill start face (file index); the lowest face when empty
  int up = 1;                     // the vertical axis for "lowest": 0 x, 1 y, 2 z
  bool scoreFolds = false;
  // A band without room for a fastener hole gets none and is glued
  // (Structure::glued), instead of NoRoomForHoleError: for when the size at
  // which every band would have room does not fit the bed.
  bool glueBandsWithoutRoom = false;
  ParameterNames names = parameterInWords;  // how messages name the parameters
};

// A panel that would overlap itself when unfolded, and whose band could be
// neither cut off nor cut across (ch. V.4): another size or fewer, larger
// panels may unfold it.
class UnfoldOverlapError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
  int panels = 1;  // how many fold
  // Where a mend of the design may unfold them (a weave's: the two
  // vertices of each folding panel's own edge, whose region a sliver beside
  // it made thin, MeshMending.h); empty where none is known to.
  std::vector<std::array<int, 2>> places;
};

// The mesh must be usable (analyzeMesh), already at construction size
// (inches). Throws InvalidMeshError, std::invalid_argument (a
// ParameterError for a parameter's value, NoRoomForHoleError when bands have
// no room for a hole, UnfoldOverlapError) with one line naming what cannot be built, and
// core::Cancelled. Progress: phase "geometry", steps "band decomposition"
// (of the faces), "panels split" (bands cut off, when there are any),
// "fastener holes" (of the bands), "labels" (of the panels).
Structure buildBandStructure(const PolygonMesh& mesh, const BandOptions& options, const core::WorkContext& context);

// The structure at the smallest size, from the mesh's, at which every band
// has room for its fastener (FastenerHoles.h, kLeastClearance): when some
// band has none, the mesh is scaled by what the bands without room ask
// (every length of the structure scales with it) and built again
// (growUntilRoom(), Structure.h; a hole may move to a tighter place on the
// larger band).
GrownStructure buildBandStructureWithRoom(PolygonMesh& mesh, const BandOptions& options,
                                          const core::WorkContext& context);

}  // namespace rotafab::geometry
