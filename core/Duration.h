#pragma once
// A duration for people: "4m 37s", "12s", "1h 05m".

#include <fmt/format.h>

#include <cmath>
#include <string>

namespace rotafab::core {

inline std::string minutes(double seconds) {
  const long s = std::lround(seconds);
  if (s >= 3600) return fmt::format("{}h {:02}m", s / 3600, s % 3600 / 60);
  return s >= 60 ? fmt::format("{}m {:02}s", s / 60, s % 60) : fmt::format("{}s", s);
}

}  // namespace rotafab::core
