#pragma once
// The sheets of a planned job as a cutter runs them: a `make` output folder
// (its manifest's SVG sheets, in order) or one sheet's SVG, read back
// (SheetReader.h), and checked against the bed they are to be cut on.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "profiles/Profiles.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::jobs {

struct JobSheet {
  int index = 1;  // the sheet's number in the job
  std::filesystem::path file;
  SheetDrawing drawing;
};

// All the sheets, or only sheet `only`. Throws core::UserError naming the
// folder, the manifest or the sheet file and what is wrong.
std::vector<JobSheet> readJobSheets(const std::filesystem::path& target, std::optional<int> only);
// All the sheets of an output folder whose manifest (readManifest) the caller has read already.
std::vector<JobSheet> readJobSheets(const std::filesystem::path& folder, const nlohmann::ordered_json& manifest);
// The sheets of an output folder named as readManifestSheets lists them.
std::vector<JobSheet> readJobSheets(const std::filesystem::path& folder,
                                    const std::vector<std::pair<int, std::string>>& svgSheets);

// Throws core::UserError naming the first sheet larger than the machine's bed.
void checkSheetsFitBed(const std::vector<JobSheet>& sheets, const profiles::MachineProfile& machine);

}  // namespace rotafab::jobs
