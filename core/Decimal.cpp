#include "core/Decimal.h"

#include <algorithm>
#include <cmath>

namespace rotafab::core {

int64_t unitsOf(double value, int decimals) {
  static constexpr double kPowers[] = {1, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9};
  return std::llround(value * kPowers[std::clamp(decimals, 0, 9)]);
}

void appendUnits(fmt::memory_buffer& out, int64_t units, int decimals) {
  decimals = std::clamp(decimals, 0, 9);  // as unitsOf
  char digits[32];
  char* const end = digits + sizeof digits;
  char* at = end;
  uint64_t magnitude = units < 0 ? 0 - static_cast<uint64_t>(units) : static_cast<uint64_t>(units);
  // The fraction's digits from the last, trailing zeros dropped, then the point.
  bool fraction = false;
  for (int i = 0; i < decimals; ++i) {
    const char digit = static_cast<char>('0' + magnitude % 10);
    magnitude /= 10;
    if (fraction || digit != '0') {
      *--at = digit;
      fraction = true;
    }
  }
  if (fraction) *--at = '.';
  do {
    *--at = static_cast<char>('0' + magnitude % 10);
    magnitude /= 10;
  } while (magnitude != 0);
  if (units < 0) *--at = '-';
  out.append(at, end);
}

}  // namespace rotafab::core
