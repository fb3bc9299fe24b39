#pragma once
// Concave parts for the nester's tests: stars like vertex panels and wavy
// strips like unfolded ribbons, from a seed.

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "jobs/Nesting.h"

namespace rotafab::test {

using jobs::NestingPart;
using jobs::Polygon2;

// A star-shaped vertex panel: `spikes` points between two radii.
inline Polygon2 star(std::mt19937& random, int spikes, double outer) {
  std::uniform_real_distribution<double> inner(0.3, 0.7), jitter(0.85, 1.0);
  Polygon2 p;
  const double ratio = inner(random);
  for (int i = 0; i < 2 * spikes; ++i) {
    const double angle = std::numbers::pi * i / spikes;
    const double r = (i % 2 ? ratio : 1.0) * outer * jitter(random);
    p.emplace_back(r * std::cos(angle), r * std::sin(angle));
  }
  return p;
}

// A long wavy strip, like an unfolded woven ribbon.
inline Polygon2 wavyStrip(std::mt19937& random, double length, double width) {
  std::uniform_real_distribution<double> amplitude(0.1, 0.6);
  const double a = amplitude(random);
  const int steps = 24;
  Polygon2 p;
  for (int i = 0; i <= steps; ++i) {
    const double x = length * i / steps;
    p.emplace_back(x, a * std::sin(2 * std::numbers::pi * x / length * 2));
  }
  for (int i = steps; i >= 0; --i) {
    const double x = length * i / steps;
    p.emplace_back(x, width + a * std::sin(2 * std::numbers::pi * x / length * 2));
  }
  return p;
}

inline std::vector<NestingPart> randomParts(unsigned seed, int count) {
  std::mt19937 random(seed);
  std::vector<NestingPart> parts;
  for (int i = 0; i < count; ++i) {
    NestingPart part;
    part.name = "panel " + std::to_string(i + 1);
    part.order = i;
    switch (random() % 4) {
      case 0:
        part.outline = wavyStrip(random, 6.0 + random() % 10, 0.6);
        break;
      case 1:
        part.outline = star(random, 3 + random() % 3, 0.2 + (random() % 10) / 20.0);
        break;  // tiny
      default:
        part.outline = star(random, 4 + random() % 8, 1.0 + (random() % 30) / 10.0);
        break;
    }
    parts.push_back(std::move(part));
  }
  return parts;
}

}  // namespace rotafab::test
