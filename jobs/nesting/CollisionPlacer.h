#pragma once
// The first layout: parts placed one by one in a given sequence, each as
// far left and then as low as it goes (of its rotations, the one whose
// area's centroid lies leftmost there), at a cost per part that does not
// grow as the sheets fill. No no-fit polygons: the places are tried
// directly, with the collision detection of jagua-rs (Gardeyn and Wauters,
// "A collision detection engine for 2D irregular cutting and packing
// problems", EJOR 2025): a grid of the placed shapes' hazards, a fail-fast
// test on the inscribed discs (poles), then the exact edge test.
//
// Which places are worth an exact test comes from a clearance raster per
// sheet: for each cell, how far its centre is from the nearest placed
// shape (capped at a bound on any part's largest pole, and a cell:
// PartShapes::largestPoleBound()). A pole of radius r can
// only go where the clearance is at least r, less half a cell's diagonal,
// so a part's largest poles rule out nearly every place on a filling sheet
// by table lookups, and a sheet (or a column of it) with no room for the
// part's largest pole is skipped whole. The places left are tried column
// by column from the left, each column from the bottom; the first free one
// then slides left and down in halving steps until it touches (exact
// tests all along), and a confirmed overlap test by Clipper has the last
// word. Placing a part updates the raster only within the reach of the
// largest pole around it, by a Euclidean distance transform (Felzenszwalb
// and Huttenlocher 2012) of that window.
//
// Sheets fill first fit (a strict order: only the last one), with the
// same order window as the bottom-left packer. One placer per first
// layout; not for two threads at once.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "core/Cancellation.h"
#include "jobs/nesting/Shapes.h"

namespace rotafab::jobs::nesting {

class CollisionPlacer {
 public:
  explicit CollisionPlacer(const PartShapes& shapes, const core::Cancellation* cancellation = nullptr);

  // Lays out the parts in `sequence`; returns placements in cutting order.
  // `policy` Strict fills only the last sheet; otherwise first fit over all
  // sheets (within the order window for Window). Where the pace so far
  // would not finish by `deadline`, parts are tried at their quarter turns
  // only (hurried()). At `deadline` it stops:
  // the result then holds the parts of the sequence placed so far, a
  // leading run of it. Throws std::invalid_argument naming a part that
  // fits no empty sheet (or the strip), core::Cancelled.
  NestingResult place(const std::vector<int>& sequence, OrderMode policy,
                      std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());

  // The last layout, in cutting order, the beds side by side in one row
  // (bed s from s * pitch on: OverlapCompaction's frame).
  [[nodiscard]] const std::vector<PlacedShape>& layout() const { return layout_; }

  // Called for every part placed: parts placed so far, of how many, on how many sheets.
  std::function<void(size_t, size_t, size_t)> onProgress;
  // Called before the next parts of the sequence are placed, kPartsAhead
  // at a time (their shapes can be built then: PartShapes::build()).
  std::function<void(std::span<const int>)> beforeParts;
  static constexpr size_t kPartsAhead = 256;

 private:
  struct Sheet {
    std::vector<PlacedShape> parts;
    double freeArea = 0;
    std::vector<std::vector<int>> hazards;  // per hazard cell, the parts whose grown box meets it
    std::vector<float> clearance;           // per raster cell (column-major), grid units, capped
    std::vector<float> blockMost;           // per block of kBlock x kBlock cells (column-major), its largest
    std::vector<float> blockColumnMost;     // per column of blocks, its largest
    float most = 0;                         // the largest of all
  };

  Sheet newSheet() const;
  // Whether, at the pace of the first `placed` parts, the rest of `of`
  // would take most of the time left to `deadline`: the placer then tries
  // each part at its quarter turns only (PartShapes::quarterOf()).
  static bool hurried(std::chrono::steady_clock::time_point started, std::chrono::steady_clock::time_point deadline,
                      size_t placed, size_t of);
  std::optional<PlacedShape> bestSpot(int part, Sheet& sheet);
  std::optional<PlacedShape> leftmostFor(int part, int k, Sheet& sheet, cInt beyond);
  [[nodiscard]] bool free(const Sheet& sheet, const Shape& shape, IntPoint at);
  [[nodiscard]] bool confirmed(const Sheet& sheet, const Shape& shape, IntPoint at) const;
  IntPoint slide(const Sheet& sheet, const Shape& shape, IntPoint at, const Box& fit);
  [[nodiscard]] bool polesHaveRoom(const Sheet& sheet, const Shape& shape, IntPoint at, size_t from) const;
  void put(Sheet& sheet, const PlacedShape& spot);
  [[nodiscard]] float clearanceAt(const Sheet& sheet, IntPoint p) const;
  template <typename Visit>
  void forHazardCells(const Box& box, Visit&& visit) const;

  const PartShapes& shapes_;
  const core::Cancellation* cancellation_;
  bool quarterTurnsOnly_ = false;                 // hurried(): see place()
  static constexpr size_t kHurryCheckEvery = 32;  // parts placed between checks of the pace
  cInt cell_ = 1;                                 // the raster's cell side
  int columns_ = 0, rows_ = 0;
  static constexpr int kBlock = 16;  // raster cells per block side: the scan skips blocks without room
  // Sheets still open to first fit: trying every sheet for every part made
  // the cost per part grow with the sheets (3.4 ms a part at 8,000 torus
  // panels against 0.34 at 500), for 2% fewer sheets.
  static constexpr int kOpenSheets = 8;
  int blockColumns_ = 0, blockRows_ = 0;
  float cap_ = 0;        // clearances are kept up to this (the largest pole, and a cell)
  float cellReach_ = 0;  // half a cell's diagonal, and the cores' slack: what a lookup may be off by
  cInt hazardCell_ = 1;  // the hazard grid's cell side
  int hazardColumns_ = 0, hazardRows_ = 0;
  std::vector<uint32_t> seen_;  // per part on a sheet: the query that last met it
  uint32_t query_ = 0;
  // put()'s working space, kept between parts: a window can be the whole
  // bed (0.9 MB), and a fresh one each time was a sixth of a large job's
  // first layout in the kernel's clearing of new pages.
  struct Scratch {
    std::vector<float> squared, line, out, bounds;
    std::vector<int> roots;
    std::vector<double> xs;
  } scratch_;
  std::vector<PlacedShape> layout_;
};

}  // namespace rotafab::jobs::nesting
