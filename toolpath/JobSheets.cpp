#include "toolpath/JobSheets.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/UserError.h"
#include "profiles/Length.h"
#include "toolpath/JsonErrors.h"
#include "toolpath/ManifestFile.h"
#include "toolpath/SheetReader.h"

namespace rotafab::jobs {
namespace {

using SheetFiles = std::vector<std::pair<int, std::filesystem::path>>;  // (number, SVG file)

void requireSvgSheets(const std::filesystem::path& manifestFile, const SheetFiles& sheets) {
  if (sheets.empty()) {
    throw core::UserError(
        fmt::format("{}: lists no SVG sheet, which a cut is run from; make it again with svg in "
                    "--formats (the default)",
                    manifestFile.string()));
  }
}

// The SVG sheets an output folder's manifest lists.
SheetFiles listedSheets(const std::filesystem::path& folder, const nlohmann::ordered_json& manifest) {
  const auto manifestFile = folder / "manifest.json";
  SheetFiles sheets;
  try {
    for (const auto& sheet : manifest.at("sheets")) {
      const int64_t number = sheet.at("index");
      if (number < 1 || number > INT32_MAX) {
        throw core::UserError(
            fmt::format("{}: sheets: index {} is not a sheet's number (1, 2, ...)", manifestFile.string(), number));
      }
      const int index = static_cast<int>(number);
      for (const auto& file : sheet.at("files")) {
        const std::string name = file;
        if (name.ends_with(".svg")) sheets.emplace_back(index, folder / name);
      }
    }
  } catch (const nlohmann::json::exception& error) {
    throw core::UserError(fmt::format("{}: sheets: {}", manifestFile.string(), jsonErrorText(error)));
  }
  requireSvgSheets(manifestFile, sheets);
  return sheets;
}

// The sheets to read: an output folder's, or one sheet's SVG.
SheetFiles sheetFiles(const std::filesystem::path& target, std::optional<int> only) {
  SheetFiles sheets;
  if (std::filesystem::is_directory(target)) {
    sheets = listedSheets(target, readManifest(target));
  } else {
    if (target.extension() != ".svg") {
      throw core::UserError(
          fmt::format("{}: give the sheet's .svg (or the output folder of `rotafab make`)", target.string()));
    }
    sheets.emplace_back(1, target);
  }
  if (only) {
    const auto it = std::find_if(sheets.begin(), sheets.end(), [&](const auto& s) { return s.first == *only; });
    if (it == sheets.end()) {
      throw core::UserError(fmt::format("--sheet {}: {} has sheets 1 to {}", *only, target.string(), sheets.size()));
    }
    sheets = {*it};
  }
  return sheets;
}

std::vector<JobSheet> readSheets(const SheetFiles& files) {
  std::vector<JobSheet> sheets;
  for (const auto& [index, file] : files) {
    try {
      sheets.push_back({index, file, readSheetSvg(file)});
    } catch (const std::invalid_argument& error) {
      throw core::UserError(error.what());
    }
  }
  return sheets;
}

}  // namespace

std::vector<JobSheet> readJobSheets(const std::filesystem::path& target, std::optional<int> only) {
  return readSheets(sheetFiles(target, only));
}

std::vector<JobSheet> readJobSheets(const std::filesystem::path& folder, const nlohmann::ordered_json& manifest) {
  return readSheets(listedSheets(folder, manifest));
}

std::vector<JobSheet> readJobSheets(const std::filesystem::path& folder,
                                    const std::vector<std::pair<int, std::string>>& svgSheets) {
  SheetFiles sheets;
  for (const auto& [index, name] : svgSheets) sheets.emplace_back(index, folder / name);
  requireSvgSheets(folder / "manifest.json", sheets);
  return readSheets(sheets);
}

JobProfileNames jobProfileNames(const std::filesystem::path& target) {
  std::error_code error;
  const std::filesystem::path folder = std::filesystem::is_directory(target, error) ? target : target.parent_path();
  const std::filesystem::path manifest = folder / "manifest.json";
  if (!std::filesystem::exists(manifest, error)) return {};
  const auto read = readManifestSheets(manifest);
  if (!read) return {};
  return {read->machine, read->material, core::LengthUnit::named(read->displayUnits.value_or("")), manifest};
}

CuttingProfiles cuttingProfiles(const profiles::ProfileCatalogue& catalogue, const JobProfileNames& madeFor,
                                const std::string& machine, const std::string& material,
                                std::optional<std::string_view> driver) {
  // The job's own profiles, where this computer has them.
  std::optional<profiles::MachineProfile> madeOn;
  std::optional<profiles::MaterialProfile> madeWith;
  try {
    if (madeFor.machine) madeOn = profiles::findMachine(catalogue, *madeFor.machine);
  } catch (const profiles::ProfileError&) {
  }
  try {
    if (madeFor.material) madeWith = profiles::findMaterial(catalogue, *madeFor.material);
  } catch (const profiles::ProfileError&) {
  }
  const auto missing = [&](std::string_view kind, const std::string& name, std::string_view option) {
    return core::UserError(
        fmt::format("{}: names the {} {}, which no profile here has (`rotafab profiles` lists "
                    "them); give {} to cut it with another",
                    madeFor.manifest.string(), kind, name, option));
  };
  CuttingProfiles cutting;
  if (!machine.empty()) {
    cutting.machine = profiles::findMachine(catalogue, machine);
  } else if (madeFor.machine && !madeOn) {
    throw missing("machine", *madeFor.machine, "--machine NAME");
  } else if (madeOn && (!driver || madeOn->driver == *driver)) {
    cutting.machine = *madeOn;
  } else if (auto first = driver ? profiles::firstMachineFor(catalogue, *driver) : std::nullopt) {
    cutting.machine = *first;
  } else {
    throw core::UserError(fmt::format("no machine profile for the {} driver; give --machine", driver.value_or("")));
  }
  if (!material.empty()) {
    cutting.material = profiles::findMaterial(catalogue, material);
  } else if (madeFor.material && !madeWith) {
    throw missing("material", *madeFor.material, "--material NAME");
  } else {
    cutting.material =
        madeWith ? *madeWith : profiles::findMaterial(catalogue, std::string(profiles::kDefaultMaterial));
  }
  if (madeFor.machine || madeFor.material) {
    cutting.changes = profiles::settingChanges(madeOn.value_or(cutting.machine), madeWith.value_or(cutting.material),
                                               cutting.machine, cutting.material);
    // A profile of the job's that this computer lacks: what the job was made with is unknown, a change too.
    if (madeFor.machine && !madeOn) {
      cutting.changes.insert(cutting.changes.begin(), fmt::format("machine: {} instead of {} (no profile here)",
                                                                  cutting.machine.name, *madeFor.machine));
    }
    if (madeFor.material && !madeWith) {
      cutting.changes.insert(cutting.changes.begin(), fmt::format("material: {} instead of {} (no profile here)",
                                                                  cutting.material.name, *madeFor.material));
    }
  }
  return cutting;
}

std::string stockOf(const profiles::MaterialProfile& material, double width, double height, core::LengthUnit unit) {
  return fmt::format("{} ({}), {}", material.name, unit(material.thickness, 3), unit.size(width, height, 3));
}

void checkSheetsFitBed(const std::vector<JobSheet>& sheets, const profiles::MachineProfile& machine,
                       core::LengthUnit unit) {
  for (const JobSheet& sheet : sheets) {
    // The sheet's SVG gives its size to 1e-4 in: a 700 mm bed is written 27.5591 in, 27.559055 in rounded up.
    constexpr double kWrittenPrecision = 1e-4;
    if (sheet.drawing.width > machine.bed.width + kWrittenPrecision ||
        sheet.drawing.height > machine.bed.height + kWrittenPrecision) {
      throw core::UserError(
          fmt::format("{}: the sheet is {}, larger than the bed of {} ({}); "
                      "make it for this machine (`rotafab make ... --machine {}`)",
                      sheet.file.string(), unit.size(sheet.drawing.width, sheet.drawing.height, 3), machine.name,
                      unit.size(machine.bed.width, machine.bed.height, 3), machine.name));
    }
  }
}

}  // namespace rotafab::jobs
