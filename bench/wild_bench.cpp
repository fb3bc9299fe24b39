// Meshes nobody here made, built as a user would: CGAL's cow and elephant
// with every default (the size make chooses, the narrow places mended, the
// whole nesting), and the designer's sizes and panel counts of the band
// structure's acceptance (the bunny at 30 in with 1,000 panels, CGAL's homer
// and elephant at 36 in with 600 and 800). For each: the panels, the size
// built, the sheets and their fill, the mends, the labels left off, and the
// seconds; a refusal is printed as such. Targets (docs/PERFORMANCE.md,
// "Meshes other people made"): the cow on at most 40 sheets at its default
// size; every designer's size kept within 1% with every label etched.
//
//   build/rotafab_wild_bench [NAME]     (cow, elephant, bunny-1000, homer-600, homer-800, elephant-600, elephant-800)

#include <fmt/format.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/Executor.h"
#include "geometry/MeshMending.h"
#include "jobs/MakeJob.h"
#include "profiles/Profiles.h"

using namespace rotafab;

namespace {

// CGAL's meshes, from Debian's libcgal-demo data, unpacked once.
std::filesystem::path cgalMesh(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "rotafab-wild-bench";
  const std::filesystem::path mesh = dir / "data/meshes" / name;
  if (!std::filesystem::exists(mesh)) {
    std::filesystem::create_directories(dir);
    const std::string command =
        fmt::format("tar xzf /usr/share/doc/libcgal-dev/data.tar.gz -C '{}' data/meshes/{}", dir.string(), name);
    if (std::system(command.c_str()) != 0) throw std::runtime_error("cannot unpack " + name);
  }
  return mesh;
}

struct Case {
  std::string name;
  std::filesystem::path mesh;
  std::optional<int> panels;
  std::optional<double> size;
};

}  // namespace

int main(int argc, char** argv) {
  const std::string only = argc > 1 ? argv[1] : "";
  const std::filesystem::path source(ROTAFAB_SOURCE_DIR);
  const std::vector<Case> cases = {
      {"cow", cgalMesh("cow.off"), std::nullopt, std::nullopt},
      {"elephant", cgalMesh("elephant.off"), std::nullopt, std::nullopt},
      {"bunny-1000", source / "examples/bunny.obj", 1000, 30.0},
      {"homer-600", cgalMesh("homer.off"), 600, 36.0},
      {"homer-800", cgalMesh("homer.off"), 800, 36.0},
      {"elephant-600", cgalMesh("elephant.off"), 600, 36.0},
      {"elephant-800", cgalMesh("elephant.off"), 800, 36.0},
  };
  core::Executor executor(2);
  core::Cancellation cancellation;
  const core::WorkContext context(executor, cancellation, [](const core::Progress&) {});
  const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  fmt::print("{:<13} {:>7} {:>8} {:>7} {:>6} {:>6} {:>6} {:>6} {:>7}\n", "mesh", "panels", "size in", "asked", "sheets",
             "fill", "mends", "unetch", "seconds");
  for (const Case& c : cases) {
    if (!only.empty() && only != c.name) continue;
    jobs::MakeRequest request;
    request.mesh = c.mesh;
    request.machine = profiles::findMachine(catalogue, "workshop-32x18");
    request.material = profiles::findMaterial(catalogue, "posterboard");
    request.panels = c.panels;
    request.size = c.size;
    const auto start = std::chrono::steady_clock::now();
    try {
      const jobs::PlannedJob job = jobs::planJob(request, context);
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      int mends = 0;
      for (const auto& repair : job.mesh.repairs) {
        if (geometry::isMend(repair)) mends += repair.count;
      }
      int unetched = 0;
      for (const std::string& warning : job.warnings) {
        if (warning.find("not etched") != std::string::npos) unetched += std::atoi(warning.c_str());
      }
      fmt::print("{:<13} {:>7} {:>8.1f} {:>7} {:>6} {:>5.1f}% {:>6} {:>6} {:>7.1f}\n", c.name,
                 job.structure.panels.size(), job.size.maxCoeff(), c.size ? fmt::format("{:.0f}", *c.size) : "-",
                 job.sheets.sheets.size(), 100 * job.sheets.utilization, mends, unetched, seconds);
    } catch (const std::exception& error) {
      fmt::print("{:<13} refused: {}\n", c.name, error.what());
    }
  }
}
