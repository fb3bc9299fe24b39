#include "jobs/MakeJob.h"

#include "jobs/MakeSteps.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <functional>
#include <regex>

#include "core/UserError.h"
#include "geometry/BandStructure.h"
#include "geometry/ConstructionScale.h"
#include "geometry/CoplanarMerge.h"
#include "geometry/EdgeProjection.h"
#include "geometry/FastenerHoles.h"
#include "geometry/HoleFilling.h"
#include "geometry/MeshAnalysis.h"
#include "geometry/MeshRepair.h"
#include "geometry/WeaveStructure.h"
#include "geometry/io/MeshImport.h"
#include "jobs/OutputFolder.h"
#include "toolpath/AtomicFile.h"
#include "toolpath/Toolpath.h"

namespace rotafab::jobs {
namespace {

using geometry::Parameter;

// Seconds since the last call.
class Lap {
 public:
  double operator()() {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return elapsed;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

using making::builtSize;
using making::builtStructure;
using making::importedMesh;
using making::oneFaceCapAdvice;
using making::Sizing;

// Square inches to square metres: the areal density is in grams per square metre.
constexpr double kSquareMetresPerSquareInch = 0.0254 * 0.0254;

geometry::StabilityOptions stabilityOptions(const MakeRequest& request) {
  geometry::StabilityOptions options;
  options.up = request.up;
  options.gramsPerSquareInch = request.material.arealDensity * kSquareMetresPerSquareInch;
  options.gramsPerFastener = request.material.fastenerMass;
  return options;
}

}  // namespace

std::filesystem::path defaultOutputFolder(const MakeRequest& request) {
  return request.mesh.stem().string() + "-" + std::string(geometry::structureName(request.structure));
}

// The sheets, the fasteners and the cutting time, sheet by sheet, on the
// profile's machine (the toolpath `rotafab run` would send, and its time).
JobCost jobCost(const PlannedJob& job, const MakeRequest& request, const core::WorkContext& context) {
  JobCost cost;
  cost.material = request.material.name;
  cost.sheets = job.sheets.sheets.size();
  cost.sheetWidth = request.machine.bed.width, cost.sheetHeight = request.machine.bed.height;
  cost.fasteners = job.structure.fasteners;
  cost.panels = static_cast<int>(job.structure.panels.size());
  cost.fastenerDiameter = request.fastener.value_or(request.material.fastenerDiameter);
  cost.motionGiven = request.machine.motion.has_value();
  const MotionLimits limits = profileMotion(request.machine);
  // (Each sheet's stroke order is its own work: shared out among the threads.)
  std::vector<double> seconds(job.sheets.sheets.size(), 0.0);
  std::vector<std::string> refused(seconds.size());
  context.parallelFor(seconds.size(), [&](size_t s) {
    try {
      seconds[s] = planToolpath(job.sheets.sheets[s], request.machine, request.material, limits).seconds;
    } catch (const std::invalid_argument& error) {
      refused[s] = error.what();
    }
  });
  context.check();
  if (const auto why = std::find_if(refused.begin(), refused.end(), [](const auto& r) { return !r.empty(); });
      why != refused.end()) {
    context.warn(fmt::format("{}: no cutting time: {}", request.mesh.string(), *why));
  } else {
    cost.cuttingSeconds = std::move(seconds);
  }
  return cost;
}

PlannedJob planJob(const MakeRequest& request, const core::WorkContext& context) {
  Lap lap;
  const std::string name = request.mesh.string();
  PlannedJob job;
  job.title = fmt::format("{} ({})", request.mesh.stem().string(), geometry::structureName(request.structure));
  Sizing sizing;
  geometry::PolygonMesh mesh = making::builtAsAsked(request, job, sizing, context);
  for (const auto& note : job.structure.notes) context.note(fmt::format("{}: {}", name, note));
  for (const auto& warning : job.structure.warnings) {
    context.warn(fmt::format("{}: {}", name, warning));
    job.warnings.push_back(warning);
  }
  job.stability = geometry::structureStability(job.structure, stabilityOptions(request));
  job.size = builtSize(job.structure);
  job.seconds.geometry = lap() - job.seconds.import;

  PlanOptions plan;
  plan.kerf = request.kerf.value_or(request.material.kerf);
  plan.seconds = request.seconds;
  plan.evaluations = request.evaluations;
  plan.order = request.order;
  plan.window = request.window;
  plan.rows = request.rows;
  plan.title = job.title;
  context.report({"nesting", "", 0, job.structure.panels.size()});
  try {
    // (The parts, copies of the panels' outlines and strokes, only while they are planned.)
    job.sheets = planSheets(structureParts(job.structure), request.machine, plan, context);
  } catch (const std::invalid_argument& error) {
    throw core::UserError(fmt::format(
        "{}: {}{}{}", name, error.what(),
        sizing.grown > 1 ? fmt::format(" at {:.2f} times the default size, the smallest at which every {} has room for "
                                       "its fastener{}; a smaller {}, or fewer and evener faces ({} N), needs less",
                                       sizing.grown, making::roomPlace(request.structure),
                                       request.structure == geometry::StructureKind::Weave ? " holes" : "",
                                       request.names(Parameter::Fastener), request.names(Parameter::Panels))
                         : "",
        oneFaceCapAdvice(request, mesh)));
  }
  job.meshFile = request.mesh;
  job.bed = request.machine.bed;
  job.machine = request.machine.name;
  job.material = request.material.name;
  job.shownIn = request.shownIn;
  job.formats = request.formats.value_or(defaultFormats(request.machine));
  job.seconds.nesting = lap();
  if (!job.sheets.inRowsNote.empty()) context.note(fmt::format("{}: {}", name, job.sheets.inRowsNote));
  job.cost = jobCost(job, request, context);
  job.seconds.estimate = lap();
  return job;
}

void writeJob(PlannedJob& job, const std::filesystem::path& folder, const core::WorkContext& context) {
  Lap lap;
  context.report({"writing", "", 0, job.sheets.sheets.size()});
  OutputFolder output(folder);
  job.files = writeSheets(job.sheets, job.formats, output.staging(), context, job.shownIn);
  context.check();
  writeFileAtomically(output.staging() / "structure.obj", [&](std::ostream& stream) {
    geometry::writeStructureObj(
        stream, job.structure,
        fmt::format("rotafab {} structure of {}: {} panels, inches", geometry::structureName(job.structure.kind),
                    job.meshFile.string(), job.structure.panels.size()),
        kSheetDecimals);
  });
  {
    // The machine and material it was planned for: what `run` and the daemon cut it with.
    nlohmann::ordered_json more = {{"machine", job.machine},
                                   {"material", job.material},
                                   {"size", {job.size.x(), job.size.y(), job.size.z()}},
                                   {"stability", stabilityJson(job.stability)},
                                   {"cost", costJson(job.cost)},
                                   // The unit manifest.txt, `run` and the page show its lengths in.
                                   {"display_units", job.shownIn.name()}};
    if (!job.warnings.empty()) more["warnings"] = job.warnings;
    ManifestFiles manifest = manifestFiles(job.structure, job.mesh, job.bed, job.sheets, job.files, more, context);
    writeFileAtomically(output.staging() / "manifest.json", manifest.json);
    std::string().swap(manifest.json);
    writeFileAtomically(output.staging() / "manifest.txt", manifest.text);
  }
  context.check();
  // manifest.json last: until it moves in, the folder's manifest is the old job's.
  static const std::regex ours(
      R"((sheet-\d{3,}\.(eps|svg|dxf|preview\.svg))|manifest\.json|manifest\.txt|structure\.obj)");
  output.commit("manifest.json", [](const std::string& name) { return std::regex_match(name, ours); });
  job.folder = output.target();
  job.seconds.writing = lap();
}

nlohmann::ordered_json summaryJson(const PlannedJob& job) {
  const PhaseSeconds& s = job.seconds;
  nlohmann::ordered_json summary = {{"panels", job.structure.panels.size()},
                                    {"sheets", job.sheets.sheets.size()},
                                    {"fasteners", job.structure.fasteners},
                                    {"utilization", job.sheets.utilization},
                                    {"seconds",
                                     {{"import", s.import},
                                      {"geometry", s.geometry},
                                      {"nesting", s.nesting},
                                      {"estimate", s.estimate},
                                      {"writing", s.writing}}}};
  if (!job.sheets.stopped.empty()) summary["nesting_stopped"] = job.sheets.stopped;
  if (job.mesh.panelCount) summary["simplified"] = simplifiedJson(*job.mesh.panelCount);
  summary["size"] = {job.size.x(), job.size.y(), job.size.z()};
  summary["stability"] = stabilityJson(job.stability);
  summary["cost"] = costJson(job.cost);
  return summary;
}

PlannedJob makeJob(const MakeRequest& request, const std::filesystem::path& folder, const core::WorkContext& context) {
  PlannedJob job = planJob(request, context);
  writeJob(job, folder, context);
  return job;
}

}  // namespace rotafab::jobs
