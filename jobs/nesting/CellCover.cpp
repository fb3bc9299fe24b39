#include "jobs/nesting/CellCover.h"

#include <algorithm>
#include <cmath>

namespace rotafab::jobs::nesting {

using ClipperLib::cInt;
using ClipperLib::IntPoint;

CellCover::CellCover(const ClipperLib::Paths& region, const Box& bounds, cInt cell, long maxCells)
    : x0_(bounds[0]), y0_(bounds[1]), cell_(std::max<cInt>(cell, 1)) {
  const double width = static_cast<double>(bounds[2] - bounds[0]) + 1,
               height = static_cast<double>(bounds[3] - bounds[1]) + 1;
  if (width / cell_ * (height / cell_) > static_cast<double>(maxCells)) {
    cell_ = static_cast<cInt>(std::ceil(std::sqrt(width * height / static_cast<double>(maxCells))));
  }
  columns_ = static_cast<int>(std::ceil(width / cell_)) + 1;
  rows_ = static_cast<int>(std::ceil(height / cell_)) + 1;
  cells_.assign(static_cast<size_t>(columns_) * rows_, 0);
  // The boundary: every cell an edge passes through. Samples half a cell
  // apart, each pair of neighbours marking the cells of their bounding box,
  // so that no cell the edge crosses (even at a corner) is missed.
  for (const auto& path : region) {
    for (size_t i = 0; i < path.size(); ++i) {
      const IntPoint& a = path[i];
      const IntPoint& b = path[(i + 1) % path.size()];
      const double length = std::hypot(static_cast<double>(b.X - a.X), static_cast<double>(b.Y - a.Y));
      const int steps = std::max(1, static_cast<int>(std::ceil(2 * length / cell_)));
      int previousColumn = column(a.X), previousRow = row(a.Y);
      for (int s = 1; s <= steps; ++s) {
        const cInt x = a.X + static_cast<cInt>(std::llround(static_cast<double>(b.X - a.X) * s / steps));
        const cInt y = a.Y + static_cast<cInt>(std::llround(static_cast<double>(b.Y - a.Y) * s / steps));
        const int c = column(x), r = row(y);
        for (int cc = std::min(c, previousColumn); cc <= std::max(c, previousColumn); ++cc) {
          for (int rr = std::min(r, previousRow); rr <= std::max(r, previousRow); ++rr) mark(cc, rr);
        }
        previousColumn = c, previousRow = r;
      }
    }
  }
  // The inside: cells whose centre is inside, by crossings along each row's centre line.
  std::vector<double> crossings;
  for (int r = 0; r < rows_; ++r) {
    const double y = static_cast<double>(y0_) + (r + 0.5) * static_cast<double>(cell_);
    crossings.clear();
    for (const auto& path : region) {
      for (size_t i = 0; i < path.size(); ++i) {
        const IntPoint& a = path[i];
        const IntPoint& b = path[(i + 1) % path.size()];
        if ((a.Y <= y) == (b.Y <= y)) continue;
        crossings.push_back(a.X + (y - a.Y) * static_cast<double>(b.X - a.X) / static_cast<double>(b.Y - a.Y));
      }
    }
    std::sort(crossings.begin(), crossings.end());
    for (size_t i = 0; i + 1 < crossings.size(); i += 2) {
      const int first = std::max(0, static_cast<int>(std::ceil((crossings[i] - x0_) / cell_ - 0.5)));
      const int last = std::min(columns_ - 1, static_cast<int>(std::floor((crossings[i + 1] - x0_) / cell_ - 0.5)));
      for (int c = first; c <= last; ++c) mark(c, r);
    }
  }
  sums_.assign(static_cast<size_t>(rows_ + 1) * (columns_ + 1), 0);
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < columns_; ++c) {
      const size_t at = static_cast<size_t>(r + 1) * (columns_ + 1) + (c + 1);
      sums_[at] = cells_[static_cast<size_t>(r) * columns_ + c] + sums_[at - 1] + sums_[at - (columns_ + 1)] -
                  sums_[at - (columns_ + 1) - 1];
    }
  }
  marked_ = sums_.back();
  for (int r = 0; r < rows_; ++r) {
    for (int c = 0; c < columns_;) {
      if (!cells_[static_cast<size_t>(r) * columns_ + c]) {
        ++c;
        continue;
      }
      int end = c;
      while (end + 1 < columns_ && cells_[static_cast<size_t>(r) * columns_ + end + 1]) ++end;
      runs_.push_back({x0_ + c * cell_, y0_ + r * cell_, x0_ + (end + 1) * cell_, y0_ + (r + 1) * cell_});
      c = end + 1;
    }
  }
}

int CellCover::column(cInt x) const {
  return std::clamp(static_cast<int>((x - x0_) / cell_ - (x < x0_ ? 1 : 0)), 0, columns_ - 1);
}

int CellCover::row(cInt y) const {
  return std::clamp(static_cast<int>((y - y0_) / cell_ - (y < y0_ ? 1 : 0)), 0, rows_ - 1);
}

bool CellCover::meets(const Box& box) const {
  if (box[2] < x0_ || box[3] < y0_ || box[0] > x0_ + columns_ * cell_ || box[1] > y0_ + rows_ * cell_) return false;
  const int c0 = column(box[0]), c1 = column(box[2]), r0 = row(box[1]), r1 = row(box[3]);
  const auto at = [&](int r, int c) { return sums_[static_cast<size_t>(r) * (columns_ + 1) + c]; };
  return at(r1 + 1, c1 + 1) - at(r0, c1 + 1) - at(r1 + 1, c0) + at(r0, c0) > 0;
}

}  // namespace rotafab::jobs::nesting
