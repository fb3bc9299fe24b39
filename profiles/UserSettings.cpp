#include "profiles/UserSettings.h"

#include <system_error>

#include "core/ProgramFolders.h"
#include "profiles/Length.h"
#include "profiles/YamlReader.h"

namespace rotafab::profiles {

std::filesystem::path userSettingsFile() {
  const std::string config = core::environmentValue("XDG_CONFIG_HOME");
  const std::filesystem::path folder = config.empty() ? core::homeFolder() / ".config" : std::filesystem::path(config);
  return folder / "rotafab" / "config.yaml";
}

UserSettings readUserSettings(const std::filesystem::path& file) {
  UserSettings settings;
  std::error_code error;
  const auto type = std::filesystem::status(file, error).type();
  if (type == std::filesystem::file_type::not_found) return settings;
  // (A FIFO would hang the reader; a folder is no settings.)
  if (type != std::filesystem::file_type::regular) throw ProfileError(file.string() + ": not a regular file");
  const YamlReader reader(file);
  const YAML::Node root = reader.load("settings", "expected a map of keys (units)", /*emptyIsMap=*/true);
  const auto keys = reader.keys(root, "", {"units"}, {});
  if (keys.contains("units")) settings.units = reader.shownUnit(root["units"], "units");
  return settings;
}

core::LengthUnit shownUnit(const std::string& given, std::optional<core::LengthUnit> preferred,
                           const std::string& sizeText, std::string_view bedUnit) {
  if (const auto unit = core::LengthUnit::named(given)) return *unit;
  if (preferred) return *preferred;
  const std::string_view written = sizeText.empty() ? bedUnit : writtenUnit(sizeText);
  const bool metric = written == "mm" || written == "cm" || written == "m";
  return metric ? core::LengthUnit::millimetres() : core::LengthUnit::inches();
}

}  // namespace rotafab::profiles
