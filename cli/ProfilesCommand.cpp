#include "cli/ProfilesCommand.h"

#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli/ExitStatus.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {
namespace {

struct ProfilesOptions {
  bool json = false;
  std::vector<std::string> files, checks;  // FILE..., --check FILE: the same
};

// A file given on the command line is checked as the kind it declares.
void checkFile(const std::string& file, profiles::ProfileCatalogue& into) {
  try {
    into.machines.push_back(profiles::loadMachineProfile(file));
  } catch (const profiles::ProfileError& asMachine) {
    try {
      into.materials.push_back(profiles::loadMaterialProfile(file));
    } catch (const profiles::ProfileError& asMaterial) {
      // Report against the kind the file says it is.
      const std::string message = asMachine.what();
      into.errors.push_back(message.find(": kind: expected 'machine'") != std::string::npos ? asMaterial.what()
                                                                                            : message);
    }
  }
}

int runProfiles(const ProfilesOptions& options) {
  profiles::ProfileCatalogue catalogue;
  if (options.files.empty()) {
    catalogue = profiles::loadProfiles(profiles::profileSearchPath());
  } else {
    for (const auto& file : options.files) checkFile(file, catalogue);
  }
  for (const auto& error : catalogue.errors) fmt::print(stderr, "error: {}\n", error);
  if (options.json) {
    nlohmann::ordered_json out = {{"machines", nlohmann::ordered_json::array()},
                                  {"materials", nlohmann::ordered_json::array()}};
    for (const auto& m : catalogue.machines) {
      out["machines"].push_back(
          {{"name", m.name},
           {"description", m.description},
           {"bed", {{"width", m.bed.width}, {"height", m.bed.height}, {"margin", m.bed.margin}, {"unit", m.bed.unit}}},
           {"driver", m.driver},
           {"connection", m.connection},
           {"file", m.source.string()}});
    }
    for (const auto& m : catalogue.materials) {
      out["materials"].push_back({{"name", m.name},
                                  {"description", m.description},
                                  {"thickness", m.thickness},
                                  {"kerf", m.kerf},
                                  {"fastener", m.fastenerDiameter},
                                  {"areal_density", m.arealDensity > 0 ? nlohmann::json(m.arealDensity) : nullptr},
                                  {"fastener_mass", m.fastenerMass},
                                  {"file", m.source.string()}});
    }
    std::cout << out.dump() << '\n';
  } else {
    // A section only where there is something in it: checking only bad
    // files prints nothing on standard output, only the errors.
    if (!catalogue.machines.empty()) fmt::print("machines\n");
    // Each in the unit its file gives (a 400 x 400 mm bed is not shown as 15.7 in).
    for (const auto& m : catalogue.machines) {
      const double k = profiles::unitsPerInch(m.bed.unit);
      fmt::print("  {:<18} {:>6.4g} x {:<6.4g} {:<2}  margin {:<10} {:<7} {:<34} {}\n", m.name, m.bed.width * k,
                 m.bed.height * k, m.bed.unit, profiles::formatLength(m.bed.margin, m.bed.unit), m.driver, m.connection,
                 m.source.string());
    }
    if (!catalogue.materials.empty()) fmt::print("materials\n");
    for (const auto& m : catalogue.materials) {
      fmt::print("  {:<18} {} thick, kerf {}, fastener {}  {}\n", m.name,
                 profiles::formatLength(m.thickness, m.units.thickness), profiles::formatLength(m.kerf, m.units.kerf),
                 profiles::formatLength(m.fastenerDiameter, m.units.fastener), m.source.string());
    }
  }
  return catalogue.errors.empty() ? kSuccess : kUserError;
}

}  // namespace

void addProfilesCommand(CLI::App& app, int& status) {
  auto options = std::make_shared<ProfilesOptions>();
  CLI::App* command = app.add_subcommand("profiles", "List the machine and material profiles, or check profile files");
  command->add_option("FILE", options->files, "Profile files to check instead of listing the search path");
  command->add_option("--check", options->checks, "A profile file to check (as FILE); may be given more than once");
  command->add_flag("--json", options->json, "Print one JSON object: {\"machines\": [...], \"materials\": [...]}");
  command->footer(
      "Profiles are YAML files in machines/ and materials/ under each folder of the search path, first match wins:\n"
      "  ./profiles, $XDG_CONFIG_HOME/rotafab/profiles (~/.config/rotafab/profiles), PREFIX/share/rotafab/profiles\n"
      "  (beside an installed PREFIX/bin/rotafab), /usr/share/rotafab/profiles.\n"
      "An invalid profile is reported as FILE:LINE:COL: key: what is wrong, and the exit status is 1.\n\n"
      "Examples:\n"
      "  rotafab profiles\n"
      "  rotafab profiles --check ~/.config/rotafab/profiles/machines/my-laser.yaml\n\n"
      "Every key, its unit and its default: docs/profiles.md.");
  command->callback([options, &status] {
    options->files.insert(options->files.end(), options->checks.begin(), options->checks.end());
    status = runProfiles(*options);
  });
}

}  // namespace rotafab::cli
