#include "cli/MakeCommand.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli/CommandContext.h"
#include "cli/CommandSupport.h"
#include "cli/MakeOptionsCli.h"
#include "cli/ProgressLines.h"
#include "jobs/MakeJob.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {
namespace {

// Why the nesting stopped, as the summary says it (NestingResult::stopped).
std::string nestingStopped(const std::string& stopped) {
  if (stopped == "area bound") return " (done: as few sheets as the parts' area allows)";
  if (stopped == "no better layout") return " (done: no better layout in many tries)";
  if (stopped == "time budget") return " (the whole --time)";
  if (stopped == "layout cap") return " (the --evaluations cap)";
  if (stopped == "nothing to search") return " (the first layout: nothing to search in this order)";
  if (stopped == "too many parts") return " (the first layout: too many parts to search in this order)";
  return "";
}

// "stands: ..." or "tips over: ... hang it from ...", with the mass when the material gives it.
std::string stabilityLine(const geometry::Stability& stability, core::LengthUnit unit) {
  const std::string mass = stability.massKg ? fmt::format("; mass {:.3g} kg", *stability.massKg) : "";
  if (stability.stands) {
    return fmt::format("stands: its centre of mass is {} inside its footprint{}", unit(stability.margin, 2), mass);
  }
  const auto point = [unit](const geometry::Point3& p) {
    return fmt::format("({}, {}, {}) {}", unit.number(p.x()), unit.number(p.y()), unit.number(p.z()), unit.name());
  };
  const geometry::Point3 &p = stability.hangPoints.at(0), &q = stability.hangPoints.at(1);
  const std::string hang = p == q ? point(p) : fmt::format("{} and {}", point(p), point(q));
  if (!(stability.margin < -geometry::kBalanceInches)) {
    return fmt::format("balances on the edge of its footprint, and a touch tips it{}; hang it from {}", mass, hang);
  }
  return fmt::format("tips over: its centre of mass is {} outside its footprint{}; hang it from {}",
                     unit(-stability.margin, 2), mass, hang);
}

void printSummary(const MakeOptions& options, const jobs::PlannedJob& job, const CommandContext& command) {
  const auto& s = job.seconds;
  if (options.json) {
    // The summary (docs/CONTRACT.md, "make"), and the notes and warnings
    // printed on the way (also on standard error), for a script that reads only
    // the object.
    nlohmann::ordered_json summary = jobs::summaryJson(job);
    summary["notes"] = command.notes();
    summary["warnings"] = command.warnings();
    std::cout << summary.dump() << '\n';
    return;
  }
  const size_t sheets = job.sheets.sheets.size();
  const size_t panels = job.structure.panels.size();
  const int fasteners = job.structure.fasteners;
  fmt::print("{}: {} panel{} on {} sheet{} ({:.1f}% of the usable bed area), {} fastener{}; written to {}/\n",
             options.mesh, panels, panels == 1 ? "" : "s", sheets, sheets == 1 ? "" : "s", 100 * job.sheets.utilization,
             fasteners, fasteners == 1 ? "" : "s", job.folder.string());
  if (const auto& count = job.mesh.panelCount) {
    const geometry::Remeshing& remeshing = count->remeshing;
    if (remeshing.remeshed) {
      // (Mends of narrow bands collapse or merge faces; a panel that would overlap itself is split in two.)
      const bool changed =
          job.structure.kind == geometry::StructureKind::Band && static_cast<int>(panels) != remeshing.facesAfter;
      fmt::print("  panels asked: {}; the mesh remeshed from {} faces to {} even triangles{}\n", count->asked,
                 remeshing.facesBefore, remeshing.facesAfter,
                 changed ? fmt::format(", {} panels as built (after the mends and splits above)", panels) : "");
    } else {
      fmt::print("  panels asked: {}; the mesh has {} faces, kept as drawn\n", count->asked, remeshing.facesAfter);
    }
  }
  fmt::print("  built, {}; {}\n", job.shownIn.size(job.size.x(), job.size.y(), job.size.z(), 1),
             stabilityLine(job.stability, job.shownIn));
  fmt::print("  it takes {}\n", jobs::costLine(job.cost, job.shownIn));
  fmt::print("  import {:.2f} s, geometry {:.2f} s, nesting {:.2f} s{}, estimate {:.2f} s, writing {:.2f} s\n",
             s.import, s.geometry, s.nesting, nestingStopped(job.sheets.stopped), s.estimate, s.writing);
  fmt::print("  assembly: {}/manifest.txt (or `rotafab manifest {}`)\n", job.folder.string(), job.folder.string());
}

int runMake(const MakeOptions& given) {
  return reportingErrors(given.mesh, [&]() -> int {
    MakeOptions options = given;
    // (--units, else the user's setting; else requestOf() takes --size's unit, else the machine's.)
    if (options.units.empty()) {
      if (const auto preferred = profiles::readUserSettings().units) options.units = std::string(preferred->name());
    }
    const auto catalogue = profiles::loadProfiles(profiles::profileSearchPath());
    const jobs::MakeRequest request = requestOf(options, catalogue);
    const std::filesystem::path folder =
        options.out.empty() ? jobs::defaultOutputFolder(request) : std::filesystem::path(options.out);
    ProgressLineOptions lines;
    lines.prefix = "make: ";
    lines.nestingPrefix = "nesting: ";
    const auto& bed = request.machine.bed;
    lines.bed = request.shownIn.size(bed.width, bed.height, 3);
    lines.unit = request.shownIn;
    lines.rows = request.rows;
    lines.folder = folder.string();
    CommandContext command{ProgressLines(lines)};
    try {
      printSummary(options, jobs::makeJob(request, folder, command.context()), command);
      return kSuccess;
    } catch (const core::Cancelled&) {
      fmt::print(stderr, "make: stopped; nothing was written\n");
      return command.interruptedStatus();
    } catch (const geometry::InvalidMeshError& error) {
      fmt::print(stderr, "error: {}\n", error.what());
      return kUserError;
    } catch (const std::bad_alloc&) {
      fmt::print(stderr, "error: {}: the structure does not fit in memory\n", options.mesh);
      return kUserError;
    }
  });
}

}  // namespace

void addMakeCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<MakeOptions>();
  CLI::App* make = app.add_subcommand("make", "Turn a mesh into numbered, drilled panels on laser sheets");
  addMakeOptions(*make, *options);
  make->footer(
      "Writes into the output folder: sheet-001.eps/.svg/.dxf, ... (one set per sheet, for the cutter) and\n"
      "sheet-001.preview.svg (for people), manifest.json (docs/CONTRACT.md), manifest.txt (what it takes, and\n"
      "the assembly steps), structure.obj (the panels in 3D, a group per panel). Lengths take in, mm or cm.\n"
      "Default scale: the mean edge becomes 2 in. Ctrl-C stops at once and writes nothing.\n\n"
      "Examples:\n"
      "  rotafab make examples/bunny.obj --structure band\n"
      "  rotafab make examples/torus.obj --structure band --size 30in --fastener 3mm --out torus/");
  make->callback([options, make, &status] {
    checkStructureOptions(*make, *options);
    status = runMake(*options);
  });
}

}  // namespace rotafab::cli
