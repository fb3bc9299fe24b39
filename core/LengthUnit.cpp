#include "core/LengthUnit.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/Decimal.h"

namespace rotafab::core {

std::optional<LengthUnit> LengthUnit::named(std::string_view name) {
  if (name == "in") return inches();
  if (name == "mm") return millimetres();
  return std::nullopt;
}

std::string LengthUnit::digits(double inches, int inchDecimals, int direction) const {
  const int decimals = std::max(0, millimetres_ ? inchDecimals - 1 : inchDecimals);
  const double scaled = inches * perInch() * std::pow(10.0, decimals);
  // (A hair's tolerance: 92.0000001 is 92, not 93.)
  const double rounded = direction > 0   ? std::ceil(scaled - 1e-6)
                         : direction < 0 ? std::floor(scaled + 1e-6)
                                         : std::round(scaled);
  fmt::memory_buffer out;
  appendUnits(out, static_cast<int64_t>(rounded), decimals);
  return fmt::to_string(out);
}

std::string LengthUnit::number(double inches, int inchDecimals) const { return digits(inches, inchDecimals, 0); }

std::string LengthUnit::value(double inches, int inchDecimals, int direction) const {
  return digits(inches, inchDecimals, direction) + std::string(name());
}

std::string LengthUnit::operator()(double inches, int inchDecimals, int direction) const {
  return fmt::format("{} {}", digits(inches, inchDecimals, direction), name());
}

std::string LengthUnit::size(double width, double height, int inchDecimals) const {
  return fmt::format("{} x {} {}", number(width, inchDecimals), number(height, inchDecimals), name());
}

std::string LengthUnit::size(double x, double y, double z, int inchDecimals) const {
  return fmt::format("{} x {} x {} {}", number(x, inchDecimals), number(y, inchDecimals), number(z, inchDecimals),
                     name());
}

}  // namespace rotafab::core
