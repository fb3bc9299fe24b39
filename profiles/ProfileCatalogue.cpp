// Finding profiles: the search path and the catalogue of what it holds.

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>

#include "core/ProgramFolders.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::profiles {
namespace {

std::vector<std::filesystem::path> yamlFilesIn(const std::filesystem::path& folder) {
  std::vector<std::filesystem::path> files;
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const auto extension = entry.path().extension();
    if (entry.is_regular_file(error) && (extension == ".yaml" || extension == ".yml")) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());  // deterministic
  return files;
}

template <typename Profile>
void addUnlessShadowed(std::vector<Profile>& into, Profile profile) {
  const bool known = std::any_of(into.begin(), into.end(), [&](const Profile& p) { return p.name == profile.name; });
  if (!known) into.push_back(std::move(profile));
}

template <typename Profile>
std::string namesOf(const std::vector<Profile>& profiles) {
  std::vector<std::string> names;
  for (const auto& p : profiles) names.push_back(p.name);
  return names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace

std::vector<std::filesystem::path> profileSearchPath() {
  std::vector<std::filesystem::path> path{std::filesystem::path("profiles")};
  if (const char* config = std::getenv("XDG_CONFIG_HOME"); config && *config) {
    path.push_back(std::filesystem::path(config) / "rotafab" / "profiles");
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    path.push_back(std::filesystem::path(home) / ".config" / "rotafab" / "profiles");
  }
  // Installed (cmake --install): beside the program, wherever its prefix is; then the system's.
  const auto installed = core::installedDataFolder() / "profiles";
  if (installed != "/usr/share/rotafab/profiles") path.push_back(installed);
  path.push_back("/usr/share/rotafab/profiles");
#if defined(ROTAFAB_PROFILES_DIR) && defined(ROTAFAB_BUILD_DIR)
  // The shipped profiles of the source tree, for a program run from its build tree (not once installed).
  std::error_code error;
  if (std::filesystem::equivalent(core::programFolder(), ROTAFAB_BUILD_DIR, error))
    path.push_back(ROTAFAB_PROFILES_DIR);
#endif
  return path;
}

ProfileCatalogue loadProfiles(const std::vector<std::filesystem::path>& searchPath) {
  ProfileCatalogue catalogue;
  std::vector<std::filesystem::path> seen;
  for (const auto& folder : searchPath) {
    std::error_code error;
    const auto canonical = std::filesystem::weakly_canonical(folder, error);
    if (std::find(seen.begin(), seen.end(), canonical) != seen.end()) continue;  // ./profiles may be the shipped folder
    seen.push_back(canonical);
    for (const auto& file : yamlFilesIn(folder / "machines")) {
      try {
        addUnlessShadowed(catalogue.machines, loadMachineProfile(file));
      } catch (const ProfileError& e) {
        catalogue.errors.push_back(e.what());
      }
    }
    for (const auto& file : yamlFilesIn(folder / "materials")) {
      try {
        addUnlessShadowed(catalogue.materials, loadMaterialProfile(file));
      } catch (const ProfileError& e) {
        catalogue.errors.push_back(e.what());
      }
    }
  }
  return catalogue;
}

MachineProfile findMachine(const ProfileCatalogue& catalogue, const std::string& name) {
  for (const auto& machine : catalogue.machines)
    if (machine.name == name) return machine;
  throw ProfileError(fmt::format("no machine profile named '{}' (there are: {}; `rotafab profiles` lists them)", name,
                                 namesOf(catalogue.machines)));
}

std::optional<MachineProfile> firstMachineFor(const ProfileCatalogue& catalogue, std::string_view driver) {
  for (const auto& machine : catalogue.machines)
    if (machine.driver == driver) return machine;
  return std::nullopt;
}

MaterialProfile findMaterial(const ProfileCatalogue& catalogue, const std::string& name) {
  for (const auto& material : catalogue.materials)
    if (material.name == name) return material;
  throw ProfileError(fmt::format("no material profile named '{}' (there are: {}; `rotafab profiles` lists them)", name,
                                 namesOf(catalogue.materials)));
}

OperationSettings operationSettings(const MachineProfile& machine, const MaterialProfile& material,
                                    Operation operation) {
  const ColourSetting& row = machine.settingFor(operation);
  OperationSettings settings{row.power, row.speed, row.passes};
  std::optional<double> minPower = row.minPower;
  if (const auto overrides = material.machines.find(machine.name); overrides != material.machines.end()) {
    if (const auto it = overrides->second.find(operation); it != overrides->second.end()) {
      settings.power = it->second.power.value_or(settings.power);
      settings.speed = it->second.speed.value_or(settings.speed);
      settings.passes = it->second.passes.value_or(settings.passes);
      if (it->second.minPower) minPower = it->second.minPower;
    }
  }
  settings.minPower = std::min(minPower.value_or(settings.power), settings.power);
  return settings;
}

std::vector<std::string> settingChanges(const MachineProfile& madeFor, const MaterialProfile& madeWith,
                                        const MachineProfile& cutOn, const MaterialProfile& cutWith) {
  std::vector<std::string> changes;
  const auto said = [](const OperationSettings& s) {
    return fmt::format("{:g}% power at {:g}% speed, {} pass{}", s.power, s.speed, s.passes, s.passes == 1 ? "" : "es");
  };
  if (madeFor.name != cutOn.name) changes.push_back(fmt::format("machine: {} instead of {}", cutOn.name, madeFor.name));
  if (madeWith.name != cutWith.name) {
    changes.push_back(fmt::format("material: {} ({}) instead of {} ({})", cutWith.name,
                                  formatLength(cutWith.thickness, cutWith.units.thickness), madeWith.name,
                                  formatLength(madeWith.thickness, madeWith.units.thickness)));
  }
  for (const Operation operation : {Operation::Cut, Operation::Score, Operation::Etch}) {
    const OperationSettings before = operationSettings(madeFor, madeWith, operation);
    const OperationSettings after = operationSettings(cutOn, cutWith, operation);
    if (before == after) continue;
    changes.push_back(fmt::format("{}: {} instead of {}", operationName(operation), said(after), said(before)));
  }
  return changes;
}

}  // namespace rotafab::profiles
