#pragma once
// Bottom-left placement of parts one by one in a given sequence (Dowsland,
// Vaid and Dowsland 2002; with no-fit polygons, Burke et al. 2006): each
// part goes at the leftmost, then lowest, vertex of its feasible region, the
// inner-fit rectangle of the area minus the no-fit polygons of the parts
// already on the sheet (NoFitPolygons.h), each candidate confirmed by an
// exact overlap test so that no rounding lets two parts overlap. Only the
// no-fit polygons near the places where a part's inscribed discs still have
// room on the sheet are built (CellCover.h). Sheets fill first fit, or only
// the last one for a strict order. Layouts of sequences that share a start
// resume from a checkpoint of the last accepted one.
//
// One packer per search; not for two threads at once.

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "core/Cancellation.h"
#include "jobs/nesting/CellCover.h"
#include "jobs/nesting/NoFitPolygons.h"
#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs::nesting {

class BottomLeftPacker {
 public:
  // `cancellation`, when given, is checked for every part placed (and
  // within each placement): pack() then throws core::Cancelled.
  BottomLeftPacker(const PartShapes& shapes, const core::Cancellation* cancellation = nullptr)
      : shapes_(shapes), noFitPolygons_(shapes, cancellation), cancellation_(cancellation) {}

  // Lays out the parts in `sequence`; returns placements in cutting order.
  // `policy` Strict fills only the last sheet; otherwise first fit over all sheets.
  //
  // `unchanged`: how many leading parts of `sequence` are those of the last
  // accepted sequence (see accept()); the layout resumes from the latest
  // checkpoint among them instead of starting over.
  // `shapeOf[part]`, when given and not negative, is the only rotation (index
  // into the part's rotations) tried for the part, unless it cannot go on an empty sheet.
  //
  // `until`: a trial layout is given up (nothing returned) once past it, so
  // that the search keeps to its time budget.
  std::optional<NestingResult> pack(
      const std::vector<int>& sequence, OrderMode policy, size_t unchanged = 0, const std::vector<int>& shapeOf = {},
      std::chrono::steady_clock::time_point until = std::chrono::steady_clock::time_point::max());

  // The last pack() becomes the sequence later calls compare with: its
  // checkpoints, and the earlier ones it resumed from, are kept.
  void accept();

  // The accepted layout, in cutting order, the beds side by side in one row
  // (bed s from s * pitch on: OverlapCompaction's frame).
  [[nodiscard]] const std::vector<PlacedShape>& acceptedLayout() const { return acceptedLayout_; }

  // Called for every part placed while pack() works: parts placed so far, of how many, on how many sheets.
  std::function<void(size_t, size_t, size_t)> onProgress;

 private:
  // A bed (or the strip) being filled.
  struct Sheet {
    std::vector<PlacedShape> parts;
    Paths occupied;  // the union of the placed grown shapes
    double freeArea = 0;
    // Radius -> the centres of discs of that radius clear of `occupied` and on
    // the area: a shape holding such a disc can only go where its disc's centre
    // is in this region, so only the no-fit polygons near it matter.
    struct Room {
      Paths centres;  // the region
      size_t upTo;    // of `parts`, those kept clear of; the later ones are taken out when next asked for
      CellCover cover;
    };
    std::map<cInt, Room> room;
  };
  // The state of a layout part way through a sequence.
  struct PackState {
    std::vector<Sheet> sheets;
    std::vector<std::pair<int, PlacedShape>> placed;  // (sheet, shape) in placing order
  };
  static constexpr size_t kCheckpointEvery = 8;

  void put(Sheet& sheet, const PlacedShape& spot);
  const CellCover& room(Sheet& sheet, cInt radius);
  [[nodiscard]] Box roomBounds() const;
  std::optional<PlacedShape> bestSpot(int part, Sheet& sheet, int only);
  std::optional<PlacedShape> bestLeftOf(int part, int k, const Sheet& sheet, const std::vector<Box>& search, cInt upTo,
                                        const std::function<bool(const Box&)>& mightFit,
                                        const std::optional<PlacedShape>& best);
  // Bottom-left across rotations compares where the parts themselves would
  // be (the lower left corner of their box), not their reference points:
  // smaller is better. Measured on six ESICUP instances, 5 s each: this beat
  // reference points on four (dagli 80.4% against 76.4%) and lost on none;
  // the right edge instead of the left lost on two.
  static std::pair<cInt, cInt> rankOffset(const Shape& shape) { return {shape.minX, shape.minY}; }
  [[nodiscard]] std::pair<cInt, cInt> rankOf(const PlacedShape& spot) const;
  [[nodiscard]] bool clear(const Shape& moving, IntPoint at, const std::vector<PlacedShape>& sheet) const;
  void checkCancelled() const {
    if (cancellation_) cancellation_->check();
  }

  const PartShapes& shapes_;
  NoFitPolygons noFitPolygons_;
  const core::Cancellation* cancellation_;
  std::vector<PlacedShape> lastLayout_, acceptedLayout_;          // in cutting order
  std::vector<std::pair<size_t, PackState>> accepted_, pending_;  // (parts placed, state), ascending
  size_t pendingStart_ = 0;
  std::optional<OrderMode> acceptedPolicy_, pendingPolicy_;
};

}  // namespace rotafab::jobs::nesting
