#pragma once
// One search for a layout (jobs/Nesting.h): from the first layout by the
// collision placer (CollisionPlacer.h) in assembly order (largest first in
// free order), made once for all searches, on jobs of up to kMostPartsForNoFitPolygons parts, a
// local search over the sequence and the rotations by bottom-left placement
// on no-fit polygons (BottomLeftPacker.h), as in Jakobs 1996 and Gomes and
// Oliveira 2002 (swap two parts, within the window when the order is
// bounded, or fix or free a part's rotation; keep the change when the
// layout is no worse), and in free order the compaction (OverlapCompaction.h,
// or on larger jobs on beds SheetEmptying.h) for the rest of the budget. Its course
// is fixed by its seed; the time budget, or a cap on layouts, decides how
// far along it gets. Several run side by side (nest()), and the best wins.

#include <chrono>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "core/WorkContext.h"
#include "jobs/Nesting.h"
#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs::nesting {

// Smaller is better: fewer sheets, then less used of the last sheet (or a shorter strip).
std::pair<int, double> layoutCost(const NestingResult& result, const std::vector<NestingPart>& parts);

// The progress of searches running side by side, each report stamped with
// the seconds since the nesting began and its budget: the first layout's
// progress from the first search only, a layout only when it beats every
// search's best so far, and every few seconds without one, that the search
// goes on (so that a long budget is never silent).
class SharedProgress {
 public:
  SharedProgress(const core::WorkContext& context, std::chrono::steady_clock::time_point started, double budget)
      : context_(context), started_(started), budget_(budget), lastReport_(started) {}
  void remark(unsigned search, core::Progress progress);
  void improved(const std::pair<int, double>& cost, core::Progress progress);
  void stillSearching(unsigned search);
  [[nodiscard]] std::chrono::steady_clock::time_point deadline() const { return deadlineAfter(budget_); }
  // `seconds` from the start of the nesting.
  [[nodiscard]] std::chrono::steady_clock::time_point deadlineAfter(double seconds) const;

 private:
  void report(core::Progress& progress);

  const core::WorkContext& context_;
  const std::chrono::steady_clock::time_point started_;
  const double budget_;
  std::mutex mutex_;
  std::optional<std::pair<int, double>> best_;
  std::chrono::steady_clock::time_point lastReport_;
};

// The first layout, the same for every search and so made once: the
// collision placer in assembly order, or for free order the largest parts
// first; in window order, the strict layout (nothing moves).
struct FirstLayout {
  std::vector<int> sequence;        // the parts in the order they were placed
  NestingResult result;             // the parts placed, in cutting order
  std::vector<PlacedShape> layout;  // the same, the beds side by side (CollisionPlacer::layout())
  // How many of `sequence` were placed: all, unless the budget ran out
  // first (never with a cap on layouts, nor in the strip).
  size_t placed = 0;
};

// Throws core::Cancelled when the context is cancelled.
// The parts' shapes are built as the layout reaches them.
FirstLayout firstLayout(PartShapes& shapes, SharedProgress& progress, const core::WorkContext& context);

// Search number `search` (seed options.seed + search) on the shared shapes,
// from a complete first layout, once every shape is built. Throws core::Cancelled when the context is
// cancelled.
NestingResult searchLayout(const PartShapes& shapes, const FirstLayout& first, unsigned search,
                           SharedProgress& progress, const core::WorkContext& context);

}  // namespace rotafab::jobs::nesting
