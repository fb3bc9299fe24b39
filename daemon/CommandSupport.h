#pragma once
// What the command-line verbs share: the one-line user error, length options and error reporting.

#include <fmt/format.h>

#include <stdexcept>
#include <string>

#include "daemon/ExitCode.h"
#include "profiles/Length.h"
#include "profiles/Profiles.h"

namespace rotafab::cli {

// Bad input or a bad option value: printed as one line, exit status 1.
class UserError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

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

}  // namespace rotafab::cli
