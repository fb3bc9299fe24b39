#include "cli/NestCommand.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <thread>

#include "cli/CommandContext.h"
#include "cli/CommandSupport.h"
#include "cli/ProgressLines.h"
#include "jobs/NestJob.h"
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
  double seconds = jobs::kDefaultNestingSeconds;
  std::string out;
  bool json = false;
  std::string order = "free";
  int window = 8;
  unsigned seed = 1;
  int evaluations = 0;
  int threads = 0;
};

// The bed: the machine profile's (the workshop bed of docs/CONTRACT.md,
// "Units and scale", when the profiles cannot be read and none was named), with
// --bed and --margin over it.
profiles::Bed bedOf(const NestOptions& options) {
  profiles::Bed bed;
  try {
    bed = profiles::findMachine(profiles::loadProfiles(profiles::profileSearchPath()), options.machine).bed;
  } catch (const profiles::ProfileError&) {
    if (options.machine != "workshop-32x18") throw;
  }
  if (!options.bed.empty()) {
    const auto size = profiles::parseSize(options.bed);
    if (!size || !(size->first > 0) || !(size->second > 0)) {
      throw UserError(fmt::format(
          "--bed {}: expected WIDTHxHEIGHT, a unit once at the end for both or one each, e.g. 32x18, 800x600mm or "
          "32inx18in",
          options.bed));
    }
    bed.width = size->first, bed.height = size->second;
  }
  if (!options.margin.empty()) bed.margin = lengthOption(options.margin, "--margin");
  if (2 * bed.margin >= std::min(bed.width, bed.height)) {
    throw UserError(
        fmt::format("--margin {}: leaves no usable area on a {} x {} bed", bed.margin, bed.width, bed.height));
  }
  return bed;
}

int runNest(const NestOptions& options) {
  return reportingErrors(options.instance, [&]() -> int {
    jobs::NestRequest request;
    request.instance = options.instance;
    request.strip = options.strip;
    if (!options.strip) request.bed = bedOf(options);
    if (!options.spacing.empty()) request.spacing = lengthOption(options.spacing, "--spacing");
    request.search.seconds = options.seconds;
    request.search.seed = options.seed;
    request.search.evaluations = options.evaluations;
    request.search.threads = options.threads;
    request.search.order = orderModeOf(options.order);
    request.search.window = options.window;
    ProgressLineOptions lines;
    lines.prefix = "nest: ";
    lines.strip = options.strip;
    // As many threads as searches asked for, at least one per core.
    CommandContext command(options.json ? core::ProgressSink() : ProgressLines(lines),
                           std::max(std::thread::hardware_concurrency(), static_cast<unsigned>(options.threads)));
    jobs::NestedInstance nested;
    try {
      nested = jobs::nestInstance(request, command.context());
    } catch (const core::Cancelled&) {
      fmt::print(stderr, "nest: stopped\n");
      return command.interruptedStatus();
    }
    if (!options.out.empty()) jobs::writeNestOutput(nested, options.out);
    const auto& summary = nested.summary;
    const jobs::NestingResult& result = nested.result;
    const size_t parts = nested.instance.parts.size();
    const double seconds = summary["seconds"].get<double>();
    if (options.json) {
      std::cout << summary.dump() << '\n';
    } else if (options.strip) {
      fmt::print("{} parts in a strip {:.4g} long and {:.4g} high: density {:.1f}% ({} layouts tried in {:.1f} s)\n",
                 parts, result.stripLength, nested.options.height, 100.0 * summary["density"].get<double>(),
                 result.evaluations, seconds);
    } else {
      fmt::print("{} parts on {} sheet{}: utilization {:.1f}% ({} layouts tried in {:.1f} s)\n", parts, result.sheets,
                 result.sheets == 1 ? "" : "s", 100.0 * summary["utilization"].get<double>(), result.evaluations,
                 seconds);
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
  command
      ->add_option("--time", options->seconds,
                   "Time budget in seconds, first layout included: the best layout found by then\n"
                   "is kept; parts the first layout has not reached by then go in rows (not with\n"
                   "--strip or --evaluations: the first layout is then always finished)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 86400.0));
  command
      ->add_option("--order", options->order,
                   "kits, strict, window or free: how far parts may move from their order (kits: each sheet a run of "
                   "it)")
      ->capture_default_str()
      ->check(CLI::IsMember({"kits", "strict", "window", "free"}));
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
  command->add_option("--out", options->out, "Folder for layout.json and layout.svg")->check(outputFolderCheck());
  command->add_flag("--json", options->json,
                    "Print one JSON object: sheets, utilization, strip_length, density, seconds, layouts");
  command->footer(
      "Lengths take in, mm or cm (a bare number is inches). In bin mode utilization is part area over the usable\n"
      "area of all sheets; in strip mode density is part area over strip_height x strip_length.\n\n"
      "Examples:\n"
      "  rotafab nest parts.json --out layout/\n"
      "  rotafab nest $ESICUP/shirts.json --strip --time 60 --json   (ESICUP: the benchmark instances, in the\n"
      "  jagua-rs / sparrow JSON format; docs/PERFORMANCE.md, \"ESICUP, strip mode\")");
  command->callback([options, &status] { status = runNest(*options); });
}

}  // namespace rotafab::cli
