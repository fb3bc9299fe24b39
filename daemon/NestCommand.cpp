#include "daemon/NestCommand.h"

#include <fmt/format.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "daemon/CommandSupport.h"
#include "daemon/ExitCode.h"
#include "daemon/ProgressLines.h"
#include "jobs/AtomicFile.h"
#include "jobs/LayoutSvg.h"
#include "jobs/Nesting.h"
#include "jobs/NestingInstance.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {
namespace {

struct NestOptions {
  std::string instance;
  std::string bed;
  std::string margin;
  std::string spacing;
  std::string machine = "workshop-32x18";
  bool strip = false;
  double seconds = 5.0;
  std::string out;
  bool json = false;
  std::string order = "free";
  int window = 8;
  unsigned seed = 1;
  int evaluations = 0;
  int threads = 0;
};

int runNest(const NestOptions& options) {
  return reportingErrors(options.instance, [&]() -> int {
    const auto start = std::chrono::steady_clock::now();
    jobs::NestingInstance instance;
    try {
      instance = jobs::readNestingInstance(options.instance);
    } catch (const std::invalid_argument& error) {
      throw UserError(error.what());
    }
    const std::vector<jobs::NestingPart>& parts = instance.parts;
    const double stripHeight = instance.stripHeight;

    jobs::NestingOptions nesting;
    nesting.strip = options.strip;
    nesting.seconds = options.seconds;
    nesting.seed = options.seed;
    nesting.evaluations = options.evaluations;
    nesting.threads = options.threads;
    double margin = 0;
    if (options.strip) {
      if (!(stripHeight > 0))
        throw UserError(fmt::format("{}: strip_height: expected a positive number", options.instance));
      nesting.height = stripHeight;
      nesting.spacing = options.spacing.empty() ? 0.0 : lengthOption(options.spacing, "--spacing");
    } else {
      profiles::Bed bed;
      try {
        bed = profiles::findMachine(profiles::loadProfiles(profiles::profileSearchPath()), options.machine).bed;
      } catch (const profiles::ProfileError&) {
        if (options.machine != "workshop-32x18") throw;  // the default bed of SPEC otherwise
      }
      if (!options.bed.empty()) {
        const auto x = options.bed.find('x');
        if (x == std::string::npos)
          throw UserError(fmt::format("--bed {}: expected WIDTHxHEIGHT, e.g. 32x18 or 812.8mmx457.2mm", options.bed));
        bed.width = lengthOption(options.bed.substr(0, x), "--bed");
        bed.height = lengthOption(options.bed.substr(x + 1), "--bed");
      }
      if (!options.margin.empty()) bed.margin = lengthOption(options.margin, "--margin");
      if (2 * bed.margin >= std::min(bed.width, bed.height)) {
        throw UserError(
            fmt::format("--margin {}: leaves no usable area on a {} x {} bed", bed.margin, bed.width, bed.height));
      }
      margin = bed.margin;
      nesting.width = bed.width - 2 * bed.margin;
      nesting.height = bed.height - 2 * bed.margin;
      nesting.spacing = options.spacing.empty() ? 0.0625 : lengthOption(options.spacing, "--spacing");
    }
    nesting.order = orderOption(options.order);
    nesting.window = options.window;
    core::Executor executor(
        std::max({1u, std::thread::hardware_concurrency(), static_cast<unsigned>(options.threads)}));
    core::Cancellation cancellation;
    core::ProgressSink progress;
    if (!options.json) {
      ProgressLineOptions lines;
      lines.prefix = "nest: ";
      lines.seconds = options.seconds;
      lines.strip = options.strip;
      progress = ProgressLines(lines);
    }
    const core::WorkContext context(executor, cancellation, progress);

    jobs::NestingResult result;
    try {
      result = jobs::nest(parts, nesting, context);
    } catch (const std::invalid_argument& error) {
      throw UserError(fmt::format("{}: {}", options.instance, error.what()));
    }
    const auto problems = jobs::layoutProblems(parts, result, nesting);
    if (!problems.empty()) {
      fmt::print(stderr, "error: internal: the layout failed its own check: {}\n", problems.front());
      return kUserError;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    nlohmann::ordered_json summary;
    summary["sheets"] = result.sheets;
    summary["utilization"] =
        options.strip ? nlohmann::ordered_json(nullptr)
                      : nlohmann::ordered_json(result.partArea / (result.sheets * nesting.width * nesting.height));
    summary["strip_length"] =
        options.strip ? nlohmann::ordered_json(result.stripLength) : nlohmann::ordered_json(nullptr);
    summary["density"] = options.strip ? nlohmann::ordered_json(result.partArea / (nesting.height * result.stripLength))
                                       : nlohmann::ordered_json(nullptr);
    summary["seconds"] = seconds;
    summary["layouts"] = result.evaluations;  // an extension of SPEC's summary: how far the search got

    if (!options.out.empty()) {
      std::filesystem::create_directories(options.out);
      nlohmann::ordered_json layout = {{"placements", nlohmann::ordered_json::array()}};
      for (size_t cut = 0; cut < result.placements.size(); ++cut) {
        const auto& p = result.placements[cut];
        layout["placements"].push_back({{"item", instance.itemOfPart[p.part]},
                                        {"copy", instance.copyOfPart[p.part]},
                                        {"sheet", p.sheet},
                                        {"x", p.x + margin},
                                        {"y", p.y + margin},
                                        {"rotation", p.rotation},
                                        // Extension: how far the layout moved the part from its order in the file.
                                        {"moved", static_cast<int>(cut) - parts[p.part].order}});
      }
      jobs::writeFileAtomically(std::filesystem::path(options.out) / "layout.json", layout.dump(1) + "\n");
      jobs::writeFileAtomically(std::filesystem::path(options.out) / "layout.svg",
                                jobs::layoutSvg(parts, result, nesting, margin));
    }
    if (options.json) {
      std::cout << summary.dump() << '\n';
    } else if (options.strip) {
      fmt::print("{} parts in a strip {:.4g} long and {:.4g} high: density {:.1f}% ({} layouts tried in {:.1f} s)\n",
                 parts.size(), result.stripLength, nesting.height, 100.0 * summary["density"].get<double>(),
                 result.evaluations, seconds);
    } else {
      fmt::print("{} parts on {} sheet{}: utilization {:.1f}% ({} layouts tried in {:.1f} s)\n", parts.size(),
                 result.sheets, result.sheets == 1 ? "" : "s", 100.0 * summary["utilization"].get<double>(),
                 result.evaluations, seconds);
    }
    return kSuccess;
  });
}

}  // namespace

void addNestCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<NestOptions>();
  CLI::App* command = app.add_subcommand("nest", "Nest the parts of an instance file onto beds or into a strip");
  command->add_option("INSTANCE", options->instance, "Instance file (jagua-rs / sparrow JSON)")->required();
  command->add_option("--bed", options->bed, "Bed size WIDTHxHEIGHT (default: the machine profile's, 32x18 in)");
  command->add_option("--margin", options->margin, "Margin on every side of the bed (default: the profile's, 1/4 in)");
  command->add_option("--machine", options->machine, "Machine profile for the bed")->capture_default_str();
  command->add_option("--spacing", options->spacing, "Least distance between parts (default 1/16 in; 0 with --strip)");
  command->add_flag("--strip", options->strip, "Nest into one strip of the instance's strip_height, least length");
  command->add_option("--time", options->seconds, "Improvement time budget in seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  command->add_option("--order", options->order, "strict, window or free: how far parts may move from their order")
      ->capture_default_str()
      ->check(CLI::IsMember({"strict", "window", "free"}));
  command->add_option("--window", options->window, "With --order window: at most this many places")
      ->capture_default_str();
  command->add_option("--seed", options->seed, "Seed of the improvement search")->capture_default_str();
  command->add_option("--evaluations", options->evaluations,
                      "Stop each search after this many layouts (with a long --time: the same layout on any machine\n"
                      "with the same --threads)");
  command
      ->add_option("--threads", options->threads,
                   "Searches side by side, seeds SEED, SEED+1, ...; the best layout wins (default 0: one per core)")
      ->capture_default_str()
      ->check(CLI::Range(0, 256));
  command->add_option("--out", options->out, "Folder for layout.json and layout.svg");
  command->add_flag("--json", options->json,
                    "Print one JSON object: sheets, utilization, strip_length, density, seconds, layouts");
  command->footer(
      "Lengths take in, mm or cm (a bare number is inches). In bin mode utilization is part area over the usable\n"
      "area of all sheets; in strip mode density is part area over strip_height x strip_length.\n\n"
      "Examples:\n"
      "  rotafab nest parts.json --out layout/\n"
      "  rotafab nest ../shared/benchmarks/esicup/shirts.json --strip --time 60 --json");
  command->callback([options, &status] { status = runNest(*options); });
}

}  // namespace rotafab::cli
