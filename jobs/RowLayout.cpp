#include "jobs/RowLayout.h"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace rotafab::jobs {

NestingResult rowLayout(const std::vector<NestingPart>& parts, const NestingOptions& options) {
  if (options.strip) throw std::invalid_argument("the row layout is for beds, not a strip");
  checkNestingParts(parts);
  std::vector<int> sequence(parts.size());
  std::iota(sequence.begin(), sequence.end(), 0);
  std::stable_sort(sequence.begin(), sequence.end(), [&](int a, int b) { return parts[a].order < parts[b].order; });

  // What the nester's grid may round away (1/10000 in): a part it takes
  // for fitting the area fits here too (nest() lays the parts its budget
  // had no time for out here).
  const double width = options.width + 1e-4, height = options.height + 1e-4;
  NestingResult result;
  // The current row: from y = rowY, `rowHeight` high, filled up to x = rowX.
  double rowX = 0, rowY = 0, rowHeight = 0;
  int sheet = 0;
  for (int index : sequence) {
    const NestingPart& part = parts[index];
    // The allowed rotation whose box is lowest, then narrowest.
    double bestRotation = 0;
    Point2 low = Point2::Zero(), high = Point2::Zero();
    bool fits = false;
    for (double rotation : part.rotations) {
      const auto [min, max] = rotatedBox(part.outline, rotation);
      const Point2 size = max - min;
      if (size.x() > width || size.y() > height) continue;
      const Point2 bestSize = high - low;
      if (!fits || size.y() < bestSize.y() || (size.y() == bestSize.y() && size.x() < bestSize.x())) {
        bestRotation = rotation, low = min, high = max, fits = true;
      }
    }
    if (!fits) {
      throw std::invalid_argument(
          fmt::format("{} does not fit the usable area of {:.4g} x {:.4g} in any allowed rotation", part.name,
                      options.width, options.height));
    }
    const Point2 size = high - low;
    if (sheet == 0) sheet = 1;
    if (rowX > 0 && rowX + size.x() > width) {  // the next row
      rowY += rowHeight + options.spacing;
      rowX = 0, rowHeight = 0;
    }
    if (rowY + size.y() > height) {  // the next sheet
      ++sheet;
      rowX = 0, rowY = 0, rowHeight = 0;
    }
    result.placements.push_back({index, sheet, rowX - low.x(), rowY - low.y(), bestRotation});
    rowX += size.x() + options.spacing;
    rowHeight = std::max(rowHeight, size.y());
    result.partArea += std::abs(polygonArea(part.outline));
  }
  result.sheets = sheet;
  result.evaluations = 1;
  return result;
}

}  // namespace rotafab::jobs
