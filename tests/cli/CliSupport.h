#pragma once
// What the command line's tests share: the program they run and the source
// tree its examples and profiles come from, and what they read in a
// manifest.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace rotafab::test {

inline const std::string kCli = ROTAFAB_CLI;
inline const std::filesystem::path kSource = ROTAFAB_SOURCE_DIR;

// The distance from a point to a closed outline given as manifest.json's [[x, y], ...].
inline double distanceToOutline(const nlohmann::json& outline, double x, double y) {
  double nearest = 1e300;
  for (size_t k = 0; k < outline.size(); ++k) {
    const double ax = outline[k][0], ay = outline[k][1];
    const double bx = outline[(k + 1) % outline.size()][0], by = outline[(k + 1) % outline.size()][1];
    const double dx = bx - ax, dy = by - ay, length2 = dx * dx + dy * dy;
    const double t = length2 > 0 ? std::clamp(((x - ax) * dx + (y - ay) * dy) / length2, 0.0, 1.0) : 0.0;
    nearest = std::min(nearest, std::hypot(ax + t * dx - x, ay + t * dy - y));
  }
  return nearest;
}

// Whether a point lies inside a closed outline given as manifest.json's [[x, y], ...] (even-odd rule).
inline bool insideOutline(const nlohmann::json& outline, double x, double y) {
  bool inside = false;
  for (size_t k = 0, j = outline.size() - 1; k < outline.size(); j = k++) {
    const double ax = outline[k][0], ay = outline[k][1], bx = outline[j][0], by = outline[j][1];
    if ((ay > y) != (by > y) && x < (bx - ax) * (y - ay) / (by - ay) + ax) inside = !inside;
  }
  return inside;
}

}  // namespace rotafab::test
