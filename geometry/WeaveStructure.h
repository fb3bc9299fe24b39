#pragma once
// A plain-woven structure, end to end in geometry (dissertation ch. IV): the
// threads of face tracing with twisted edges (III.1.2, IV.1), the
// projection method's ribbons (IV.1-IV.2), cut into down-up-down panels and
// unfolded (IV.3-IV.4), with two fastener holes at each crossing through
// its three panels, the edge numbers etched at both ends and the middle and
// the neighbouring edge's underlined (IV.4, fig. 39-43). Panels come thread
// by thread, each thread's in its order: the order to assemble them in
// (docs/WEAVE.md).

#include <vector>

#include "core/WorkContext.h"
#include "geometry/BandStructure.h"
#include "geometry/Parameters.h"
#include "geometry/PolygonMesh.h"
#include "geometry/Structure.h"
#include "geometry/WeaveRibbons.h"

namespace rotafab::geometry {

// Offsets above this share of the mean edge are warned of (ribbons over
// and under a crossing that far apart do not hold each other).
inline constexpr double kMostOffsetPerEdge = 0.1;

struct WeaveOptions {
  WeaveCycles cycles = WeaveCycles::All;
  RibbonShape shape;
  // Narrow the ribbons edge by edge where at the shape's width they would
  // pass through each other (narrowUntilClear()); else keep the width and
  // warn of them.
  bool narrowWhereRibbonsMeet = true;
  double fastener = 0.125;  // hole diameter, inches
  // Glue every crossing without room for its holes (with a warning), and
  // leave off the labels that fit nowhere (warned of), rather than throw
  // NoRoomForHoleError: --glue-narrow, and the measuring build of --size.
  bool glueCrossingsWithoutRoom = false;
  int up = 1;  // the vertical axis for "lowest": 0 x, 1 y, 2 z
  ParameterNames names = parameterInWords;
};

// The mesh must be usable (analyzeMesh) and closed, already at construction
// size (inches). Edge numbers are panel numbers: panel k goes over edge k.
// The first thread is the one over the lowest crossing, then each time the
// thread that crosses most of the threads placed; each from its lowest
// crossing over onwards. Throws InvalidMeshError or std::invalid_argument
// (NoRoomForHoleError when a crossing has no room for even one hole, or a
// label of it none on its ribbon, with the mesh vertices of those
// crossings' edges in `places`; UnfoldOverlapError when a panel would fold
// over itself even cut in three) with one line, and core::Cancelled. Progress: phase "geometry", steps "weaving
// threads", "ribbons", "crossing holes" (of the crossings), "labels" (of the
// panels).
Structure buildWeaveStructure(const PolygonMesh& mesh, const WeaveOptions& options, const core::WorkContext& context);

// As buildBandStructureWithRoom(): the mesh grown until every crossing has
// room for its holes (growUntilRoom, Structure.h).
GrownStructure buildWeaveStructureWithRoom(PolygonMesh& mesh, const WeaveOptions& options,
                                           const core::WorkContext& context);

// The steps of building a woven structure panel by panel in id order: each
// crossing (edge k: panel k over it, two panels under it, each with two
// holes of edge k) is fastened, with its two fasteners through its three
// panels, at the step of the last of them. The join names the panel that
// goes over (or, at the over panel's own step, the first panel under).
std::vector<AssemblyStep> weaveSteps(const std::vector<Panel>& panels);

}  // namespace rotafab::geometry
