#include "toolpath/SheetDrawing.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>

#include <cmath>
#include <numbers>
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
    if (path.circle && !(path.closed && path.circle->centre.allFinite() && std::isfinite(path.circle->radius) &&
                         path.circle->radius > 0))
      throw std::invalid_argument(
          fmt::format("sheet {}: path {} ({}) is a circle of radius {}; it needs a positive one", sheet.index, i + 1,
                      name, path.circle->radius));
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

void appendDecimal(fmt::memory_buffer& out, double value, int decimals) {
  // std::to_chars rounds exactly as printf does, several times faster than
  // a format string (the writers print every coordinate of every sheet).
  char digits[400];
  auto [end, error] = std::to_chars(digits, digits + sizeof digits, value, std::chars_format::fixed, decimals);
  if (error != std::errc()) {  // beyond 400 digits: not a coordinate of any bed
    fmt::format_to(std::back_inserter(out), "{:.{}f}", value, decimals);
    return;
  }
  if (std::find(digits, end, '.') != end) {
    while (end[-1] == '0') --end;
    if (end[-1] == '.') --end;
  }
  if (end - digits == 2 && digits[0] == '-' && digits[1] == '0') {
    out.push_back('0');
    return;
  }
  out.append(digits, end);
}

std::vector<Point2> circlePolygon(const Circle& circle) {
  const double outer = circle.radius / std::cos(std::numbers::pi / kCircleSides);
  std::vector<Point2> polygon;
  polygon.reserve(kCircleSides);
  for (int i = 0; i < kCircleSides; ++i) {
    const double a = 2 * std::numbers::pi * i / kCircleSides;
    polygon.push_back(circle.centre + outer * Point2(std::cos(a), std::sin(a)));
  }
  return polygon;
}

DrawnPath circlePath(Operation operation, const Circle& circle, std::string part) {
  return {operation, circlePolygon(circle), true, std::move(part), circle};
}

std::string formatDecimal(double value, int decimals) {
  fmt::memory_buffer out;
  appendDecimal(out, value, decimals);
  return fmt::to_string(out);
}

}  // namespace rotafab::jobs
