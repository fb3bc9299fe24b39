// The fixed-point text of every sheet and structure.obj: the digits a
// laser's software reads, exactly those of the rounded value.

#include "core/Decimal.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

namespace rotafab::core {
namespace {

std::string text(int64_t units, int decimals) {
  fmt::memory_buffer out;
  appendUnits(out, units, decimals);
  return fmt::to_string(out);
}

TEST(Decimal, UnitsAsDecimalsWithoutTrailingZeros) {
  EXPECT_EQ(text(0, 4), "0");
  EXPECT_EQ(text(120000, 4), "12");
  EXPECT_EQ(text(125000, 4), "12.5");
  EXPECT_EQ(text(-5, 4), "-0.0005");
  EXPECT_EQ(text(-10, 4), "-0.001");
  EXPECT_EQ(text(1234567, 3), "1234.567");
  EXPECT_EQ(text(7, 0), "7");
  EXPECT_EQ(text(INT64_MIN, 4), "-922337203685477.5808");
}

TEST(Decimal, TheSameDigitsAsPrintf) {
  // printf rounds the binary value exactly; unitsOf rounds value * 10^d.
  // The two can differ only within a rounding error of a tie (a fifth decimal of 5):
  // none of a million random coordinates does.
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> coordinate(-40, 40);
  int differ = 0;
  for (int i = 0; i < 1000000; ++i) {
    const double value = coordinate(random);
    char expected[64];
    std::snprintf(expected, sizeof expected, "%.4f", value);
    std::string printed = expected;
    while (printed.back() == '0') printed.pop_back();
    if (printed.back() == '.') printed.pop_back();
    if (printed == "-0") printed = "0";
    differ += text(unitsOf(value, 4), 4) != printed;
  }
  EXPECT_EQ(differ, 0);
}

}  // namespace
}  // namespace rotafab::core
