#pragma once
// What the command-line verbs share: the one-line user error and length options.

#include <fmt/format.h>

#include <stdexcept>
#include <string>

#include "profiles/Length.h"

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

}  // namespace rotafab::cli
