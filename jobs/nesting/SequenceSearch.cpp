#include "jobs/nesting/SequenceSearch.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <random>

#include "jobs/nesting/BottomLeftPacker.h"
#include "jobs/nesting/CollisionPlacer.h"
#include "jobs/nesting/OverlapCompaction.h"
#include "jobs/nesting/SheetEmptying.h"

namespace rotafab::jobs::nesting {
namespace {

// The share of the time budget (and of a cap on layouts) that the sequence
// search has in free order; the compaction has the rest.
constexpr double kSequenceShare = 0.15;
// Without a cap on layouts, and with no compaction after it (the order
// kept: kits, window), the sequence search stops after this many tries in a
// row (at least, and per part) that found no better layout: the 6 panels
// of a cube are done in a moment, not in the whole budget.
constexpr int kLeastStalledTries = 200;
constexpr int kStalledTriesPerPart = 20;

}  // namespace

std::pair<int, double> layoutCost(const NestingResult& result, const std::vector<NestingPart>& parts) {
  if (result.sheets == 0) return {0, 0.0};
  double lastExtent = 0;
  for (const auto& p : result.placements) {
    if (p.sheet != result.sheets) continue;
    for (const Point2& v : placedOutline(parts[p.part], p)) lastExtent = std::max(lastExtent, v.x());
  }
  return {result.sheets, lastExtent};
}

// How often a search with nothing better to say says that it goes on.
constexpr std::chrono::seconds kStillSearchingEvery{2};

void SharedProgress::report(core::Progress& progress) {
  const auto now = std::chrono::steady_clock::now();
  progress.elapsed = std::chrono::duration<double>(now - started_).count();
  progress.budget = budget_;
  lastReport_ = now;
  context_.report(progress);
}

void SharedProgress::remark(unsigned search, core::Progress progress) {
  const std::lock_guard lock(mutex_);
  if (search == 0) report(progress);
}

void SharedProgress::improved(const std::pair<int, double>& cost, core::Progress progress) {
  const std::lock_guard lock(mutex_);
  if (best_ && cost >= *best_) return;
  best_ = cost;
  report(progress);
}

void SharedProgress::stillSearching(unsigned search) {
  if (search != 0) return;
  const std::lock_guard lock(mutex_);
  if (std::chrono::steady_clock::now() - lastReport_ < kStillSearchingEvery || !best_) return;
  core::Progress progress{"nesting", "searching", 0, 0, best_->first, best_->second};
  report(progress);
}

std::chrono::steady_clock::time_point SharedProgress::deadlineAfter(double seconds) const {
  return started_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(std::max(0.0, seconds)));
}

FirstLayout firstLayout(PartShapes& shapes, SharedProgress& progress, const core::WorkContext& context) {
  const std::vector<NestingPart>& parts = shapes.parts();
  const NestingOptions& options = shapes.options();
  FirstLayout first;
  first.sequence.resize(parts.size());
  std::vector<int>& sequence = first.sequence;
  std::iota(sequence.begin(), sequence.end(), 0);
  std::stable_sort(sequence.begin(), sequence.end(), [&](int a, int b) { return parts[a].order < parts[b].order; });
  if (options.order == OrderMode::Free) {
    std::stable_sort(sequence.begin(), sequence.end(), [&](int a, int b) {
      return std::abs(polygonArea(parts[a].outline)) > std::abs(polygonArea(parts[b].outline));
    });
  }
  CollisionPlacer placer(shapes, &context.cancellation());
  placer.beforeParts = [&](std::span<const int> upcoming) { shapes.build(upcoming, context); };
  // The first layout can take many seconds (25 s for 100 long strips): say so.
  progress.remark(0, {"nesting", "first layout", 0, parts.size()});
  placer.onProgress = [&](size_t placed, size_t of, size_t sheets) {
    if (placed > 0) progress.remark(0, {"nesting", "first layout", placed, of, static_cast<int>(sheets)});
  };
  // The budget holds for the first layout too, except with a cap on
  // layouts (the same layout on every machine) and in the strip (whose
  // parts could go nowhere else).
  const bool timed = options.evaluations <= 0 && !options.strip;
  // (The window and the kits begin from the assembly order, each sheet filled before the next.)
  const bool fromStrict = options.order == OrderMode::Window || options.order == OrderMode::Kits;
  first.result =
      placer.place(sequence, fromStrict ? OrderMode::Strict : options.order,
                   timed ? progress.deadlineAfter(options.seconds) : std::chrono::steady_clock::time_point::max());
  first.layout = placer.layout();
  first.placed = first.result.placements.size();
  if (first.placed == parts.size()) {
    const auto cost = layoutCost(first.result, parts);
    progress.improved(cost, {"nesting", "first layout", parts.size(), parts.size(), cost.first, cost.second});
  }
  return first;
}

NestingResult searchLayout(const PartShapes& shapes, const FirstLayout& first, unsigned search,
                           SharedProgress& progress, const core::WorkContext& context) {
  const std::vector<NestingPart>& parts = shapes.parts();
  const NestingOptions& options = shapes.options();
  BottomLeftPacker packer(shapes, &context.cancellation());
  std::vector<int> sequence = first.sequence;
  // Window: start from the strict layout (nothing moves) and accept only
  // layouts in which no part is cut more than `window` places from its order.
  auto withinWindow = [&](const NestingResult& result) {
    if (options.order == OrderMode::Kits) return inKits(parts, result);
    if (options.order != OrderMode::Window) return true;
    for (size_t i = 0; i < result.placements.size(); ++i) {
      if (std::abs(static_cast<int>(i) - parts[result.placements[i].part].order) > options.window) return false;
    }
    return true;
  };
  // Kits: each sheet is packed in turn (the packer's strict policy) from a
  // sequence whose parts move within a sheet's worth of places, so that a
  // sheet's own parts, and those at its kit's ends, trade places freely.
  const OrderMode packing = options.order == OrderMode::Kits ? OrderMode::Strict : options.order;
  const long kitSpan = first.result.sheets > 0
                           ? std::max<long>(options.window, static_cast<long>(parts.size()) / first.result.sheets)
                           : options.window;
  std::vector<int> shapeOf(parts.size(), -1);  // forced rotations (index), -1: the best of all
  NestingResult best = first.result;
  std::vector<PlacedShape> bestLayout = first.layout;
  auto bestCost = layoutCost(best, parts);
  // On beds, no layout has fewer sheets than the parts' area fills: once
  // there, the search stops (what it could still do, shorten the last
  // sheet, is not worth the user's wait).
  const int sheetBound = jobs::sheetsTheAreaNeeds(parts, options);
  const auto atBound = [&] { return !options.strip && bestCost.first <= sheetBound; };
  bool stalled = false;
  int evaluations = 1;
  // Improvement: swap two parts of the sequence (within the window when the
  // order is bounded), or fix or free one part's rotation, and keep the
  // change when the layout is no worse.
  // In free order, the sequence search has the first part of the budget and
  // the compaction the rest.
  const bool compaction = options.order == OrderMode::Free && parts.size() > 1;
  const double sequenceShare = compaction ? kSequenceShare : 1.0;
  // The budget left after the first layout: the sequence search has its
  // share, the compaction the rest. With a cap on layouts, the cap decides.
  const auto start = std::chrono::steady_clock::now();
  const auto deadline = options.evaluations > 0 ? std::chrono::steady_clock::time_point::max() : progress.deadline();
  std::mt19937 random(options.seed + search);
  if (options.order != OrderMode::Strict && parts.size() > 1 && shapes.forNoFitPolygons()) {
    const auto searchDeadline = deadline == std::chrono::steady_clock::time_point::max() || deadline <= start
                                    ? deadline
                                    : start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                  sequenceShare * (deadline - start));
    const int lastEvaluation = static_cast<int>(std::ceil(sequenceShare * options.evaluations));
    // Tries in a row that found nothing better: the search has stopped helping.
    int sinceBetter = 0;
    const int mostSinceBetter = std::max(kLeastStalledTries, kStalledTriesPerPart * static_cast<int>(parts.size()));
    while (!atBound() && std::chrono::steady_clock::now() < searchDeadline &&
           (options.evaluations <= 0 || evaluations < lastEvaluation)) {
      // (Not where the compaction follows: it has the rest of the budget, and the strip's density gains from it.)
      if (!compaction && options.evaluations <= 0 && sinceBetter >= mostSinceBetter) {
        stalled = true;
        break;
      }
      ++sinceBetter;
      context.check();
      progress.stillSearching(search);
      std::vector<int> trial = sequence, trialShapes = shapeOf;
      const size_t i = random() % trial.size();
      size_t j = i;
      const unsigned move = random() % 10;
      if (move < 3) {
        // Fix the part's rotation, or free it again.
        const int part = trial[i];
        const int choice = static_cast<int>(random() % (parts[part].rotations.size() + 1)) - 1;
        if (choice == trialShapes[part]) continue;
        trialShapes[part] = choice;
      } else {
        // Swap with a neighbour (small steps) or with any part.
        const long span = options.order == OrderMode::Window ? std::max(1, options.window)
                          : move < 6                         ? 3
                          : options.order == OrderMode::Kits ? kitSpan
                                                             : static_cast<long>(trial.size());
        j = std::clamp<long>(static_cast<long>(i) + static_cast<long>(random() % (2 * span + 1)) - span, 0,
                             static_cast<long>(trial.size()) - 1);
        if (i == j) continue;
        std::swap(trial[i], trial[j]);
      }
      // The parts before the first changed one are placed as before.
      // Without a cap on layouts, a trial that would end past the deadline is given up.
      auto packed = packer.pack(trial, packing, std::min(i, j), trialShapes, searchDeadline);
      if (!packed) break;
      NestingResult result = std::move(*packed);
      ++evaluations;
      const auto trialCost = layoutCost(result, parts);
      if (trialCost <= bestCost && withinWindow(result)) {
        if (trialCost < bestCost) {
          progress.improved(trialCost, {"nesting", "improving", 0, 0, trialCost.first, trialCost.second});
          sinceBetter = 0;
        }
        best = std::move(result);
        bestCost = trialCost;
        sequence = std::move(trial);
        shapeOf = std::move(trialShapes);
        packer.accept();
        bestLayout = packer.acceptedLayout();
      }
    }
  }
  if (compaction && !atBound()) {
    const auto goOn = [&] {
      progress.stillSearching(search);
      return !context.cancelled() && std::chrono::steady_clock::now() < deadline &&
             (options.evaluations <= 0 || evaluations < options.evaluations);
    };
    // Progress while compacting: the layout so far (its exact check comes at the end).
    const auto shorter = [&](int sheets, double length) {
      progress.improved({sheets, length}, {"nesting", "compacting", 0, 0, sheets, length});
    };
    // On a large job on beds, the whole row of beds is too many pairs for
    // the compaction: the beds are emptied one at a time instead.
    NestingResult compacted =
        options.strip || shapes.forNoFitPolygons()
            ? OverlapCompaction(shapes).compact(bestLayout, random, goOn, evaluations, shorter)
            : SheetEmptying(shapes).empty(bestLayout, sheetBound, random, goOn, evaluations, shorter);
    context.check();
    stalled = compacted.stopped == "no better layout";
    // The compaction lets grown shapes reach into each other by a few grid
    // units; the layout is kept only if the true outlines keep the spacing
    // (within layoutProblems' tolerance).
    if (layoutCost(compacted, parts) < layoutCost(best, parts) &&
        layoutProblems(parts, compacted, options, 1e-3, &context.cancellation()).empty()) {
      best = std::move(compacted);
    }
  }
  best.evaluations = evaluations;
  best.stopped = atBound()                                                       ? "area bound"
                 : stalled                                                       ? "no better layout"
                 : options.evaluations > 0 && evaluations >= options.evaluations ? "layout cap"
                                                                                 : "time budget";
  return best;
}

}  // namespace rotafab::jobs::nesting
