// The first layout's cost per part as jobs grow: the band panels of the
// bunny (the first N in assembly order, and its 3674 panels again for more)
// and of tori, from 500 to 8,000 parts, laid out on the workshop bed (32 x
// 18 in, 1/4 in margins, spacing 1/16 in plus the posterboard's kerf) by the
// collision placer (jobs/nesting/CollisionPlacer.h) in the free order
// (largest first, first fit over every sheet) and in the strict order (the
// window order's first layout). Only the placement is timed: the parts are
// made once (`make --layout rows`) and their shapes built before the clock
// starts. Target: the time per part flat within a factor 1.5 from 500 to
// 8,000 parts. Every layout is checked exactly (layoutProblems()).
//
//   build/rotafab_layout_bench [bunny|torus [PARTS]]

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "core/Executor.h"
#include "geometry/Primitives.h"
#include "geometry/io/ObjWriter.h"
#include "jobs/MakeJob.h"
#include "jobs/Manifest.h"
#include "jobs/Nesting.h"
#include "jobs/nesting/CollisionPlacer.h"
#include "jobs/nesting/Shapes.h"
#include "profiles/Profiles.h"

using namespace rotafab;

namespace {

// The parts `make` nests for this mesh (kerf applied).
std::vector<jobs::NestingPart> partsOf(const std::filesystem::path& mesh, const core::WorkContext& context) {
  const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  jobs::MakeRequest request;
  request.mesh = mesh;
  request.machine = profiles::findMachine(catalogue, "workshop-32x18");
  request.material = profiles::findMaterial(catalogue, "posterboard");
  request.rows = true;
  const jobs::PlannedJob job = jobs::planJob(request, context);
  std::vector<jobs::NestingPart> parts;
  for (const jobs::Part& part : jobs::structureParts(job.structure)) {
    const jobs::Part cut = jobs::compensateKerf(part, request.material.kerf);
    parts.push_back({cut.name, cut.outline, cut.rotations, cut.order});
  }
  return parts;
}

struct Measure {
  int sheets = 0;
  double seconds = 0;
  bool valid = false;
};

Measure firstLayout(const std::vector<jobs::NestingPart>& parts, jobs::OrderMode order,
                    const core::WorkContext& context) {
  jobs::NestingOptions options;
  options.spacing = 1.0 / 16 + 0.008;
  options.order = order;
  jobs::nesting::PartShapes shapes(parts, options, context);
  shapes.buildAll(context);
  std::vector<int> sequence(parts.size());
  std::iota(sequence.begin(), sequence.end(), 0);
  if (order == jobs::OrderMode::Free) {
    std::stable_sort(sequence.begin(), sequence.end(), [&](int a, int b) {
      return std::abs(jobs::polygonArea(parts[a].outline)) > std::abs(jobs::polygonArea(parts[b].outline));
    });
  }
  jobs::nesting::CollisionPlacer placer(shapes);
  const auto start = std::chrono::steady_clock::now();
  const jobs::NestingResult result = placer.place(sequence, order);
  Measure measure;
  measure.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  measure.sheets = result.sheets;
  const auto problems = jobs::layoutProblems(parts, result, options);
  measure.valid = problems.empty();
  if (!problems.empty()) {
    fmt::print(stderr, "{} order: {} problems, the first: {}\n", order == jobs::OrderMode::Free ? "free" : "strict",
               problems.size(), problems.front());
  }
  return measure;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string only = argc > 1 ? argv[1] : "";
  core::Executor executor(2);
  core::Cancellation cancellation;
  const core::WorkContext context(executor, cancellation, [](const core::Progress&) {});
  const std::filesystem::path source(ROTAFAB_SOURCE_DIR);
  struct Instance {
    std::string name;
    std::vector<jobs::NestingPart> parts;
  };
  std::vector<Instance> instances;
  std::vector<size_t> counts{500, 1000, 2000, 4000, 8000};
  if (argc > 2) counts = {std::stoul(argv[2])};
  if (only.empty() || only == "bunny") {
    // The bunny's panels, the first N in assembly order (a region of the
    // bunny), or all of them again and again up to N: the same kind of
    // parts at every size.
    const auto all = partsOf(source / "examples/bunny.obj", context);
    for (size_t count : counts) {
      std::vector<jobs::NestingPart> parts;
      for (size_t i = 0; i < count; ++i) {
        parts.push_back(all[i % all.size()]);
        parts.back().order = static_cast<int>(i);
      }
      instances.push_back({fmt::format("bunny panels, {}", count), std::move(parts)});
    }
  }
  if (only.empty() || only == "torus") {
    const auto folder = std::filesystem::temp_directory_path() / "rotafab-layout-bench";
    std::filesystem::create_directories(folder);
    for (size_t count : counts) {
      // A torus of quads, `count` of them, about four times round as across.
      const int across = std::max(4, static_cast<int>(std::lround(std::sqrt(count / 4.0))));
      const int around = static_cast<int>(count) / across;
      const auto file = folder / fmt::format("torus-{}.obj", count);
      {
        std::ofstream out(file);
        geometry::writeObj(out, geometry::torus(around, across));
      }
      instances.push_back({fmt::format("torus panels, {}", around * across), partsOf(file, context)});
    }
    std::filesystem::remove_all(folder);
  }
  fmt::print("{:<22} {:>6} | {:>7} {:>8} {:>9} | {:>7} {:>8} {:>9}\n", "instance", "parts", "free", "sheets", "ms/part",
             "strict", "sheets", "ms/part");
  for (const Instance& instance : instances) {
    const Measure free = firstLayout(instance.parts, jobs::OrderMode::Free, context);
    const Measure strict = firstLayout(instance.parts, jobs::OrderMode::Strict, context);
    const double n = static_cast<double>(instance.parts.size());
    fmt::print("{:<22} {:>6} | {:>6.2f}s {:>8} {:>9.3f} | {:>6.2f}s {:>8} {:>9.3f}{}\n", instance.name,
               instance.parts.size(), free.seconds, free.sheets, 1000 * free.seconds / n, strict.seconds, strict.sheets,
               1000 * strict.seconds / n, free.valid && strict.valid ? "" : "  INVALID LAYOUT");
  }
  return 0;
}
