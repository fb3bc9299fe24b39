#pragma once
// A region covered by the cells of a coarse grid: every cell that meets the
// region (its boundary or its inside) is marked, so the marked cells hold the
// whole region. It answers "might this box meet the region?" in constant time
// from a summed-area table, and gives the marked cells as row runs. The nester
// uses it to skip the no-fit polygons that cannot touch the places where a
// part still has room.

#include <clipper.hpp>

#include <array>
#include <vector>

namespace rotafab::jobs::nesting {

using Box = std::array<ClipperLib::cInt, 4>;  // min x, min y, max x, max y (closed)

class CellCover {
 public:
  // `region`: closed paths, outer contours and holes as Clipper returns them
  // (even-odd and non-zero filling agree). `bounds` holds the region; `cell`
  // is the cell's side, raised so that the grid has at most `maxCells` cells.
  CellCover(const ClipperLib::Paths& region, const Box& bounds, ClipperLib::cInt cell, long maxCells = 1 << 16);

  bool empty() const { return marked_ == 0; }
  // Whether any marked cell meets the box (false means the box misses the region).
  bool meets(const Box& box) const;
  // The marked cells, as boxes of whole runs along each row.
  const std::vector<Box>& runs() const { return runs_; }

 private:
  int column(ClipperLib::cInt x) const;
  int row(ClipperLib::cInt y) const;
  void mark(int c, int r) { cells_[static_cast<size_t>(r) * columns_ + c] = 1; }

  ClipperLib::cInt x0_, y0_, cell_;
  int columns_ = 0, rows_ = 0;
  long marked_ = 0;
  std::vector<unsigned char> cells_;
  std::vector<long> sums_;  // (rows + 1) x (columns + 1) summed-area table
  std::vector<Box> runs_;
};

}  // namespace rotafab::jobs::nesting
