#pragma once
// What the command-line verbs share: the one-line user error, length options and error reporting.

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>

#include "cli/ExitStatus.h"
#include "core/UserError.h"
#include "jobs/MakeOptions.h"
#include "jobs/Nesting.h"
#include "jobs/OutputFolder.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"
#include "profiles/UserSettings.h"

namespace rotafab::cli {

// Bad input or a bad option value: printed as one line, exit status 1.
using core::UserError;

using jobs::flagOf;       // a build parameter by the flag that sets it, for messages: "--fastener"
using jobs::orderModeOf;  // --order strict|window|free (CLI11 has checked the word)
using profiles::lengthOption;

// Runs a command's body and reports the errors every command reports alike,
// as one line on stderr with exit status 1: a UserError or an invalid profile
// as it is, anything else after `subject` (the file the command works on).
// The body catches its own first (a device fault, an invalid mesh).
template <typename Body>
int reportingErrors(const std::string& subject, Body&& body) {
  try {
    return body();
  } catch (const UserError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
  } catch (const profiles::ProfileError& error) {
    fmt::print(stderr, "error: {}\n", error.what());
  } catch (const std::exception& error) {
    fmt::print(stderr, "error: {}: {}\n", subject, error.what());
  }
  return kUserError;
}

// The unit to show lengths in: `given` (--units, "mm" or "in") when not
// empty, else the user's setting (profiles/UserSettings.h: a bad settings
// file throws ProfileError, reported as above), else `otherwise` (the job's
// own, or the unit --size is written in).
inline core::LengthUnit unitShown(const std::string& given, core::LengthUnit otherwise) {
  if (const auto unit = core::LengthUnit::named(given)) return *unit;
  return profiles::readUserSettings().units.value_or(otherwise);
}

// --units, for the verbs that show lengths.
inline CLI::Option* addUnitsOption(CLI::App* command, std::string& units) {
  return command
      ->add_option("--units", units,
                   "Show lengths in mm or in (default: `units:` in ~/.config/rotafab/config.yaml, else the job's)")
      ->check(CLI::IsMember({"mm", "in"}));
}

// An --out folder option's check (a usage error, before any work): not a
// file, nor inside one, and writable.
inline CLI::Validator outputFolderCheck() {
  return CLI::Validator(
      [](std::string& folder) {
        const std::string why = jobs::whyNotAnOutputFolder(folder);
        return why.empty() ? std::string() : fmt::format("{}: {}", folder, why);
      },
      "FOLDER");
}

}  // namespace rotafab::cli
