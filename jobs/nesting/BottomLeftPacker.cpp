#include "jobs/nesting/BottomLeftPacker.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rotafab::jobs::nesting {
namespace {

// The room regions are eroded by this much less than the radius: Clipper's
// round joins put their vertices on the arcs (so their chords only add to the
// region), and the grid rounds by a unit.
constexpr cInt kRoomSlack = 4;

// What two placed grown shapes have in common (nothing when their boxes are apart).
Paths common(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) {
  if (boxesApart(a, atA, b, atB)) return {};
  return intersectionOf(a.grown, atA, b.grown, atB);
}
double overlap(const Shape& a, IntPoint atA, const Shape& b, IntPoint atB) {
  double area = 0;
  for (const Path& c : common(a, atA, b, atB)) area += std::abs(ClipperLib::Area(c));
  return area;
}
// Whether an overlap is beyond rounding along the edges of `shape`.
bool overlapping(double area, const Shape& shape) { return area > 4.0 * static_cast<double>(shape.grown.size()); }

}  // namespace

std::optional<NestingResult> BottomLeftPacker::pack(const std::vector<int>& sequence, OrderMode policy,
                                                    size_t unchanged, const std::vector<int>& shapeOf,
                                                    std::chrono::steady_clock::time_point until) {
  PackState state;
  size_t start = 0;
  if (policy == acceptedPolicy_) {
    for (const auto& [at, snapshot] : accepted_) {
      if (at <= unchanged && at > start && at <= sequence.size()) start = at, state = snapshot;
    }
  }
  pending_.clear();
  pendingStart_ = start;
  pendingPolicy_ = policy;
  auto& [sheets, placed] = state;
  const double sheetArea = static_cast<double>(shapes_.width()) * static_cast<double>(shapes_.height());
  for (size_t index = start; index < sequence.size(); ++index) {
    checkCancelled();
    if (std::chrono::steady_clock::now() > until) return std::nullopt;
    if (onProgress) onProgress(index, sequence.size(), sheets.size());
    if (index > start && index % kCheckpointEvery == 0) {
      pending_.emplace_back(index, state);
      for (Sheet& sheet : pending_.back().second.sheets) sheet.room.clear();  // rebuilt on demand
    }
    const int part = sequence[index];
    const int only = shapeOf.empty() ? -1 : shapeOf[part];
    bool done = false;
    for (int s = 0; s < static_cast<int>(sheets.size()) && !done; ++s) {
      if (!mayGoOn(shapes_, policy, sheets, s, part)) continue;
      if (sheets[s].freeArea < shapes_.area(part)) continue;  // cannot hold it: skip the no-fit polygons
      if (auto spot = bestSpot(part, sheets[s], only)) {
        put(sheets[s], *spot);
        placed.emplace_back(s, *spot);
        done = true;
      }
    }
    if (!done && shapes_.options().strip && !sheets.empty()) {
      // The strip is one sheet: a fixed rotation that does not fit it gives way.
      if (auto spot = only >= 0 ? bestSpot(part, sheets.front(), -1) : std::nullopt) {
        put(sheets.front(), *spot);
        placed.emplace_back(0, *spot);
        done = true;
      } else {
        throw std::invalid_argument(fmt::format("{} does not fit the strip", shapes_.parts()[part].name));
      }
    }
    if (!done) {
      sheets.emplace_back();
      sheets.back().freeArea = sheetArea;
      auto spot = bestSpot(part, sheets.back(), only);
      if (!spot && only >= 0) spot = bestSpot(part, sheets.back(), -1);
      if (!spot) throw std::invalid_argument(fmt::format("{} does not fit an empty sheet", shapes_.parts()[part].name));
      put(sheets.back(), *spot);
      placed.emplace_back(static_cast<int>(sheets.size()) - 1, *spot);
    }
  }
  return shapes_.inCuttingOrder(placed, static_cast<int>(sheets.size()), lastLayout_);
}

void BottomLeftPacker::accept() {
  acceptedLayout_ = lastLayout_;
  std::erase_if(accepted_, [&](const auto& checkpoint) { return checkpoint.first > pendingStart_; });
  if (pendingPolicy_ != acceptedPolicy_) accepted_.clear();
  for (auto& checkpoint : pending_) accepted_.push_back(std::move(checkpoint));
  acceptedPolicy_ = pendingPolicy_;
  pending_.clear();
}

void BottomLeftPacker::put(Sheet& sheet, const PlacedShape& spot) {
  sheet.parts.push_back(spot);
  sheet.freeArea -= shapes_.area(spot.part);
  ClipperLib::Clipper clipper;
  clipper.AddPaths(sheet.occupied, ClipperLib::ptSubject, true);
  clipper.AddPath(translatedPath(shapes_.at(spot.part, spot.shape).grown, spot.at), ClipperLib::ptClip, true);
  clipper.Execute(ClipperLib::ctUnion, sheet.occupied, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
}

// Where the centre of a disc of `radius` can be: on the area (grown by what
// a grown shape may overhang it) and clear of every placed shape.
const CellCover& BottomLeftPacker::room(Sheet& sheet, cInt radius) {
  const Box bounds = roomBounds();
  auto it = sheet.room.find(radius);
  if (it != sheet.room.end()) {
    Sheet::Room& room = it->second;
    if (room.upTo < sheet.parts.size()) {
      // Eroding the free area after a part is placed takes the part, grown
      // by the erosion, out of the region: that, for the parts placed since,
      // instead of eroding the whole free area again (it was half the time
      // of a first layout of 600 panels).
      ClipperLib::ClipperOffset offset(2.0, shapes_.roomScale().arcTolerance);
      for (size_t i = room.upTo; i < sheet.parts.size(); ++i) {
        const PlacedShape& q = sheet.parts[i];
        offset.AddPath(translatedPath(shapes_.at(q.part, q.shape).grown, q.at), ClipperLib::jtRound,
                       ClipperLib::etClosedPolygon);
      }
      Paths taken;
      offset.Execute(taken, static_cast<double>(radius - kRoomSlack));
      ClipperLib::Clipper clipper;
      clipper.AddPaths(room.centres, ClipperLib::ptSubject, true);
      clipper.AddPaths(taken, ClipperLib::ptClip, true);
      clipper.Execute(ClipperLib::ctDifference, room.centres, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
      room.cover = CellCover(room.centres, bounds, shapes_.roomScale().cell);
      room.upTo = sheet.parts.size();
    }
    return room.cover;
  }
  Paths free{Path{{bounds[0], bounds[1]}, {bounds[2], bounds[1]}, {bounds[2], bounds[3]}, {bounds[0], bounds[3]}}};
  if (!sheet.occupied.empty()) {
    ClipperLib::Clipper clipper;
    clipper.AddPaths(free, ClipperLib::ptSubject, true);
    clipper.AddPaths(sheet.occupied, ClipperLib::ptClip, true);
    clipper.Execute(ClipperLib::ctDifference, free, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  }
  ClipperLib::ClipperOffset offset(2.0, shapes_.roomScale().arcTolerance);
  offset.AddPaths(free, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  Paths eroded;
  offset.Execute(eroded, -static_cast<double>(radius - kRoomSlack));
  CellCover cover(eroded, bounds, shapes_.roomScale().cell);
  return sheet.room.emplace(radius, Sheet::Room{std::move(eroded), sheet.parts.size(), std::move(cover)})
      .first->second.cover;
}

// The box that holds every room region: the area grown by what a grown shape may overhang it.
Box BottomLeftPacker::roomBounds() const {
  const cInt overhang = toInt(shapes_.options().spacing / 2 + 2 * kSimplifyTolerance);
  return {-overhang, -overhang, shapes_.width() + overhang, shapes_.height() + overhang};
}

std::optional<PlacedShape> BottomLeftPacker::bestSpot(int part, Sheet& sheet, int only) {
  std::optional<PlacedShape> best;
  for (int k = 0; k < static_cast<int>(shapes_.of(part).size()); ++k) {
    if (only >= 0 && k != only) continue;
    checkCancelled();
    const Shape& moving = shapes_.at(part, k);
    const CellCover* centres = moving.centres.empty() ? nullptr : &room(sheet, moving.radius);
    if (centres && centres->empty()) continue;  // no room for this rotation's discs
    // Inner-fit rectangle: reference positions keeping the true outline on the area.
    const cInt x0 = -moving.minX, y0 = -moving.minY;
    cInt x1 = shapes_.width() - moving.maxX, y1 = shapes_.height() - moving.maxY;
    if (x1 < x0 || y1 < y0) continue;
    // A part exactly as wide (or high) as the area has a one-line inner-fit
    // region, which Clipper would drop: give it one grid unit (1e-4 in).
    x1 = std::max(x1, x0 + 1);
    y1 = std::max(y1, y0 + 1);
    // A box of reference points might hold a feasible one only if, for
    // each disc, the disc's centres for it meet the room.
    const auto mightFit = [&](const Box& b) {
      if (!centres) return true;
      return std::all_of(moving.centres.begin(), moving.centres.end(), [&](const IntPoint& c) {
        return centres->meets({b[0] + c.X, b[1] + c.Y, b[2] + c.X, b[3] + c.Y});
      });
    };
    const IntPoint centre = centres ? moving.centres.front() : IntPoint{0, 0};
    // The reference points to search: the inner-fit rectangle, cut down to
    // the cells where the disc's centre has room. Every feasible point is
    // in them, so the feasible region is found whole.
    std::vector<Box> search;
    for (const Box& cells : centres ? centres->runs() : std::vector<Box>{{x0, y0, x1, y1}}) {
      Box b = cells;
      if (centres) {
        b = {std::max(x0, cells[0] - centre.X), std::max(y0, cells[1] - centre.Y), std::min(x1, cells[2] - centre.X),
             std::min(y1, cells[3] - centre.Y)};
        if (b[0] > b[2] || b[1] > b[3]) continue;
        // Like the inner-fit rectangle, never thinner than one grid unit.
        b[2] = std::max(b[2], b[0] + 1), b[3] = std::max(b[3], b[1] + 1);
      }
      search.push_back(b);
    }
    if (search.empty()) continue;
    // Bottom-left: nothing right of a point an earlier rotation found can
    // be better, so the no-fit polygons only matter up to there. (Searching
    // windows from the left, doubling, was measured slower: 14 s against 7 s
    // for 200 star panels.)
    cInt right = std::numeric_limits<cInt>::min();
    for (const Box& b : search) right = std::max(right, b[2]);
    if (best) right = std::min(right, rankOf(*best).first - rankOffset(moving).first);
    if (auto spot = bestLeftOf(part, k, sheet, search, right, mightFit, best)) best = spot;
  }
  return best;
}

// The bottom-left point for shape k of `part` among the search boxes' points
// not right of `upTo`, better than `best`; nothing when there is none.
std::optional<PlacedShape> BottomLeftPacker::bestLeftOf(int part, int k, const Sheet& sheet,
                                                        const std::vector<Box>& search, cInt upTo,
                                                        const std::function<bool(const Box&)>& mightFit,
                                                        const std::optional<PlacedShape>& best) {
  const Shape& moving = shapes_.at(part, k);
  ClipperLib::Clipper clipper;
  bool any = false;
  for (const Box& b : search) {
    if (b[0] > upTo) continue;
    const cInt x1 = std::max(std::min(b[2], upTo), b[0] + 1);
    clipper.AddPath(Path{{b[0], b[1]}, {x1, b[1]}, {x1, b[3]}, {b[0], b[3]}}, ClipperLib::ptSubject, true);
    any = true;
  }
  if (!any) return std::nullopt;
  // A box of reference points matters only if it reaches left of `upTo` and might hold a feasible point.
  const auto matters = [&](const Box& b) { return b[0] <= upTo && mightFit(b); };
  clipper.AddPaths(noFitPolygons_.obstacles(part, k, sheet.parts, matters), ClipperLib::ptClip, true);
  Paths feasible;
  clipper.Execute(ClipperLib::ctDifference, feasible, ClipperLib::pftNonZero, ClipperLib::pftNonZero);
  std::vector<IntPoint> candidates;
  for (const Path& region : feasible) candidates.insert(candidates.end(), region.begin(), region.end());
  // Bottom-left: leftmost, then lowest; the first that an exact check
  // confirms, so that no rounding in the no-fit polygons can let parts overlap.
  std::sort(candidates.begin(), candidates.end(),
            [](const IntPoint& a, const IntPoint& b) { return a.X < b.X || (a.X == b.X && a.Y < b.Y); });
  for (const IntPoint& p : candidates) {
    if (best && rankOf({part, k, p}) >= rankOf(*best)) break;
    if (clear(moving, p, sheet.parts)) return PlacedShape{part, k, p};
  }
  return std::nullopt;
}

std::pair<cInt, cInt> BottomLeftPacker::rankOf(const PlacedShape& spot) const {
  const auto offset = rankOffset(shapes_.at(spot.part, spot.shape));
  return {spot.at.X + offset.first, spot.at.Y + offset.second};
}

// Whether the grown shape at `at` keeps off every placed grown shape (touching allowed).
bool BottomLeftPacker::clear(const Shape& moving, IntPoint at, const std::vector<PlacedShape>& sheet) const {
  for (const PlacedShape& q : sheet) {
    if (overlapping(overlap(moving, at, shapes_.at(q.part, q.shape), q.at), moving)) return false;
  }
  return true;
}

}  // namespace rotafab::jobs::nesting
