#include "jobs/NestJob.h"

#include <fmt/format.h>

#include <chrono>

#include "core/UserError.h"
#include "jobs/LayoutSvg.h"
#include "toolpath/AtomicFile.h"

namespace rotafab::jobs {

NestedInstance nestInstance(const NestRequest& request, const core::WorkContext& context) {
  const auto start = std::chrono::steady_clock::now();
  const std::string name = request.instance.string();
  NestedInstance nested;
  try {
    nested.instance = readNestingInstance(name);
  } catch (const std::invalid_argument& error) {
    throw core::UserError(error.what());
  }
  NestingOptions& options = nested.options;
  options = request.search;
  options.strip = request.strip;
  if (request.strip) {
    if (!(nested.instance.stripHeight > 0)) {
      throw core::UserError(fmt::format("{}: strip_height: expected a positive number", name));
    }
    options.height = nested.instance.stripHeight;
    options.spacing = request.spacing.value_or(0.0);
  } else {
    const profiles::Bed& bed = request.bed;
    nested.margin = bed.margin;
    options.width = bed.width - 2 * bed.margin;
    options.height = bed.height - 2 * bed.margin;
    options.spacing = request.spacing.value_or(0.0625);
  }
  const std::vector<NestingPart>& parts = nested.instance.parts;
  try {
    nested.result = nest(parts, options, context);
  } catch (const std::invalid_argument& error) {
    throw core::UserError(fmt::format("{}: {}", name, error.what()));
  }
  const auto problems = layoutProblems(parts, nested.result, options, 1e-3, &context.cancellation());
  // Never seen: every placement is checked as it is made; said as the command line has always said it.
  if (!problems.empty()) throw core::UserError("internal: the layout failed its own check: " + problems.front());
  const NestingResult& result = nested.result;
  if (result.inRows > 0) context.note(fmt::format("{}: {}", name, inRowsNote(result)));
  const auto none = nlohmann::ordered_json(nullptr);
  auto& summary = nested.summary;
  summary["sheets"] = result.sheets;
  summary["utilization"] =
      request.strip ? none : nlohmann::ordered_json(result.partArea / (result.sheets * options.width * options.height));
  summary["strip_length"] = request.strip ? nlohmann::ordered_json(result.stripLength) : none;
  summary["density"] =
      request.strip ? nlohmann::ordered_json(result.partArea / (options.height * result.stripLength)) : none;
  summary["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary["layouts"] = result.evaluations;
  summary["in_rows"] = result.inRows;
  return nested;
}

void writeNestOutput(const NestedInstance& nested, const std::filesystem::path& folder) {
  std::filesystem::create_directories(folder);
  writeFileAtomically(folder / "layout.json", layoutJson(nested.instance, nested.result, nested.margin).dump(1) + "\n");
  writeFileAtomically(folder / "layout.svg",
                      layoutSvg(nested.instance.parts, nested.result, nested.options, nested.margin));
}

}  // namespace rotafab::jobs
