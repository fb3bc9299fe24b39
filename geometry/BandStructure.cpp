#include "geometry/BandStructure.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "geometry/BandBuild.h"
#include "geometry/BandDecomposition.h"
#include "geometry/DevelopableBands.h"
#include "geometry/FastenerHoles.h"
#include "geometry/FloodFill.h"
#include "geometry/PanelUnfolding.h"

namespace rotafab::geometry {

using band::BandBuild;
using band::bandPanel;
using band::refuseUnetched;
using band::Unetched;

namespace {

// The point of a convex polygon where `room` is largest, and that room: a
// grid over its box, then a pattern search around the best point.
template <class Room>
std::pair<Point2, double> mostRoomIn(const std::vector<Point2>& polygon, const Room& room) {
  Eigen::AlignedBox2d box;
  for (const Point2& p : polygon) box.extend(p);
  Point2 best = Point2::Zero();
  for (const Point2& p : polygon) best += p;
  best /= static_cast<double>(polygon.size());
  double most = room(best);
  constexpr int kGrid = 16;
  for (int a = 1; a < kGrid; ++a) {
    for (int b = 1; b < kGrid; ++b) {
      const Point2 p = box.min() + box.sizes().cwiseProduct(Point2(a, b) / kGrid);
      if (const double r = room(p); r > most) most = r, best = p;
    }
  }
  for (double step = box.sizes().maxCoeff() / kGrid; step > 1e-4 * box.sizes().maxCoeff(); step /= 2) {
    for (bool moved = true; moved;) {
      moved = false;
      for (const Point2& d : {Point2(step, 0), Point2(-step, 0), Point2(0, step), Point2(0, -step)}) {
        if (const double r = room(best + d); r > most) most = r, best += d, moved = true;
      }
    }
  }
  return {best, most};
}

// Faces whose panels would overlap themselves however their bands are cut
// (buildOnce()): each is split in two and the structure built again.
struct FacesToSplit {
  std::vector<int> faces;
  std::string firstError;
};

// Splits `face` in two along the diagonal that leaves the parts most nearly
// convex (the fewest reflex corners, then the most even areas), in the
// face's own plane (Newell's normal): the last remedy of a panel that would
// overlap itself (V.4), the vertex band in two parts, joined again by the
// band of the new edge and its fasteners. The second part is a new face from
// the same face of the file. False when the face has no such diagonal (a
// triangle, or a face crossing itself).
bool splitFaceInTwo(PolygonMesh& mesh, int face) {
  const std::vector<int> corners = mesh.faces[face];
  const int n = static_cast<int>(corners.size());
  if (n < 4) return false;
  std::vector<Point3> polygon;
  for (int v : corners) polygon.push_back(mesh.positions[v]);
  const Point3 normal = newellNormal(polygon);
  if (normal.isZero()) return false;
  // The plane's axes, so that the face turns counter-clockwise in it.
  const Point3 x = normal.unitOrthogonal(), y = normal.cross(x);
  std::vector<core::Point2> flat;
  for (const Point3& p : polygon) flat.emplace_back(p.dot(x), p.dot(y));
  const auto part = [&](int from, int to) {
    std::vector<core::Point2> polygon;
    for (int i = from;; i = (i + 1) % n) {
      polygon.push_back(flat[i]);
      if (i == to) break;
    }
    return polygon;
  };
  const auto reflex = [](const std::vector<core::Point2>& polygon) {
    int count = 0;
    const size_t m = polygon.size();
    for (size_t i = 0; i < m; ++i) count += core::turn(polygon[i], polygon[(i + 1) % m], polygon[(i + 2) % m]) < 0;
    return count;
  };
  int bestFrom = -1, bestTo = -1, fewest = 0;
  double mostEven = 0;
  for (int i = 0; i < n; ++i) {
    for (int j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // a side, not a diagonal
      const auto first = part(i, j), second = part(j, i);
      // Inside the face: both parts turn the face's way and neither crosses itself.
      const double a = core::signedArea(first), b = core::signedArea(second);
      if (!(a > 0 && b > 0) || core::crossesItself(first) || core::crossesItself(second)) continue;
      const int reflexCorners = reflex(first) + reflex(second);
      const double even = std::min(a, b) / std::max(a, b);
      if (bestFrom < 0 || reflexCorners < fewest || (reflexCorners == fewest && even > mostEven)) {
        bestFrom = i, bestTo = j, fewest = reflexCorners, mostEven = even;
      }
    }
  }
  if (bestFrom < 0) return false;
  std::vector<int> first, second;
  for (int i = bestFrom;; i = (i + 1) % n) {
    first.push_back(corners[i]);
    if (i == bestTo) break;
  }
  for (int i = bestTo;; i = (i + 1) % n) {
    second.push_back(corners[i]);
    if (i == bestFrom) break;
  }
  if (mesh.sourceFace.empty()) {
    for (int f = 0; f < mesh.faceCount(); ++f) mesh.sourceFace.push_back(f);
  }
  mesh.faces[face] = std::move(first);
  mesh.faces.push_back(std::move(second));
  mesh.sourceFace.push_back(mesh.sourceFace[face]);
  return true;
}

double polygonArea3(const std::vector<Point3>& polygon) {
  Point3 sum = Point3::Zero();
  for (size_t i = 0; i < polygon.size(); ++i) sum += polygon[i].cross(polygon[(i + 1) % polygon.size()]);
  return sum.norm() / 2;
}

}  // namespace

namespace {

// The band decomposition (III, V.1), its bands made developable (V.2) and
// each face's panel unfolded (V.3); the flood fill's order from the face
// asked for, or the lowest (V.5).
void unfoldPanels(BandBuild& b, const core::WorkContext& context) {
  const PolygonMesh& mesh = b.mesh;
  const BandOptions& options = b.options;
  b.rs = RotationSystem::fromMesh(mesh);
  context.report({"geometry", "band decomposition", 0, static_cast<size_t>(mesh.faceCount())});
  b.decomposition = bandDecomposition(mesh, b.rs, options.tension);
  context.check();
  b.bands = developableBands(b.rs, b.decomposition, options.samples);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    context.check();
    try {
      b.flat.push_back(unfoldPanel(b.rs, b.decomposition, b.bands, f));
    } catch (const std::invalid_argument& error) {
      throw std::invalid_argument(fmt::format("{}: {}", b.faceName(f), error.what()));
    }
  }
  int start = -1;
  if (options.start) {
    for (int f = 0; f < mesh.faceCount() && start < 0; ++f) {
      if (mesh.sourceFaceIndex(f) == *options.start) start = f;
    }
    if (start < 0) {
      throw ParameterError(Parameter::Start,
                           fmt::format("{} {}: the mesh has no such face (faces are numbered from 0 as in the file)",
                                       options.names(Parameter::Start), *options.start));
    }
  } else {
    start = lowestFace(mesh, options.up);
  }
  b.order = floodFill(mesh, b.rs, start, options.up);
}

// A panel that would overlap itself (V.4) is split: one band at a time,
// the later of two that overlap, is cut off with a tab (or, where no tab
// has room, across its middle), until none do. A piece crossing itself
// cannot be mended so; the last remedy is the face itself in two
// (FacesToSplit, after this pass), where it has corners enough.
class OverlapMending {
 public:
  explicit OverlapMending(BandBuild& b) : b_(b) {}

  void mendFace(int f);

  int split = 0, halved = 0, gluedTabs = 0;  // bands cut off with a tab, cut across, tabs glued
  FacesToSplit toSplit;

 private:
  bool cutOff(int f, int index, bool glued, std::string& why, double& mostRoom);
  bool cutAcross(int f, int index);

  BandBuild& b_;
};

void OverlapMending::mendFace(int f) {
  std::vector<FlatPanel>& flat = b_.flat;
  const BandOptions& options = b_.options;
  for (auto overlaps = overlappingPieces(flat[f]); !overlaps.empty(); overlaps = overlappingPieces(flat[f])) {
    const auto [i, j] = overlaps.front();
    const auto where = [&] { return fmt::format("panel {} ({})", b_.order.panelOfFace[f] + 1, b_.faceName(f)); };
    // The last remedy, the face itself in two (after this pass), where it has corners enough.
    const auto splitLater = [&](const std::string& why) {
      if (b_.mesh.faces[f].size() < 4) return false;
      if (toSplit.faces.empty()) toSplit.firstError = why;
      toSplit.faces.push_back(f);
      return true;
    };
    if (j < 0) {
      const std::string what =
          fmt::format("{}: its vertex band crosses itself when laid flat (the face is far from planar)", where());
      if (splitLater(what)) break;
      throw std::invalid_argument(what + "; split the face in the mesh");
    }
    if (i == j) {
      throw std::invalid_argument(fmt::format("{}: the band of {} overlaps itself when laid flat", where(),
                                              b_.edgeName(flat[f].bands[j].edge)));
    }
    std::string why;
    double mostRoom = 0;  // of the tabs tried, the best share of the clearance needed
    if (!cutOff(f, j, false, why, mostRoom) && (i < 0 || !cutOff(f, i, false, why, mostRoom))) {
      const std::string what =
          fmt::format("{} would overlap itself when unfolded, and the band of {} cannot be cut off: {}", where(),
                      b_.edgeName(flat[f].bands[j].edge), why.empty() ? "it is cut across already" : why);
      // The tab's room grows with the mesh, but only until the tab is as
      // deep as it may be, and other tabs may be in the way: an estimate.
      if (mostRoom > 0 && !options.glueBandsWithoutRoom) {
        NoRoomForHoleError error(what, 1, 1.02 / mostRoom, options.fastener, options.names);
        error.estimate = true;
        // (Mended where the band is, or else anywhere about the face.)
        error.edges = {flat[f].bands[j].edge};
        for (const FlatBand& other : flat[f].bands) {
          if (other.edge >= 0 && other.edge != flat[f].bands[j].edge) error.edges.push_back(other.edge);
        }
        throw b_.withPlaces(error);
      }
      // A tab glued where it has no room for its hole and bands may be glued.
      if (options.glueBandsWithoutRoom &&
          (cutOff(f, j, true, why, mostRoom) || (i >= 0 && cutOff(f, i, true, why, mostRoom)))) {
        ++split;
        continue;
      }
      // No tab at any size: the band across its middle; else the face itself in two.
      if (cutAcross(f, j) || (i >= 0 && cutAcross(f, i))) continue;
      if (splitLater(what + "; nor can it be cut across its middle")) break;
      throw UnfoldOverlapError(fmt::format(
          "{}; nor can it be cut across its middle; split that face in the mesh, or simplify the mesh ({} N)", what,
          options.names(Parameter::Panels)));
    }
    ++split;
  }
}

// Band `index` of face f's panel cut off with a tab: the later band of the
// two, or else the earlier one, the first whose tab has room for its hole,
// at least kLeastClearance diameters from the piece's and the panel's
// outlines and clear of the panel's other tabs' holes; at the point of most
// clearance. `glued`: a tab with no room for its hole is glued
// (BandOptions::glueBandsWithoutRoom). Says `why` not, and the best share
// of the clearance a tab tried had (`mostRoom`).
bool OverlapMending::cutOff(int f, int index, bool glued, std::string& why, double& mostRoom) {
  const double fastener = b_.options.fastener;
  if (b_.flat[f].bands[index].halved) return false;
  FlatPanel trial = b_.flat[f];
  try {
    detachBand(trial, index, 2 * kClearance * fastener);
  } catch (const std::invalid_argument& error) {
    why = error.what();
    return false;
  }
  FlatBand& cut = trial.bands[index];
  // Tabs of one panel may lie on each other, but none over another's hole.
  for (const FlatBand& other : trial.bands) {
    if (&other != &cut && other.detached && !other.tabGlued && insidePolygon(cut.tabOutline, other.tab)) {
      why = "its tab would cover the hole of another band's tab";
      return false;
    }
  }
  const auto room = [&](const Point2& p) {
    if (!insidePolygon(cut.tabOutline, p) || !insidePolygon(trial.outline, p)) return -1.0;
    double least = std::min(distanceToOutline(cut.pieceOutline, p), distanceToOutline(trial.outline, p));
    for (const FlatBand& other : trial.bands) {
      if (&other == &cut || !other.detached || other.tabGlued) continue;
      least = std::min(least, (other.tab - p).norm() - fastener);
      if (insidePolygon(other.tabOutline, p)) return -1.0;  // under another tab
    }
    return least / fastener;  // diameters
  };
  const auto [hole, clearance] = mostRoomIn(cut.tabOutline, room);
  mostRoom = std::max(mostRoom, clearance / kLeastClearance);
  if (clearance < kLeastClearance && glued) {
    cut.tabGlued = true;
    ++gluedTabs;
    b_.flat[f] = std::move(trial);
    return true;
  }
  if (clearance < kLeastClearance) {
    why = fmt::format("its tab has no room for a {} fastener hole {:g} diameter{} from every outline",
                      b_.options.names.unit(fastener, 3), kLeastClearance, kLeastClearance == 1 ? "" : "s");
    return false;
  }
  cut.tab = hole;
  b_.flat[f] = std::move(trial);
  return true;
}

// Where no tab has room: the band cut across its middle, so that the
// other copy, whole, holds both halves (its holes are checked with the
// others'). Not both copies of a band: the halves would then hold only
// each other's panel.
bool OverlapMending::cutAcross(int f, int index) {
  const FlatBand& copy = b_.flat[f].bands[index];
  const EdgeBand& band = b_.bands[copy.edge];
  const FlatBand* other = bandCopy(b_.flat[copy.fromA ? band.faceB : band.faceA], copy.edge);
  if (copy.halved || (other && other->halved)) return false;
  FlatPanel trial = b_.flat[f];
  try {
    halveBand(trial, index);
  } catch (const std::invalid_argument&) {
    return false;
  }
  b_.flat[f] = std::move(trial);
  ++halved;
  return true;
}

// Edge numbers in the order the flood fill meets the edges, so that the
// numbers a builder looks for next are close to the ones in hand; how many.
int numberEdges(BandBuild& b) {
  int edges = 0;
  b.edgeNumber.assign(b.rs.edgeCount(), 0);
  for (int face : b.order.faceOfPanel) {
    Dart d = b.rs.faceDart(face);
    for (size_t side = 0; side < b.mesh.faces[face].size(); ++side, d = b.rs.faceNext(d)) {
      const int e = RotationSystem::edgeOf(d);
      if (!b.rs.isBoundaryEdge(e) && b.edgeNumber[e] == 0) b.edgeNumber[e] = ++edges;
    }
  }
  return edges;
}

// The fasteners, the bands glued and what the holes leave to say: tabs
// glued, bands glued, bands with one narrow hole.
void countFasteners(const BandBuild& b, const std::vector<BandHoles>& holes, const OverlapMending& mended,
                    Structure& result) {
  const double fastener = b.options.fastener;
  const ParameterNames& names = b.options.names;
  int narrow = 0, narrowest = -1;
  result.fasteners = mended.split - mended.gluedTabs;  // the tabs'
  for (const BandHoles& h : holes) {
    result.fasteners += static_cast<int>(h.holes.size());
    if (h.glued) result.glued.push_back(b.edgeNumber[h.edge]);
    if (h.edge < 0 || h.glued || h.clearance >= kClearance) continue;
    ++narrow;
    if (narrowest < 0 || h.clearance < holes[narrowest].clearance) narrowest = h.edge;
  }
  if (const int gluedTabs = mended.gluedTabs; gluedTabs > 0) {
    result.warnings.push_back(
        fmt::format("{} band{} cut off {} panel{} that would overlap {}: no room for {} tab's {} fastener hole, so {} "
                    "tab{} {} glued",
                    gluedTabs, gluedTabs == 1 ? "" : "s", gluedTabs == 1 ? "a" : "the", gluedTabs == 1 ? "" : "s",
                    gluedTabs == 1 ? "itself" : "themselves", gluedTabs == 1 ? "its" : "their", names.unit(fastener, 3),
                    gluedTabs == 1 ? "its" : "their", gluedTabs == 1 ? "" : "s", gluedTabs == 1 ? "is" : "are"));
  }
  if (!result.glued.empty()) {
    std::sort(result.glued.begin(), result.glued.end());
    std::string some;
    for (size_t i = 0; i < std::min<size_t>(result.glued.size(), 5); ++i) {
      some += fmt::format("{}{}", i ? ", " : "", result.glued[i]);
    }
    const size_t n = result.glued.size();
    result.warnings.push_back(
        fmt::format("{} band{} no room for a {} fastener hole {:g} diameter from every outline, so no hole: glue {} "
                    "(edge{} {}{})",
                    n, n == 1 ? " has" : "s have", names.unit(fastener, 3), kLeastClearance, n == 1 ? "it" : "them",
                    n == 1 ? "" : "s", some, n > 5 ? ", ..." : ""));
  }
  if (narrow > 0) {
    result.warnings.push_back(fmt::format(
        "{} band{} too narrow for a {} hole {} diameters from its outlines: one hole each, down to {:.2f} "
        "diameters (edge {}); a larger {} or a smaller {} gives them the full clearance",
        narrow, narrow == 1 ? " is" : "s are", names.unit(fastener, 3), kClearance, holes[narrowest].clearance,
        b.edgeNumber[narrowest], names(Parameter::Size), names(Parameter::Fastener)));
  }
}

Structure buildOnce(const PolygonMesh& mesh, const BandOptions& options, const core::WorkContext& context) {
  if (!(options.fastener > 0)) {
    throw ParameterError(Parameter::Fastener,
                         options.names(Parameter::Fastener) + ": the hole diameter must be positive");
  }
  BandBuild b(mesh, options);
  unfoldPanels(b, context);
  OverlapMending mended(b);
  for (int f = 0; f < mesh.faceCount(); ++f) {
    context.check();
    mended.mendFace(f);
  }
  if (!mended.toSplit.faces.empty()) throw mended.toSplit;
  // (done: the bands cut off with a tab; total: those and the bands cut across)
  if (mended.split + mended.halved > 0) {
    context.report({"geometry", "panels split", static_cast<size_t>(mended.split),
                    static_cast<size_t>(mended.split + mended.halved)});
  }
  Structure result;
  result.kind = StructureKind::Band;
  result.edges = numberEdges(b);

  context.report({"geometry", "fastener holes", 0, static_cast<size_t>(result.edges)});
  std::vector<BandHoles> holes;
  try {
    holes = placeFastenerHoles(
        b.bands, b.flat, options.fastener, context, [&](int e) { return b.edgeName(e); }, options.names,
        options.glueBandsWithoutRoom);
  } catch (NoRoomForHoleError& error) {
    throw b.withPlaces(error);
  }
  countFasteners(b, holes, mended, result);

  context.report({"geometry", "labels", 0, static_cast<size_t>(mesh.faceCount())});
  const HersheyFont& font = HersheyFont::simplex();
  // Each panel on its own, so the panels are shared out among the cores.
  result.panels.resize(mesh.faceCount());
  std::vector<std::vector<Unetched>> unetchedOf(mesh.faceCount());  // labels too large even at the smallest height
  context.parallelFor(mesh.faceCount(), [&](size_t number) {
    result.panels[number] = bandPanel(b, holes, font, static_cast<int>(number), unetchedOf[number]);
  });
  refuseUnetched(b, unetchedOf, result);
  result.steps = stepsInPanelOrder(result.panels);
  return result;
}

}  // namespace

Structure buildBandStructure(const PolygonMesh& mesh, const BandOptions& options, const core::WorkContext& context) {
  // A split face's parts may still overlap: split again, a few times at most.
  constexpr int kSplitRounds = 8;
  PolygonMesh split;
  const PolygonMesh* current = &mesh;
  int faces = 0;
  std::string first;
  for (int round = 1;; ++round) {
    try {
      Structure structure = buildOnce(*current, options, context);
      if (faces > 0) {
        structure.warnings.push_back(
            fmt::format("{} face{} split in two along a diagonal (the first: {}), as {} panel{} would overlap {} when "
                        "unfolded; the new edge{} {} fastened like any other",
                        faces, faces == 1 ? "" : "s", first, faces == 1 ? "its" : "their", faces == 1 ? "" : "s",
                        faces == 1 ? "itself" : "themselves", faces == 1 ? "" : "s", faces == 1 ? "is" : "are"));
      }
      return structure;
    } catch (const FacesToSplit& overlapping) {
      const auto refuse = [&] {
        return std::invalid_argument(fmt::format("{}; split that face in the mesh, or simplify the mesh ({} N)",
                                                 overlapping.firstError, options.names(Parameter::Panels)));
      };
      if (round == kSplitRounds) throw refuse();
      if (current == &mesh) split = mesh, current = &split;
      for (int f : overlapping.faces) {
        if (!splitFaceInTwo(split, f)) throw refuse();
        if (first.empty()) {
          first = split.sourceFaceIndex(f) >= 0 ? fmt::format("face {}", split.sourceFaceIndex(f)) : "a hole's cap";
        }
        ++faces;
      }
    }
  }
}

GrownStructure buildBandStructureWithRoom(PolygonMesh& mesh, const BandOptions& options,
                                          const core::WorkContext& context) {
  return growUntilRoom(
      mesh, [&](const PolygonMesh& grown) { return buildBandStructure(grown, options, context); }, context);
}

}  // namespace rotafab::geometry
