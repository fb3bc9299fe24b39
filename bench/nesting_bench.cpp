// Bin-mode nesting benchmark: 200 star-shaped vertex panels
// and 100 wavy strips on the workshop bed (32 x 18 in, 1/4 in margins, 1/16 in
// spacing). The vertex panels are shaped as the dissertation's vertex
// components (V.1-V.2): a vertex band, a polygon with one side per edge of
// the dual vertex, and on each side the edge band that leaves it, a
// quadrilateral about as long as the side. 200 spiky stars (spikes 35-65% of
// the radius deep, sharper than any vertex component) are a harder extra. Prints sheets used against the area lower
// bound ceil(part area / usable bed area) and the utilisation of every sheet but the last (target: at least 75%),
// beside the same parts through libnest2d in convex-hull mode (bench/Libnest2dBaseline.h): we must use fewer sheets.
//
//   build/rotafab_nest_bench [SECONDS [SVG_DIR [ONLY]]]
//     SECONDS: improvement budget per instance (default 60); SVG_DIR: also
//     draw each layout there (NAME.svg), to look at; ONLY: run only the
//     instances whose name holds it (e.g. "strips").

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <thread>

#include <clipper.hpp>

#include "bench/Libnest2dBaseline.h"
#include "jobs/LayoutSvg.h"
#include "jobs/Nesting.h"

using namespace rotafab::jobs;

namespace {

// A vertex component: 3 to 6 sides (triangle meshes give 3, quad meshes 4),
// the polygon's corners a little off regular, each edge band 70-130% as long
// as its side and 70-100% as wide at its far end.
Polygon2 vertexPanel(std::mt19937& random) {
  std::uniform_real_distribution<double> radius(0.4, 0.9), wobble(-0.12, 0.12), length(0.7, 1.3), width(0.7, 1.0);
  static constexpr int kSides[] = {3, 3, 3, 3, 4, 4, 5, 6};
  const int sides = kSides[random() % 8];
  const double r = radius(random);
  std::vector<Point2> corners;
  for (int i = 0; i < sides; ++i) {
    const double a = 2 * std::numbers::pi * (i + wobble(random)) / sides;
    corners.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  Polygon2 p;
  for (int i = 0; i < sides; ++i) {
    const Point2 a = corners[i], b = corners[(i + 1) % sides];
    const Point2 along = (b - a).normalized();
    const Point2 outward(along.y(), -along.x());  // counter-clockwise corners: the outside is on the right
    const double side = (b - a).norm(), reach = side * length(random), half = side * width(random) / 2;
    const Point2 end = (a + b) / 2 + reach * outward;
    p.push_back(a);
    p.push_back(end - half * along);
    p.push_back(end + half * along);
  }
  return p;
}

Polygon2 spikyStar(std::mt19937& random) {
  std::uniform_real_distribution<double> radius(0.9, 2.4), inner(0.35, 0.65), jitter(0.85, 1.0);
  const int spikes = 5 + random() % 4;  // vertex bands of valence 5 to 8
  const double outer = radius(random), ratio = inner(random);
  Polygon2 p;
  for (int i = 0; i < 2 * spikes; ++i) {
    const double a = std::numbers::pi * i / spikes;
    const double r = (i % 2 ? ratio : 1.0) * outer * jitter(random);
    p.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return p;
}

Polygon2 wavyStrip(std::mt19937& random) {
  std::uniform_real_distribution<double> length(8, 20), amplitude(0.2, 0.8), width(0.6, 1.0);
  const double l = length(random), a = amplitude(random), w = width(random);
  const int steps = 32;
  Polygon2 p;
  for (int i = 0; i <= steps; ++i) p.emplace_back(l * i / steps, a * std::sin(4 * std::numbers::pi * i / steps));
  for (int i = steps; i >= 0; --i) p.emplace_back(l * i / steps, w + a * std::sin(4 * std::numbers::pi * i / steps));
  return p;
}

// The area of a part grown by `by` on every side (round corners): what it
// takes of a bed with the spacing, half of it on each of two neighbours.
double grownArea(const Polygon2& outline, double by) {
  constexpr double kScale = 1e4;
  ClipperLib::Path path;
  for (const Point2& p : outline) path.emplace_back(std::llround(p.x() * kScale), std::llround(p.y() * kScale));
  ClipperLib::ClipperOffset offset;
  offset.ArcTolerance = 1;
  offset.AddPath(path, ClipperLib::jtRound, ClipperLib::etClosedPolygon);
  ClipperLib::Paths out;
  offset.Execute(out, by * kScale);
  double area = 0;
  for (const auto& p : out) area += ClipperLib::Area(p);
  return std::abs(area) / (kScale * kScale);
}

void run(const std::string& name, const std::vector<NestingPart>& parts, double seconds, const char* svgDir) {
  NestingOptions options;  // the workshop bed: 31.5 x 17.5 usable, 1/16 in spacing
  options.seconds = seconds;
  const auto start = std::chrono::steady_clock::now();
  rotafab::core::Executor executor(std::max(1u, std::thread::hardware_concurrency()));
  const rotafab::core::Cancellation never;
  const NestingResult result = nest(parts, options, rotafab::core::WorkContext(executor, never));
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double usable = options.width * options.height;
  std::vector<double> areaOnSheet(result.sheets, 0.0);
  for (const auto& p : result.placements) areaOnSheet[p.sheet - 1] += std::abs(polygonArea(parts[p.part].outline));
  double worst = 1.0;
  std::string perSheet;
  for (int s = 0; s < result.sheets; ++s) {
    perSheet += fmt::format("{}{:.0f}%", s ? " " : "", 100 * areaOnSheet[s] / usable);
    if (s + 1 < result.sheets) worst = std::min(worst, areaOnSheet[s] / usable);
  }
  const auto problems = layoutProblems(parts, result, options);
  if (svgDir) {
    std::string file = name;
    std::replace(file.begin(), file.end(), ' ', '-');
    std::ofstream(std::string(svgDir) + "/" + file + ".svg") << layoutSvg(parts, result, options, 0.25);
  }
  fmt::print("{}: {} parts, {} sheets (lower bound {}), worst sheet but the last {:.1f}%, {:.1f} s, {} layouts{}\n",
             name, parts.size(), result.sheets, static_cast<int>(std::ceil(result.partArea / usable)),
             100 * (result.sheets > 1 ? worst : areaOnSheet[0] / usable), elapsed, result.evaluations,
             problems.empty() ? "" : " INVALID: " + problems.front());
  fmt::print("  per sheet: {}\n", perSheet);
  // What the spacing costs: at 75% of a bed in parts, the parts grown by
  // half the spacing cover this much of it.
  double grown = 0;
  for (const auto& p : parts) grown += grownArea(p.outline, options.spacing / 2);
  fmt::print("  grown by half the spacing, the parts take {:.1f}% more area: 75% in parts is {:.1f}% of the bed\n",
             100 * (grown / result.partArea - 1), 75 * grown / result.partArea);
  const auto baseline = rotafab::bench::nestWithLibnest2d(parts, options);
  std::string baselineSheets;
  for (size_t s = 0; s < baseline.sheetArea.size(); ++s) {
    baselineSheets += fmt::format("{}{:.0f}%", s ? " " : "", 100 * baseline.sheetArea[s] / usable);
  }
  fmt::print("  libnest2d (convex hulls): {} sheets, {:.1f} s{}\n  per sheet: {}\n", baseline.sheets, baseline.seconds,
             baseline.valid ? "" : " INVALID: " + baseline.problem, baselineSheets);
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::stod(argv[1]) : 60.0;
  std::mt19937 random(2011);
  std::vector<NestingPart> stars, strips, panels;
  for (int i = 0; i < 200; ++i)
    stars.push_back({fmt::format("star {}", i + 1), spikyStar(random), {0, 90, 180, 270}, i});
  for (int i = 0; i < 100; ++i)
    strips.push_back({fmt::format("strip {}", i + 1), wavyStrip(random), {0, 90, 180, 270}, i});
  // Drawn after the others, so that those stay the instances measured before.
  for (int i = 0; i < 200; ++i)
    panels.push_back({fmt::format("panel {}", i + 1), vertexPanel(random), {0, 90, 180, 270}, i});
  const char* svgDir = argc > 2 ? argv[2] : nullptr;
  const std::string only = argc > 3 ? argv[3] : "";
  for (const auto& [name, parts] : {std::pair{"200 vertex panels", &panels}, std::pair{"100 wavy strips", &strips},
                                    std::pair{"200 spiky stars", &stars}}) {
    if (std::string(name).find(only) != std::string::npos) run(name, *parts, seconds, svgDir);
  }
  return 0;
}
