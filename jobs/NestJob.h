#pragma once
// `rotafab nest` (docs/CONTRACT.md, "nest") as one call: the parts of an
// instance file nested onto beds or into a strip, checked exactly, with the
// contract's summary, and layout.json and layout.svg written where asked.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "core/WorkContext.h"
#include "jobs/Nesting.h"
#include "jobs/NestingInstance.h"
#include "profiles/Profiles.h"

namespace rotafab::jobs {

struct NestRequest {
  std::filesystem::path instance;
  bool strip = false;             // into a strip of the instance's strip_height
  profiles::Bed bed;              // for beds
  std::optional<double> spacing;  // default: 1/16 in on beds, 0 in the strip
  // The search: seconds, order, window, seed, evaluations, threads (the area and spacing are set from the above).
  NestingOptions search;
};

struct NestedInstance {
  NestingInstance instance;
  NestingOptions options;  // as nested
  NestingResult result;
  double margin = 0;  // of the bed (0 in the strip)
  // The summary (docs/CONTRACT.md, "nest"): sheets, utilization, strip_length,
  // density, seconds; and "layouts" (our extension: how many layouts the search
  // tried).
  nlohmann::ordered_json summary;
};

// Throws core::UserError naming the instance file and what is wrong with
// it or with the bed, core::Cancelled.
NestedInstance nestInstance(const NestRequest& request, const core::WorkContext& context);

// layout.json and layout.svg into `folder`.
void writeNestOutput(const NestedInstance& nested, const std::filesystem::path& folder);

}  // namespace rotafab::jobs
