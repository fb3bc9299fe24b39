#pragma once
// The assembly steps of a manifest read back, as manifest.txt and
// manifest.html show them (dissertation V.5: the builders join the panels
// in flood-fill order). Shared by ManifestText.cpp and ManifestHtml.cpp;
// each throws nlohmann::json::exception on a manifest that is not version 1.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/LengthUnit.h"

namespace rotafab::jobs {

// One assembly step as the builders read it, whatever the structure.
struct StepLine {
  int panel = 0, sheet = 0, fasteners = 0;
  int thread = 0;  // a woven panel's (its source's cycle); 0 for a band panel
  std::string joins;
};

// The steps in assembly order, whatever the structure.
std::vector<StepLine> stepLines(const nlohmann::ordered_json& manifest);
// A sheet's kit: the steps (panel ids, in assembly order) whose panels it
// holds, from `first` to `last`, `run` when they are every step between;
// `completes`: once it and the sheets before it are cut, steps 1 to
// `completes` can all be done (their panels and pieces cut), 0 for none.
struct SheetKit {
  int first = 0, last = 0;
  bool run = true;
  int completes = 0;
};
// Each sheet's kit, in sheet order, from the panels' sheets (and their pieces').
std::vector<SheetKit> sheetKits(const nlohmann::ordered_json& manifest);
// "steps 1-176", "steps 3 to 3650 (not in one run)".
std::string kitText(const SheetKit& kit);

// What the steps mean, for the structure.
std::string howToJoin(const nlohmann::ordered_json& manifest);
// "band structure, 12 panels on 2 sheets, 30 fasteners".
std::string headline(const nlohmann::ordered_json& manifest);
// What the builders should know before they start, one sentence each, the
// lengths in `unit`.
std::vector<std::string> buildNotes(const nlohmann::ordered_json& manifest, core::LengthUnit unit);

}  // namespace rotafab::jobs
