#include "jobs/nesting/CollisionPlacer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rotafab::jobs::nesting {
namespace {

constexpr float kFar = std::numeric_limits<float>::max();

// Squared Euclidean distance transform of one line (Felzenszwalb and
// Huttenlocher 2012, "Distance transforms of sampled functions"): `f` in,
// the lower envelope of the parabolas rooted at each sample out, in place.
void distanceTransform(std::vector<float>& f, std::vector<int>& roots, std::vector<float>& bounds,
                       std::vector<float>& out) {
  const int n = static_cast<int>(f.size());
  roots.assign(static_cast<size_t>(n), 0);
  bounds.assign(static_cast<size_t>(n) + 1, 0);
  out.assign(static_cast<size_t>(n), 0);
  int k = -1;
  for (int q = 0; q < n; ++q) {
    if (f[q] >= kFar) continue;
    float s = -kFar;
    while (k >= 0) {
      const int r = roots[k];
      s = ((f[q] + static_cast<float>(q) * q) - (f[r] + static_cast<float>(r) * r)) /
          (2.0f * static_cast<float>(q - r));
      if (s > bounds[k]) break;
      --k;
    }
    ++k;
    roots[k] = q;
    bounds[k] = k == 0 ? -kFar : s;
    bounds[k + 1] = kFar;
  }
  if (k < 0) {
    std::fill(out.begin(), out.end(), kFar);
  } else {
    int j = 0;
    for (int q = 0; q < n; ++q) {
      while (bounds[j + 1] < static_cast<float>(q)) ++j;
      const float d = static_cast<float>(q - roots[j]);
      out[q] = d * d + f[roots[j]];
    }
  }
  f.swap(out);
}

// The x where the edges of `polygon` cross the line at height y, sorted:
// between each pair is inside.
void crossings(const Path& polygon, IntPoint at, double y, std::vector<double>& xs) {
  xs.clear();
  for (size_t i = 0; i < polygon.size(); ++i) {
    const double ax = static_cast<double>(polygon[i].X + at.X), ay = static_cast<double>(polygon[i].Y + at.Y);
    const IntPoint& b = polygon[(i + 1) % polygon.size()];
    const double bx = static_cast<double>(b.X + at.X), by = static_cast<double>(b.Y + at.Y);
    if ((ay <= y) == (by <= y)) continue;
    xs.push_back(ax + (y - ay) * (bx - ax) / (by - ay));
  }
  std::sort(xs.begin(), xs.end());
}

}  // namespace

CollisionPlacer::CollisionPlacer(const PartShapes& shapes, const core::Cancellation* cancellation)
    : shapes_(shapes), cancellation_(cancellation) {
  cell_ = std::max<cInt>(1, shapes.roomScale().radiusStep);
  // One cell of margin each side: grown shapes overhang the area a little.
  columns_ = static_cast<int>((shapes.width() + 2 * cell_) / cell_) + 1;
  rows_ = static_cast<int>((shapes.height() + 2 * cell_) / cell_) + 1;
  blockColumns_ = (columns_ + kBlock - 1) / kBlock;
  blockRows_ = (rows_ + kBlock - 1) / kBlock;
  // Any cap no less than every pole's radius and a cell gives the same
  // layout (a pole tests the raster against its own radius); a larger one
  // only makes put()'s windows larger.
  cap_ = static_cast<float>(shapes.largestPoleBound() + static_cast<double>(cell_));
  std::vector<cInt> sizes;
  for (size_t part = 0; part < shapes.parts().size(); ++part) sizes.push_back(shapes.sizeBound(static_cast<int>(part)));
  // The core is `grown` shrunk with mitres: at a reflex corner up to twice kCollisionSlack inside it.
  cellReach_ = static_cast<float>(static_cast<double>(cell_) * std::sqrt(0.5) + 2 * kCollisionSlack + 2);
  // Hazard cells about as large as a typical part: a query meets a few
  // cells of a few parts each.
  std::nth_element(sizes.begin(), sizes.begin() + static_cast<long>(sizes.size() / 2), sizes.end());
  hazardCell_ = std::max(cell_ * 4, sizes.empty() ? cell_ : sizes[sizes.size() / 2]);
  while ((shapes.width() / hazardCell_ + 3) * (shapes.height() / hazardCell_ + 3) > 1 << 16) hazardCell_ *= 2;
  hazardColumns_ = static_cast<int>((shapes.width() + 2 * hazardCell_) / hazardCell_) + 1;
  hazardRows_ = static_cast<int>((shapes.height() + 2 * hazardCell_) / hazardCell_) + 1;
}

CollisionPlacer::Sheet CollisionPlacer::newSheet() const {
  Sheet sheet;
  sheet.freeArea = static_cast<double>(shapes_.width()) * static_cast<double>(shapes_.height());
  sheet.hazards.resize(static_cast<size_t>(hazardColumns_) * hazardRows_);
  sheet.clearance.assign(static_cast<size_t>(columns_) * rows_, cap_);
  sheet.blockMost.assign(static_cast<size_t>(blockColumns_) * blockRows_, cap_);
  sheet.blockColumnMost.assign(static_cast<size_t>(blockColumns_), cap_);
  sheet.most = cap_;
  return sheet;
}

NestingResult CollisionPlacer::place(const std::vector<int>& sequence, OrderMode policy,
                                     std::chrono::steady_clock::time_point deadline) {
  std::vector<Sheet> sheets;
  std::vector<std::pair<int, PlacedShape>> placed;  // (sheet, shape) in placing order
  const NestingOptions& options = shapes_.options();
  const bool timed = deadline != std::chrono::steady_clock::time_point::max();
  size_t aheadTo = 0;  // beforeParts has been called for the sequence up to here
  const auto started = std::chrono::steady_clock::now();
  quarterTurnsOnly_ = false;
  for (size_t index = 0; index < sequence.size(); ++index) {
    if (cancellation_) cancellation_->check();
    if (timed && std::chrono::steady_clock::now() >= deadline) break;
    if (timed && index >= kHurryCheckEvery && index % kHurryCheckEvery == 0)
      quarterTurnsOnly_ = hurried(started, deadline, index, sequence.size());
    if (beforeParts && index == aheadTo) {
      aheadTo = std::min(sequence.size(), index + kPartsAhead);
      beforeParts(std::span<const int>(sequence).subspan(index, aheadTo - index));
    }
    const int part = sequence[index];
    if (!shapes_.built(part)) throw std::logic_error("internal: a part is placed before its shapes are built");
    if (onProgress) onProgress(index, sequence.size(), sheets.size());
    bool done = false;
    // First fit over the sheets still open: the last kOpenSheets.
    const int openFrom = std::max(0, static_cast<int>(sheets.size()) - kOpenSheets);
    for (int s = openFrom; s < static_cast<int>(sheets.size()) && !done; ++s) {
      if (!mayGoOn(shapes_, policy, sheets, s, part)) continue;
      if (sheets[s].freeArea < shapes_.area(part)) continue;
      if (auto spot = bestSpot(part, sheets[s])) {
        put(sheets[s], *spot);
        placed.emplace_back(s, *spot);
        done = true;
      }
    }
    if (!done && options.strip && !sheets.empty()) {
      throw std::invalid_argument(fmt::format("{} does not fit the strip", shapes_.parts()[part].name));
    }
    if (!done) {
      sheets.push_back(newSheet());
      auto spot = bestSpot(part, sheets.back());
      if (!spot) throw std::invalid_argument(fmt::format("{} does not fit an empty sheet", shapes_.parts()[part].name));
      put(sheets.back(), *spot);
      placed.emplace_back(static_cast<int>(sheets.size()) - 1, *spot);
    }
  }
  // The sheets closed early may still have room for the last sheet's
  // parts, the smallest: each tries them all, first fit, and the last
  // sheet goes if it empties. (Its own raster is not updated: nothing
  // more is placed on it.)
  if (policy == OrderMode::Free && sheets.size() > static_cast<size_t>(kOpenSheets) &&
      placed.size() == sequence.size()) {
    const int last = static_cast<int>(sheets.size()) - 1;
    bool emptied = true;
    for (auto& [sheet, spot] : placed) {
      if (sheet != last) continue;
      if (cancellation_) cancellation_->check();
      bool moved = false;
      for (int s = 0; s < last - kOpenSheets + 1 && !moved; ++s) {
        if (sheets[s].freeArea < shapes_.area(spot.part)) continue;
        if (auto elsewhere = bestSpot(spot.part, sheets[s])) {
          put(sheets[s], *elsewhere);
          sheet = s, spot = *elsewhere, moved = true;
        }
      }
      emptied = emptied && moved;
    }
    if (emptied) sheets.pop_back();
  }
  return shapes_.inCuttingOrder(placed, static_cast<int>(sheets.size()), layout_);
}

// Across rotations, the leftmost place of each is ranked by where it puts
// the part's mass, its area's centroid, leftmost and then lowest: the turn
// that reaches furthest left with an arm's tip alone (the box's corner,
// the bottom-left packer's rank) leaves its body further right and the
// gap behind it open. On the bunny's panels in kits, 186 parts a sheet
// against 180, and in the free order 19 sheets against 20, at the same
// cost (docs/PERFORMANCE.md, "Kits and the free order").
std::optional<PlacedShape> CollisionPlacer::bestSpot(int part, Sheet& sheet) {
  std::optional<PlacedShape> best;
  std::pair<cInt, cInt> bestRank{std::numeric_limits<cInt>::max(), std::numeric_limits<cInt>::max()};
  // (A part with no quarter turn among its rotations keeps all of them.)
  const bool quartersOnly = quarterTurnsOnly_ && shapes_.firstQuarter(part) < 4;
  for (int k = 0; k < static_cast<int>(shapes_.of(part).size()); ++k) {
    if (cancellation_) cancellation_->check();
    if (quartersOnly && shapes_.quarterOf(part, k) < 0) continue;
    const Shape& shape = shapes_.at(part, k);
    // A place whose box starts right of this has its centroid right of the best so far.
    const cInt beyond = bestRank.first == std::numeric_limits<cInt>::max()
                            ? bestRank.first
                            : bestRank.first - (shape.centroid.X - shape.minX);
    auto spot = leftmostFor(part, k, sheet, beyond);
    if (!spot) continue;
    const std::pair<cInt, cInt> rank{spot->at.X + shape.centroid.X, spot->at.Y + shape.centroid.Y};
    if (rank < bestRank) best = spot, bestRank = rank;
  }
  return best;
}

bool CollisionPlacer::hurried(std::chrono::steady_clock::time_point started,
                              std::chrono::steady_clock::time_point deadline, size_t placed, size_t of) {
  // The rest at the pace so far, against most of the time left: on a
  // slower or busier machine than the turns were chosen on, the parts
  // still get placed, at fewer turns, instead of in rows.
  constexpr double kShareOfTimeLeft = 0.8;
  const auto now = std::chrono::steady_clock::now();
  const double spent = std::chrono::duration<double>(now - started).count();
  const double left = std::chrono::duration<double>(deadline - now).count();
  return spent / static_cast<double>(placed) * static_cast<double>(of - placed) > kShareOfTimeLeft * left;
}

// The first free place, column by column from the left, for shape k of
// `part` whose box would start no further right than `beyond`, slid left
// and down until it touches.
std::optional<PlacedShape> CollisionPlacer::leftmostFor(int part, int k, Sheet& sheet, cInt beyond) {
  const Shape& shape = shapes_.at(part, k);
  // Inner-fit rectangle: reference positions keeping the true outline on the area.
  const Box fit{-shape.minX, -shape.minY, shapes_.width() - shape.maxX, shapes_.height() - shape.maxY};
  if (fit[2] < fit[0] || fit[3] < fit[1]) return std::nullopt;
  const Shape::Pole& pole = shape.poles.front();
  const float needed = static_cast<float>(pole.radius) - cellReach_;
  if (sheet.most < needed) return std::nullopt;
  const auto cellOf = [&](cInt v) { return static_cast<int>((v + cell_) / cell_); };
  const auto centreOf = [&](int i) { return static_cast<cInt>(i) * cell_ - cell_ + cell_ / 2; };
  const int firstColumn = std::clamp(cellOf(fit[0] + pole.centre.X), 0, columns_ - 1);
  const int lastColumn = std::clamp(cellOf(fit[2] + pole.centre.X), 0, columns_ - 1);
  const int firstRow = std::clamp(cellOf(fit[1] + pole.centre.Y), 0, rows_ - 1);
  const int lastRow = std::clamp(cellOf(fit[3] + pole.centre.Y), 0, rows_ - 1);
  const int firstBlockRow = firstRow / kBlock, lastBlockRow = lastRow / kBlock;
  std::vector<int> open;  // the rows of blocks with room in this column of blocks
  for (int bi = firstColumn / kBlock; bi <= lastColumn / kBlock; ++bi) {
    if (sheet.blockColumnMost[static_cast<size_t>(bi)] < needed) continue;
    const float* blocks = &sheet.blockMost[static_cast<size_t>(bi) * blockRows_];
    open.clear();
    for (int bj = firstBlockRow; bj <= lastBlockRow; ++bj) {
      if (blocks[bj] >= needed) open.push_back(bj);
    }
    for (int i = std::max(firstColumn, bi * kBlock); i <= std::min(lastColumn, bi * kBlock + kBlock - 1); ++i) {
      const cInt atX = std::clamp(centreOf(i) - pole.centre.X, fit[0], fit[2]);
      if (atX + shape.minX > beyond) return std::nullopt;
      const float* column = &sheet.clearance[static_cast<size_t>(i) * rows_];
      for (int bj : open) {
        for (int j = std::max(firstRow, bj * kBlock); j <= std::min(lastRow, bj * kBlock + kBlock - 1); ++j) {
          if (column[j] < needed) continue;
          const IntPoint at{atX, std::clamp(centreOf(j) - pole.centre.Y, fit[1], fit[3])};
          if (!polesHaveRoom(sheet, shape, at, 1) || !free(sheet, shape, at)) continue;
          const IntPoint slid = slide(sheet, shape, at, fit);
          if (confirmed(sheet, shape, slid)) return PlacedShape{part, k, slid};
          if (confirmed(sheet, shape, at)) return PlacedShape{part, k, at};
        }
      }
    }
  }
  return std::nullopt;
}

// Whether the shape's poles after `from` (the largest few) have room at `at`, by the raster.
bool CollisionPlacer::polesHaveRoom(const Sheet& sheet, const Shape& shape, IntPoint at, size_t from) const {
  constexpr size_t kPolesLookedUp = 4;
  for (size_t p = from; p < std::min(shape.poles.size(), kPolesLookedUp); ++p) {
    const Shape::Pole& pole = shape.poles[p];
    if (clearanceAt(sheet, {at.X + pole.centre.X, at.Y + pole.centre.Y}) + cellReach_ < static_cast<float>(pole.radius))
      return false;
  }
  return true;
}

float CollisionPlacer::clearanceAt(const Sheet& sheet, IntPoint p) const {
  const int i = std::clamp(static_cast<int>((p.X + cell_) / cell_), 0, columns_ - 1);
  const int j = std::clamp(static_cast<int>((p.Y + cell_) / cell_), 0, rows_ - 1);
  return sheet.clearance[static_cast<size_t>(i) * rows_ + j];
}

template <typename Visit>
void CollisionPlacer::forHazardCells(const Box& box, Visit&& visit) const {
  const auto index = [&](cInt v, int count) {
    return std::clamp(static_cast<int>((v + hazardCell_) / hazardCell_), 0, count - 1);
  };
  const int i0 = index(box[0], hazardColumns_), i1 = index(box[2], hazardColumns_);
  const int j0 = index(box[1], hazardRows_), j1 = index(box[3], hazardRows_);
  for (int i = i0; i <= i1; ++i) {
    for (int j = j0; j <= j1; ++j) {
      if (!visit(static_cast<size_t>(i) * hazardRows_ + j)) return;
    }
  }
}

// Whether the shape at `at` meets no placed shape, by the cores' edge test.
bool CollisionPlacer::free(const Sheet& sheet, const Shape& shape, IntPoint at) {
  if (++query_ == 0) std::fill(seen_.begin(), seen_.end(), 0), query_ = 1;
  bool hit = false;
  const Box box{at.X + shape.grownMinX, at.Y + shape.grownMinY, at.X + shape.grownMaxX, at.Y + shape.grownMaxY};
  forHazardCells(box, [&](size_t cell) {
    for (int index : sheet.hazards[cell]) {
      if (seen_[static_cast<size_t>(index)] == query_) continue;
      seen_[static_cast<size_t>(index)] = query_;
      const PlacedShape& q = sheet.parts[static_cast<size_t>(index)];
      const Shape& other = shapes_.of(q);
      if (boxesApart(shape, at, other, q.at)) continue;
      if (coresColliding(shape, at, other, q.at)) {
        hit = true;
        return false;
      }
    }
    return true;
  });
  return !hit;
}

// The last word on a place: no placed core has area in common with this one (Clipper).
bool CollisionPlacer::confirmed(const Sheet& sheet, const Shape& shape, IntPoint at) const {
  std::vector<int> near;
  const Box box{at.X + shape.grownMinX, at.Y + shape.grownMinY, at.X + shape.grownMaxX, at.Y + shape.grownMaxY};
  forHazardCells(box, [&](size_t cell) {
    near.insert(near.end(), sheet.hazards[cell].begin(), sheet.hazards[cell].end());
    return true;
  });
  std::sort(near.begin(), near.end());
  near.erase(std::unique(near.begin(), near.end()), near.end());
  return std::none_of(near.begin(), near.end(), [&](int index) {
    const PlacedShape& q = sheet.parts[static_cast<size_t>(index)];
    return !boxesApart(shape, at, shapes_.of(q), q.at) && coresOverlap(shape, at, shapes_.of(q), q.at);
  });
}

// From a free place, left and then down in steps that halve when neither
// is free, down to one grid unit: the part ends touching what is left of
// and below it.
IntPoint CollisionPlacer::slide(const Sheet& sheet, const Shape& shape, IntPoint at, const Box& fit) {
  for (cInt step = cell_; step >= 1;) {
    const IntPoint left{std::max(fit[0], at.X - step), at.Y};
    if (left.X != at.X && free(sheet, shape, left)) {
      at = left;
      continue;
    }
    const IntPoint down{at.X, std::max(fit[1], at.Y - step)};
    if (down.Y != at.Y && free(sheet, shape, down)) {
      at = down;
      continue;
    }
    step /= 2;
  }
  return at;
}

void CollisionPlacer::put(Sheet& sheet, const PlacedShape& spot) {
  const Shape& shape = shapes_.of(spot);
  const int index = static_cast<int>(sheet.parts.size());
  sheet.parts.push_back(spot);
  if (seen_.size() < sheet.parts.size()) seen_.resize(sheet.parts.size() * 2, 0);
  sheet.freeArea -= shapes_.area(spot.part);
  const IntPoint at = spot.at;
  forHazardCells({at.X + shape.grownMinX, at.Y + shape.grownMinY, at.X + shape.grownMaxX, at.Y + shape.grownMaxY},
                 [&](size_t cell) {
                   sheet.hazards[cell].push_back(index);
                   return true;
                 });
  // The clearance raster within reach of the shape: the distance from each
  // cell's centre to the nearest centre inside the placed core (a subset of
  // it, so the distance is never less than the true one), capped.
  const auto cellOf = [&](cInt v) { return std::clamp(static_cast<int>((v + cell_) / cell_), 0, columns_ - 1); };
  const auto rowOf = [&](cInt v) { return std::clamp(static_cast<int>((v + cell_) / cell_), 0, rows_ - 1); };
  const cInt reach = static_cast<cInt>(std::ceil(cap_));
  const int i0 = cellOf(at.X + shape.coreBox[0] - reach), i1 = cellOf(at.X + shape.coreBox[2] + reach);
  const int j0 = rowOf(at.Y + shape.coreBox[1] - reach), j1 = rowOf(at.Y + shape.coreBox[3] + reach);
  const int width = i1 - i0 + 1, height = j1 - j0 + 1;
  std::vector<float>& squared = scratch_.squared;  // column-major within the window
  squared.assign(static_cast<size_t>(width) * height, kFar);
  std::vector<double>& xs = scratch_.xs;
  bool any = false;
  for (int j = rowOf(at.Y + shape.coreBox[1]); j <= rowOf(at.Y + shape.coreBox[3]); ++j) {
    const double y = static_cast<double>(static_cast<cInt>(j) * cell_ - cell_ + cell_ / 2);
    crossings(shape.core, at, y, xs);
    for (size_t c = 0; c + 1 < xs.size(); c += 2) {
      // Cells whose centre x lies in [xs[c], xs[c + 1]].
      const double from =
          std::ceil((xs[c] + static_cast<double>(cell_) - static_cast<double>(cell_ / 2)) / static_cast<double>(cell_));
      const double to = std::floor((xs[c + 1] + static_cast<double>(cell_) - static_cast<double>(cell_ / 2)) /
                                   static_cast<double>(cell_));
      for (int i = std::max(i0, static_cast<int>(from)); i <= std::min(i1, static_cast<int>(to)); ++i) {
        squared[static_cast<size_t>(i - i0) * height + (j - j0)] = 0;
        any = true;
      }
    }
  }
  if (!any) return;  // too thin to hold a cell's centre: it blocks nothing in the raster
  std::vector<float>&line = scratch_.line, &out = scratch_.out, &bounds = scratch_.bounds;
  std::vector<int>& roots = scratch_.roots;
  for (int i = 0; i < width; ++i) {  // along each column
    line.assign(squared.begin() + static_cast<long>(i) * height, squared.begin() + static_cast<long>(i + 1) * height);
    distanceTransform(line, roots, bounds, out);
    std::copy(line.begin(), line.end(), squared.begin() + static_cast<long>(i) * height);
  }
  for (int j = 0; j < height; ++j) {  // then along each row
    line.resize(static_cast<size_t>(width));
    for (int i = 0; i < width; ++i) line[i] = squared[static_cast<size_t>(i) * height + j];
    distanceTransform(line, roots, bounds, out);
    for (int i = 0; i < width; ++i) squared[static_cast<size_t>(i) * height + j] = line[i];
  }
  const float cell = static_cast<float>(cell_);
  for (int i = 0; i < width; ++i) {
    float* column = &sheet.clearance[static_cast<size_t>(i0 + i) * rows_];
    for (int j = 0; j < height; ++j) {
      const float d = squared[static_cast<size_t>(i) * height + j];
      if (d < kFar) column[j0 + j] = std::min(column[j0 + j], std::sqrt(d) * cell);
    }
  }
  // The blocks the window meets, and their columns.
  for (int bi = i0 / kBlock; bi <= i1 / kBlock; ++bi) {
    for (int bj = j0 / kBlock; bj <= j1 / kBlock; ++bj) {
      float most = 0;
      for (int i = bi * kBlock; i < std::min(columns_, bi * kBlock + kBlock); ++i) {
        const float* column = &sheet.clearance[static_cast<size_t>(i) * rows_];
        most = std::max(most, *std::max_element(column + bj * kBlock, column + std::min(rows_, bj * kBlock + kBlock)));
      }
      sheet.blockMost[static_cast<size_t>(bi) * blockRows_ + bj] = most;
    }
    const float* blocks = &sheet.blockMost[static_cast<size_t>(bi) * blockRows_];
    sheet.blockColumnMost[static_cast<size_t>(bi)] = *std::max_element(blocks, blocks + blockRows_);
  }
  sheet.most = *std::max_element(sheet.blockColumnMost.begin(), sheet.blockColumnMost.end());
}

}  // namespace rotafab::jobs::nesting
