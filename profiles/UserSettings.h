#pragma once
// The user's own settings (docs/CONTRACT.md, "The user's settings"): a YAML
// file, $XDG_CONFIG_HOME/rotafab/config.yaml (else
// ~/.config/rotafab/config.yaml), read by the command line. Today one key:
// `units`, `mm` or `in`, the unit lengths are shown in.

#include <filesystem>
#include <optional>

#include "core/LengthUnit.h"

namespace rotafab::profiles {

struct UserSettings {
  std::optional<core::LengthUnit> units;  // unset: not said
};

// Where the user's settings are, whether or not the file exists.
std::filesystem::path userSettingsFile();

// The settings in `file`; none when it does not exist. Throws ProfileError
// naming the file, the line and the key at fault, or a file that is not a
// regular one.
UserSettings readUserSettings(const std::filesystem::path& file = userSettingsFile());

// The unit to show a job's lengths in: `given` (--units, "mm" or "in") when
// not empty, else `preferred` (the user's or the daemon's setting) when set,
// else the unit `sizeText` (--size) is written in, else the one the machine
// profile gives its bed in (`bedUnit`); millimetres for mm, cm or m, else
// inches.
core::LengthUnit shownUnit(const std::string& given, std::optional<core::LengthUnit> preferred,
                           const std::string& sizeText, std::string_view bedUnit = "in");

}  // namespace rotafab::profiles
