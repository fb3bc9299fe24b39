#pragma once
// Fastener holes on the edge bands (dissertation V.5). The two copies of a
// band overlap in the structure and are fastened through holes of the
// fastener's diameter, placed adaptively: two along a long thin band, two
// across a wide short one, one on a band too small for two.
//
// A hole is a point of the band's surface, its triangle and barycentric
// coordinates: both copies are developments of the same triangles
// (PanelUnfolding.h), so the hole is at the same place in space on both,
// and the holes of a band are the same distance apart on both panels.
//
// Clearance: every hole's centre at least kClearance diameters from the cut
// outline of each panel it is on, and from any other hole's centre on that
// panel at least that plus one diameter (the same 1.5 diameters of material
// between their rims). Among the layouts that keep it, the one that spreads
// the holes widest. A band too narrow for that (at the default scale, a
// mean edge of 2 in, a few of the bunny's 5511 bands and every band of a
// cube are about 1/3 in wide, under 3 diameters of a 1/8 in fastener) gets
// one hole where it keeps the most clearance, if that is at least
// kLeastClearance diameters; the caller warns (BandHoles::clearance, which
// counts the outlines only). That least clearance is measured on the same
// scale against outlines and other holes: from another hole's centre, at
// least kLeastClearance / kClearance of (kClearance + 1) diameters.
// "Each part it is on": a band cut off its panel (detachBand()) is a part
// of its own, with its piece's outline and its tab's hole. A band cut
// across its middle (halveBand()) has one hole of its length on each half,
// or none at all.

#include <array>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/WorkContext.h"
#include "geometry/PanelUnfolding.h"
#include "geometry/Parameters.h"

namespace rotafab::geometry {

// Chipboard tears where less than a diameter of it is left between a hole's
// centre and the edge (a web of half a diameter): no hole is drawn nearer.
constexpr double kClearance = 1.5, kLeastClearance = 1.0;
// How much larger each attempt makes a structure whose labels have no room
// (NoRoomForHoleError::forLabels()): labels keep their smallest height as
// everything else grows, so the room needed is not known ahead.
constexpr double kLabelGrowth = 1.1;

// A point of an edge band: a triangle (EdgeBand::triangles() indices) and weights.
struct BandPoint {
  std::array<int, 3> corners{};
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();

  [[nodiscard]] Point3 inSpace(const EdgeBand& band) const;
  [[nodiscard]] Point2 onPanel(const FlatBand& copy) const;
};

enum class HoleLayout { Along, Across, Single };

struct BandHoles {
  int edge = -1;
  HoleLayout layout = HoleLayout::Single;
  std::vector<BandPoint> holes;   // one fastener each
  double clearance = kClearance;  // diameters kept from the outlines, when less than kClearance
  bool glued = false;             // no room for a hole (placeFastenerHoles()'s `glueWithoutRoom`): no holes
};

// Bands too small for even one hole kLeastClearance from their outlines.
// Every length of the structure scales with the mesh, so the mesh
// `scaleNeeded` times larger, or the fastener that many times smaller,
// gives every one of them room.
class NoRoomForHoleError : public std::invalid_argument {
 public:
  NoRoomForHoleError(std::string firstBand, int bands, double scaleNeeded, double diameter,
                     const ParameterNames& names = parameterInWords);
  // Bands whose holes have room but whose numbers fit nowhere on their
  // panels, even at the smallest legible height (PanelLabels.h): a larger
  // size gives them room (by kLabelGrowth each attempt, an estimate), a
  // smaller fastener may not.
  static NoRoomForHoleError forLabels(std::string firstBand, int bands, const ParameterNames& names = parameterInWords);
  std::string bandsWithoutRoom;  // "EDGE: its band (L x W in) has no room for ... (nor have N other bands)"
  double scaleNeeded;            // > 1; infinite when a band's middle is off its panel
  int bands;                     // how many have no room
  bool estimate = false;         // scaleNeeded may not be enough (a tab's room stops growing)
  bool labels = false;           // the bands' numbers have no room (forLabels()), not their holes
  std::vector<double> scales;    // what each band without room needs, scaleNeeded the largest
  std::vector<int> edges;        // the edge numbers of the bands without room, as `placeFastenerHoles` has them
  // Their edges' two vertices in the mesh built (filled by the structure's
  // builder), for mending the design there (MeshMending.h).
  std::vector<std::array<int, 2>> places;
};

// One entry per edge (boundary edges: edge -1, no holes). `panels` indexed
// by face. Throws NoRoomForHoleError naming the first edge (by `edgeName`)
// when some band has no room for even one hole kLeastClearance from its
// outlines (with `glueWithoutRoom`, such a band has no holes and is marked
// glued instead), and core::Cancelled. The bands are shared out on the context's
// executor; the result does not depend on how many threads it has.
std::vector<BandHoles> placeFastenerHoles(
    const std::vector<EdgeBand>& bands, const std::vector<FlatPanel>& panels, double diameter,
    const core::WorkContext& context,
    const std::function<std::string(int)>& edgeName = [](int e) { return "edge " + std::to_string(e); },
    const ParameterNames& names = parameterInWords, bool glueWithoutRoom = false);

// The outline that point `at` of a copy of a band is cut with: its panel's,
// or that of the piece it is on (FlatBand::onPiece()).
const std::vector<Point2>& cutOutline(const FlatPanel& panel, const FlatBand& copy, const Point2& at);

// The copy of edge `edge`'s band on `panel`, or nullptr.
const FlatBand* bandCopy(const FlatPanel& panel, int edge);

}  // namespace rotafab::geometry
