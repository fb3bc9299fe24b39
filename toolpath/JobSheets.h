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

#include "core/LengthUnit.h"
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

// The machine and material profiles a job was planned for, by name, from
// its folder's manifest.json (for one sheet's .svg, the manifest beside
// it), where it says them: jobs made before the manifest named them, and
// sheets with no manifest, have neither.
struct JobProfileNames {
  std::optional<std::string> machine, material;
  std::optional<core::LengthUnit> shownIn;  // its lengths' unit for people ("display_units"), where it says it
  std::filesystem::path manifest;           // where they were read, for messages
};
JobProfileNames jobProfileNames(const std::filesystem::path& target);

// The profiles a job is cut with: the ones asked for (`machine`,
// `material`, empty for none), else the job's own, else the first machine
// the device's driver drives and posterboard; `changes` says what differs
// from the job's own settings (profiles::settingChanges), empty when it
// is cut as it was made. `madeFor` the job's names: one no profile here
// has is a change where another is asked for, else core::UserError naming
// the manifest. Throws profiles::ProfileError for an asked name no profile
// has, core::UserError when no machine is driven by `driver`.
struct CuttingProfiles {
  profiles::MachineProfile machine;
  profiles::MaterialProfile material;
  std::vector<std::string> changes;
};
CuttingProfiles cuttingProfiles(const profiles::ProfileCatalogue& catalogue, const JobProfileNames& madeFor,
                                const std::string& machine, const std::string& material,
                                std::optional<std::string_view> driver);

// What the operator loads for each sheet of a job, for people: the
// material, its thickness and the sheet's size (`width` x `height` inches),
// shown in `unit`: "posterboard (0.031 in), 32 x 18 in", "plywood-3mm (3 mm),
// 400 x 400 mm".
std::string stockOf(const profiles::MaterialProfile& material, double width, double height, core::LengthUnit unit);

// Throws core::UserError naming the first sheet larger than the machine's
// bed, the sizes in `unit`.
void checkSheetsFitBed(const std::vector<JobSheet>& sheets, const profiles::MachineProfile& machine,
                       core::LengthUnit unit = {});

}  // namespace rotafab::jobs
