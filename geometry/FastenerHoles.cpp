#include "geometry/FastenerHoles.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

namespace rotafab::geometry {

Point3 BandPoint::inSpace(const EdgeBand& band) const {
  return weights[0] * band.point(corners[0]) + weights[1] * band.point(corners[1]) +
         weights[2] * band.point(corners[2]);
}

Point2 BandPoint::onPanel(const FlatBand& copy) const {
  return weights[0] * copy.points[corners[0]] + weights[1] * copy.points[corners[1]] +
         weights[2] * copy.points[corners[2]];
}

const FlatBand* bandCopy(const FlatPanel& panel, int edge) {
  for (const FlatBand& band : panel.bands) {
    if (band.edge == edge) return &band;
  }
  return nullptr;
}

namespace {

// The band point at (s, t) of a flat copy: s from the first face's side
// (0) to the second's (1) along the rails, t from rail U (0) to rail V (1).
std::optional<BandPoint> locate(const EdgeBand& band, const FlatBand& copy, double s, double t) {
  const Point2 p = copy.at(s, t);
  std::optional<BandPoint> best;
  double bestLeast = -1e-9;
  for (const auto& tri : band.triangles()) {
    const Point2 a = copy.points[tri[0]], b = copy.points[tri[1]], c = copy.points[tri[2]];
    const double area = (b - a).x() * (c - a).y() - (b - a).y() * (c - a).x();
    if (std::abs(area) < 1e-18) continue;
    const double wb = ((p - a).x() * (c - a).y() - (p - a).y() * (c - a).x()) / area;
    const double wc = ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x()) / area;
    const Eigen::Vector3d w(1 - wb - wc, wb, wc);
    if (w.minCoeff() > bestLeast) {
      bestLeast = w.minCoeff();
      best = BandPoint{tri, w};
    }
  }
  return best;
}

}  // namespace

const std::vector<Point2>& cutOutline(const FlatPanel& panel, const FlatBand& copy, const Point2& at) {
  return copy.onPiece(at) ? copy.pieceOutline : panel.outline;
}

namespace {

// One band without room for a hole, and how many times larger the mesh would have to be to give it room.
struct BandTooSmall {
  std::string what;
  double scaleNeeded;
};

}  // namespace

NoRoomForHoleError::NoRoomForHoleError(std::string firstBand, int bands, double scaleNeeded_, double diameter,
                                       const ParameterNames& names)
    : std::invalid_argument(""),
      bandsWithoutRoom(firstBand + (bands > 1 ? fmt::format(" (nor have {} other bands)", bands - 1) : "")),
      scaleNeeded(scaleNeeded_),
      bands(bands) {
  static_cast<std::invalid_argument&>(*this) = std::invalid_argument(
      bandsWithoutRoom +
      (std::isfinite(scaleNeeded)
           ? fmt::format("; a fastener of {} or less, or the mesh {:.2f} times larger, would give every band room",
                         names.unit(diameter / scaleNeeded, 3, -1), scaleNeeded)
           : fmt::format("; use a smaller {} or a larger {}", names(Parameter::Fastener), names(Parameter::Size))));
}

NoRoomForHoleError NoRoomForHoleError::forLabels(std::string firstBand, int bands, const ParameterNames& names) {
  NoRoomForHoleError error(std::move(firstBand), bands, kLabelGrowth, 0, names);
  error.estimate = true;
  error.labels = true;
  static_cast<std::invalid_argument&>(error) = std::invalid_argument(
      error.bandsWithoutRoom + fmt::format("; a larger {} gives them room", names(Parameter::Size)));
  return error;
}

namespace {

// Holes already placed, per part cut: a panel (key (face, -1)) and each
// band cut off it (key (face, edge)) are parts of their own, only sharing
// the panel's frame; a tab's hole is on both.
using PlacedHoles = std::map<std::pair<int, int>, std::vector<Point2>>;

// The part cut that point `at` of a copy of a band on face `face`'s panel is on.
std::pair<int, int> partCut(int face, const FlatBand& copy, const Point2& at) {
  return std::pair{face, copy.onPiece(at) ? copy.edge : -1};
}

const std::vector<Point2>& holesOnPart(const PlacedHoles& placed, const std::pair<int, int>& part) {
  static const std::vector<Point2> none;
  const auto it = placed.find(part);
  return it == placed.end() ? none : it->second;
}

// One band's holes (V.5), kept clear of the outlines of both its copies and
// of the holes in `holesOn`. Throws BandTooSmall.
class BandHolePlacer {
 public:
  BandHolePlacer(const EdgeBand& band, const std::vector<FlatPanel>& panels, double diameter,
                 const PlacedHoles& holesOn, const std::function<std::string(int)>& edgeName, core::LengthUnit unit)
      : band_(band),
        panels_(panels),
        diameter_(diameter),
        fromOutline_(kClearance * diameter),
        fromHole_((kClearance + 1) * diameter),
        holesOn_(holesOn),
        edgeName_(edgeName),
        unit_(unit),
        copies_{bandCopy(panels[band.faceA], band.edge), bandCopy(panels[band.faceB], band.edge)},
        faces_{band.faceA, band.faceB},
        flat_(copies_[0]->fromA ? *copies_[0] : *copies_[1]),
        k_(band.segments()),
        length_(
            ((flat_.points[0] + flat_.points[k_ + 1]) / 2 - (flat_.points[k_] + flat_.points[2 * k_ + 1]) / 2).norm()),
        width_(
            ((flat_.points[k_ + 1] - flat_.points[0]).norm() + (flat_.points[2 * k_ + 1] - flat_.points[k_]).norm()) /
            2) {}

  [[nodiscard]] BandHoles place() const {
    BandHoles placed;
    placed.edge = band_.edge;
    placeTwoWithFullClearance(placed);
    const bool halved = copies_[0]->halved || copies_[1]->halved;
    if (placed.holes.empty() && halved) placeOneOnEachHalf(placed);
    if (placed.holes.empty()) placeOneWithMostClearance(placed);
    return placed;
  }

 private:
  // The least clearance of a set of holes on both copies (negative: one is off the panel).
  [[nodiscard]] double clearance(const std::vector<BandPoint>& holes) const {
    double least = std::numeric_limits<double>::max();
    for (int c = 0; c < 2; ++c) {
      for (size_t h = 0; h < holes.size(); ++h) {
        const Point2 at = holes[h].onPanel(*copies_[c]);
        const std::vector<Point2>& outline = cutOutline(panels_[faces_[c]], *copies_[c], at);
        if (!insidePolygon(outline, at)) return -1.0;
        least = std::min(least, distanceToOutline(outline, at) / fromOutline_);
        for (const Point2& other : holesOnPart(holesOn_, partCut(faces_[c], *copies_[c], at))) {
          least = std::min(least, (other - at).norm() / fromHole_);
        }
        for (size_t g = 0; g < h; ++g) least = std::min(least, (holes[g].onPanel(*copies_[c]) - at).norm() / fromHole_);
      }
      // A halved copy: a hole on each half, or one half would hang loose.
      if (copies_[c]->halved && (holes.size() != 2 || copies_[c]->onPiece(holes[0].onPanel(*copies_[c])) ==
                                                          copies_[c]->onPiece(holes[1].onPanel(*copies_[c])))) {
        return -1.0;
      }
    }
    return least;  // >= 1: every distance kept
  }

  // What a set of holes keeps from the outlines alone, in diameters (clearance() also weighs the other holes).
  [[nodiscard]] double clearanceFromOutlines(const std::vector<BandPoint>& holes) const {
    double fromOutlines = std::numeric_limits<double>::max();
    for (int c = 0; c < 2; ++c) {
      for (const BandPoint& hole : holes) {
        const Point2 at = hole.onPanel(*copies_[c]);
        fromOutlines =
            std::min(fromOutlines, distanceToOutline(cutOutline(panels_[faces_[c]], *copies_[c], at), at) / diameter_);
      }
    }
    return fromOutlines;
  }

  [[nodiscard]] std::vector<BandPoint> layout(HoleLayout kind, double spread) const {
    std::vector<BandPoint> holes;
    const auto add = [&](double s, double t) {
      if (auto p = locate(band_, flat_, s, t)) holes.push_back(*p);
    };
    if (kind == HoleLayout::Along) add(0.5 - spread, 0.5), add(0.5 + spread, 0.5);
    if (kind == HoleLayout::Across) add(0.5, 0.5 - spread), add(0.5, 0.5 + spread);
    if (kind == HoleLayout::Single) add(0.5, 0.5);
    return holes;
  }

  // Two holes with the full clearance, along a long thin band or across a
  // wide short one, spread as wide as they keep it.
  void placeTwoWithFullClearance(BandHoles& placed) const {
    const HoleLayout preferred = length_ >= width_ ? HoleLayout::Along : HoleLayout::Across;
    const HoleLayout other = preferred == HoleLayout::Along ? HoleLayout::Across : HoleLayout::Along;
    // A hole with the full clearance needs the band at least twice that
    // wide where it is, and the band is nowhere wider than its widest
    // ruling (a ruling between two others is no longer than the longer).
    double widest = 0;
    for (int i = 0; i <= k_; ++i) widest = std::max(widest, (flat_.points[k_ + 1 + i] - flat_.points[i]).norm());
    const bool roomForFull = widest >= 2 * fromOutline_;
    for (HoleLayout kind : {preferred, other}) {
      if (!roomForFull) break;
      for (double spread : {0.3, 0.25, 0.2, 0.15, 0.1}) {
        auto holes = layout(kind, spread);
        if (holes.size() == 2 && clearance(holes) >= 1) {
          placed.layout = kind, placed.holes = std::move(holes);
          break;
        }
      }
      if (!placed.holes.empty()) break;
    }
  }

  // Two holes along the band, one on each half, with the most clearance
  // there is (the middle of the band is an outline now).
  void placeOneOnEachHalf(BandHoles& placed) const {
    double most = -1;
    for (double spread = 0.05; spread < 0.451; spread += 0.025) {
      auto holes = layout(HoleLayout::Along, spread);
      if (const double c = holes.size() == 2 ? clearance(holes) : -1; c > most) most = c, placed.holes = holes;
    }
    placed.layout = HoleLayout::Along;
    placed.clearance = std::min(kClearance, clearanceFromOutlines(placed.holes));
    if (most < kLeastClearance / kClearance) {
      throw BandTooSmall{
          fmt::format("{}: its band ({}), cut across its middle, has no room for a {} fastener "
                      "hole on each half {:g} diameter{} from every outline (centre to edge)",
                      edgeName_(band_.edge), unit_.size(length_, width_, 3), unit_(diameter_, 3), kLeastClearance,
                      kLeastClearance == 1 ? "" : "s"),
          most > 0 ? 1.02 * kLeastClearance / kClearance / most : std::numeric_limits<double>::infinity()};
    }
  }

  // One hole: the point of most clearance, found on a coarse grid over
  // the band and then by a pattern search around the best (the middle on a tie).
  void placeOneWithMostClearance(BandHoles& placed) const {
    double most = -1, bestS = 0.5, bestT = 0.5;
    const auto consider = [&](double s, double t) {
      if (s < 0.05 || s > 0.95 || t < 0.05 || t > 0.95) return;
      const auto p = locate(band_, flat_, s, t);
      if (!p) return;
      const double c = clearance({*p}) - 1e-3 * (std::abs(s - 0.5) + std::abs(t - 0.5));
      if (c > most) most = c, bestS = s, bestT = t, placed.holes = {*p};
    };
    for (double s = 0.2; s <= 0.801; s += 0.1) {
      for (double t : {0.3, 0.5, 0.7}) consider(s, t);
    }
    for (double step = 0.05; step > 0.01; step /= 2) {
      const double s0 = bestS, t0 = bestT;
      for (const auto& [ds, dt] : {std::pair{step, 0.0}, {-step, 0.0}, {0.0, step}, {0.0, -step}}) {
        consider(s0 + ds, t0 + dt);
      }
    }
    placed.layout = HoleLayout::Single;
    placed.clearance = std::min(kClearance, clearanceFromOutlines(placed.holes));
    if (most < kLeastClearance / kClearance) {
      throw BandTooSmall{
          fmt::format("{}: its band ({}) has no room for a {} fastener hole {:g} diameter{} "
                      "from every outline (centre to edge)",
                      edgeName_(band_.edge), unit_.size(length_, width_, 3), unit_(diameter_, 3), kLeastClearance,
                      kLeastClearance == 1 ? "" : "s"),
          // (with 2% to spare: the search for the hole's place is on a grid)
          most > 0 ? 1.02 * kLeastClearance / kClearance / most : std::numeric_limits<double>::infinity()};
    }
  }

  const EdgeBand& band_;
  const std::vector<FlatPanel>& panels_;
  const double diameter_, fromOutline_, fromHole_;
  const PlacedHoles& holesOn_;
  const std::function<std::string(int)>& edgeName_;
  core::LengthUnit unit_;  // of the lengths in its messages
  const FlatBand* const copies_[2];
  const int faces_[2];
  const FlatBand& flat_;  // the copy on face A's panel: where the holes' (s, t) are measured
  const int k_;
  const double length_, width_;
};

// Replaces band `e`'s holes by none, glued instead (placeFastenerHoles()'s `glueWithoutRoom`).
void glueBand(std::vector<BandHoles>& result, const std::vector<EdgeBand>& bands, size_t e) {
  result[e] = BandHoles{};
  result[e].edge = bands[e].edge, result[e].clearance = 0, result[e].glued = true;
}

// Every band without room, in one error: the first by edge, how many, and
// the scale that gives the smallest of them room.
void throwIfWithoutRoom(const std::vector<EdgeBand>& bands, const std::vector<std::optional<BandTooSmall>>& tooSmall,
                        double diameter, const ParameterNames& names) {
  const BandTooSmall* first = nullptr;
  int small = 0;
  double scaleNeeded = 1;
  std::vector<double> scales;
  std::vector<int> edges;
  for (size_t e = 0; e < tooSmall.size(); ++e) {
    const auto& some = tooSmall[e];
    if (!some) continue;
    if (!first) first = &*some;
    ++small;
    scaleNeeded = std::max(scaleNeeded, some->scaleNeeded);
    scales.push_back(some->scaleNeeded);
    edges.push_back(bands[e].edge);
  }
  if (first) {
    NoRoomForHoleError error(first->what, small, scaleNeeded, diameter, names);
    error.scales = std::move(scales);
    error.edges = std::move(edges);
    throw error;
  }
}

// The fasteners of the tabs of the bands cut off their panels (and not glued):
// each is on the panel and on the piece.
PlacedHoles tabFasteners(const std::vector<FlatPanel>& panels) {
  PlacedHoles holesOn;
  for (size_t f = 0; f < panels.size(); ++f) {
    for (const FlatBand& copy : panels[f].bands) {
      if (!copy.detached || copy.tabGlued) continue;
      holesOn[{static_cast<int>(f), -1}].push_back(copy.tab);                     // the tab's fastener, on the panel
      holesOn[partCut(static_cast<int>(f), copy, copy.tab)].push_back(copy.tab);  // and on the piece
    }
  }
  return holesOn;
}

// In edge order, a band whose holes come too near those of a band before it
// on the same part (rare: the outline runs between two bands) is placed
// again beside them.
void placeAgainBesideEarlierBands(const std::vector<EdgeBand>& bands, const std::vector<FlatPanel>& panels,
                                  double diameter, const std::function<std::string(int)>& edgeName,
                                  const ParameterNames& names, bool glueWithoutRoom, std::vector<BandHoles>& result) {
  const double fromHole = (kClearance + 1) * diameter;
  PlacedHoles holesOn = tabFasteners(panels);
  for (const EdgeBand& band : bands) {
    if (band.edge < 0) continue;
    const FlatBand* copies[2] = {bandCopy(panels[band.faceA], band.edge), bandCopy(panels[band.faceB], band.edge)};
    const int faces[2] = {band.faceA, band.faceB};
    const auto tooNear = [&] {
      for (int c = 0; c < 2; ++c) {
        for (const BandPoint& h : result[band.edge].holes) {
          const Point2 at = h.onPanel(*copies[c]);
          for (const Point2& other : holesOnPart(holesOn, partCut(faces[c], *copies[c], at))) {
            if ((other - at).norm() < fromHole) return true;
          }
        }
      }
      return false;
    };
    if (tooNear()) {
      try {
        result[band.edge] = BandHolePlacer(band, panels, diameter, holesOn, edgeName, names.unit).place();
      } catch (const BandTooSmall& small) {
        if (!glueWithoutRoom) {
          NoRoomForHoleError error(small.what, 1, small.scaleNeeded, diameter, names);
          error.edges = {band.edge};
          throw error;
        }
        glueBand(result, bands, static_cast<size_t>(band.edge));
      }
    }
    for (int c = 0; c < 2; ++c) {
      for (const BandPoint& h : result[band.edge].holes) {
        const Point2 at = h.onPanel(*copies[c]);
        holesOn[partCut(faces[c], *copies[c], at)].push_back(at);
      }
    }
  }
}

}  // namespace

std::vector<BandHoles> placeFastenerHoles(const std::vector<EdgeBand>& bands, const std::vector<FlatPanel>& panels,
                                          double diameter, const core::WorkContext& context,
                                          const std::function<std::string(int)>& edgeName, const ParameterNames& names,
                                          bool glueWithoutRoom) {
  std::vector<BandHoles> result(bands.size());
  // Each band alone first, the bands shared out among the cores; then, in
  // edge order, a band whose holes come too near those of a band before it
  // on the same panel (rare: the outline runs between two bands) is placed
  // again beside them. The result does not depend on the number of cores.
  const PlacedHoles none;
  std::vector<std::optional<BandTooSmall>> tooSmall(bands.size());
  context.parallelFor(bands.size(), [&](size_t e) {
    if (bands[e].edge < 0) return;
    try {
      result[e] = BandHolePlacer(bands[e], panels, diameter, none, edgeName, names.unit).place();
    } catch (const BandTooSmall& small) {
      tooSmall[e] = small;
    }
  });
  if (glueWithoutRoom) {
    for (size_t e = 0; e < bands.size(); ++e) {
      if (tooSmall[e]) glueBand(result, bands, e), tooSmall[e].reset();
    }
  }
  throwIfWithoutRoom(bands, tooSmall, diameter, names);
  placeAgainBesideEarlierBands(bands, panels, diameter, edgeName, names, glueWithoutRoom, result);
  return result;
}

}  // namespace rotafab::geometry
