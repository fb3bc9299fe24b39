#include "profiles/Length.h"

#include <charconv>
#include <cmath>
#include <string>

namespace rotafab::profiles {

std::optional<double> parseLength(std::string_view text) {
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  double inchesPerUnit = 1.0;
  for (auto [suffix, factor] : {std::pair{"in", 1.0}, {"mm", 1.0 / 25.4}, {"cm", 1.0 / 2.54}}) {
    const std::string_view unit(suffix);
    if (text.size() > unit.size() && text.substr(text.size() - unit.size()) == unit) {
      text.remove_suffix(unit.size());
      while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
      inchesPerUnit = factor;
      break;
    }
  }
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double value = 0;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value * inchesPerUnit;
}

}  // namespace rotafab::profiles
