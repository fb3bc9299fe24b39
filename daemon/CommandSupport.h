#pragma once
// What the command-line verbs share: the one-line user error, length options and error reporting.

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <stdexcept>
#include <string>

#include "core/UserError.h"
#include "daemon/ExitCode.h"
#include "geometry/Parameters.h"
#include "jobs/Nesting.h"
#include "jobs/OutputFolder.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {

// Bad input or a bad option value: printed as one line, exit status 1.
using core::UserError;

// A length option in in, mm or cm (a bare number is inches); zero allowed
// unless `positive`.
inline double lengthOption(const std::string& text, const char* option, bool positive = false) {
  const auto value = profiles::parseLength(text);
  if (!value || *value < 0 || (positive && !(*value > 0))) {
    throw UserError(fmt::format("{} {}: expected a {}length such as 0.125in, 3.2mm or 0.32cm", option, text,
                                positive ? "positive " : ""));
  }
  return *value;
}

// A build parameter by the flag that sets it, for messages: "--fastener".
inline std::string flagOf(geometry::Parameter parameter) {
  switch (parameter) {
    case geometry::Parameter::Structure:
      return "--structure";
    case geometry::Parameter::Holes:
      return "--holes";
    case geometry::Parameter::Repair:
      return "--repair";
    case geometry::Parameter::MergeCoplanar:
      return "--merge-coplanar";
    case geometry::Parameter::Panels:
      return "--panels";
    case geometry::Parameter::Size:
      return "--size";
    case geometry::Parameter::Scale:
      return "--scale";
    case geometry::Parameter::Fastener:
      return "--fastener";
    case geometry::Parameter::Start:
      return "--start";
    case geometry::Parameter::Width:
      return "--width";
    case geometry::Parameter::Offset:
      return "--offset";
  }
  return "--" + geometry::parameterInWords(parameter);
}

// --order strict|window|free (CLI11 has checked the word).
inline jobs::OrderMode orderOption(const std::string& order) {
  return order == "strict" ? jobs::OrderMode::Strict
         : order == "free" ? jobs::OrderMode::Free
                           : jobs::OrderMode::Window;
}

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
