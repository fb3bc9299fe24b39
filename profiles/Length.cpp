#include "profiles/Length.h"

#include <fmt/format.h>

#include <array>
#include <charconv>
#include <cmath>
#include <string>

#include "core/UserError.h"

namespace rotafab::profiles {
namespace {

// The units a length may be written in, and how many of each make an inch
// ("mm" before "m": the first whose name ends the text is its unit).
constexpr std::array<std::pair<std::string_view, double>, 5> kUnits{
    {{"mm", 25.4}, {"cm", 2.54}, {"in", 1.0}, {"ft", 1.0 / 12}, {"m", 0.0254}}};

// The unit a length ends with, or empty.
std::string_view unitOf(std::string_view text) {
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  for (const auto& [unit, perInch] : kUnits) {
    if (text.size() > unit.size() && text.ends_with(unit)) return unit;
  }
  return {};
}

}  // namespace

std::optional<double> parseLength(std::string_view text) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  const std::string_view unit = unitOf(text);
  const double inchesPerUnit = 1.0 / unitsPerInch(unit.empty() ? "in" : unit);
  text.remove_suffix(unit.size());
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value * inchesPerUnit;
}

double lengthOption(const std::string& text, std::string_view flag, bool positive) {
  const auto value = parseLength(text);
  if (!value || *value < 0 || (positive && !(*value > 0))) {
    throw core::UserError(fmt::format("{} {}: expected a {}length such as 0.125in, 3.2mm, 0.32cm, 2ft or 1.2m", flag,
                                      text, positive ? "positive " : ""));
  }
  return *value;
}

std::string_view writtenUnit(std::string_view text) {
  const std::string_view unit = unitOf(text);
  return unit.empty() ? "in" : unit;
}

double unitsPerInch(std::string_view unit) {
  for (const auto& [name, perInch] : kUnits) {
    if (name == unit) return perInch;
  }
  return 1.0;
}

std::string formatLength(double inches, std::string_view unit) {
  return fmt::format("{:.4g} {}", inches * unitsPerInch(unit), unit);
}

std::optional<std::pair<double, double>> parseSize(std::string_view text) {
  const size_t x = text.find('x');
  if (x == std::string_view::npos || text.find('x', x + 1) != std::string_view::npos) return std::nullopt;
  const std::string_view first = text.substr(0, x), second = text.substr(x + 1);
  const std::string_view firstUnit = unitOf(first), secondUnit = unitOf(second);
  if (!firstUnit.empty() && secondUnit.empty()) return std::nullopt;
  // "800x600mm": the one unit, at the end, is both numbers'.
  const auto width = firstUnit.empty() && !secondUnit.empty()
                         ? parseLength(std::string(first) + std::string(secondUnit))
                         : parseLength(first);
  const auto height = parseLength(second);
  if (!width || !height) return std::nullopt;
  return std::pair{*width, *height};
}

}  // namespace rotafab::profiles
