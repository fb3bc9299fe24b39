#pragma once
// Fixed-point numbers for files people's tools read (sheets, meshes): a value
// as a whole number of 10^-decimals units, and those units as decimal text.
// Writers that give a path's points as moves compute them in these units, so
// that the moves add up exactly to the rounded positions.

#include <fmt/format.h>

#include <cstdint>

namespace rotafab::core {

// `value` rounded to a whole number of 10^-decimals (decimals 0 to 9).
int64_t unitsOf(double value, int decimals);

// `units` of 10^-decimals appended as a decimal with trailing zeros dropped
// ("-0.0123", "12.5", "3"; never "-0"), the same in any locale.
void appendUnits(fmt::memory_buffer& out, int64_t units, int decimals);

}  // namespace rotafab::core
