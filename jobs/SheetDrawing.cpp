#include "jobs/SheetDrawing.h"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace rotafab::jobs {

void checkDrawable(const SheetDrawing& sheet) {
  if (!(std::isfinite(sheet.width) && std::isfinite(sheet.height) && sheet.width > 0 && sheet.height > 0))
    throw std::invalid_argument(
        fmt::format("sheet {}: the bed {} x {} in is not a positive size", sheet.index, sheet.width, sheet.height));
  const double slack = 1e-9;
  for (size_t i = 0; i < sheet.paths.size(); ++i) {
    const DrawnPath& path = sheet.paths[i];
    const auto name = profiles::operationName(path.operation);
    if (!sheet.colours.contains(path.operation))
      throw std::invalid_argument(fmt::format("sheet {}: path {} ({}): the machine profile gives no colour for {}",
                                              sheet.index, i + 1, name, name));
    if (path.points.size() < 2)
      throw std::invalid_argument(fmt::format("sheet {}: path {} ({}) has {} point(s); a path needs at least 2",
                                              sheet.index, i + 1, name, path.points.size()));
    for (const Point2& p : path.points)
      if (!p.allFinite() || p.x() < -slack || p.y() < -slack || p.x() > sheet.width + slack ||
          p.y() > sheet.height + slack)
        throw std::invalid_argument(fmt::format("sheet {}: path {} ({}) has the point ({}, {}) off the {} x {} in bed",
                                                sheet.index, i + 1, name, p.x(), p.y(), sheet.width, sheet.height));
  }
}

std::string printableAscii(std::string_view text) {
  std::string out;
  for (char c : text) {
    if (out.size() >= 200) break;
    out += (c >= ' ' && c <= '~') ? c : '?';
  }
  return out;
}

std::string formatDecimal(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find('.') != std::string::npos) {
    text.erase(text.find_last_not_of('0') + 1);
    if (text.back() == '.') text.pop_back();
  }
  return text == "-0" ? std::string(1, '0') : text;
}

}  // namespace rotafab::jobs
