#pragma once
// Lengths as users write them (SPEC, "Units and scale"): a number with an
// optional unit, `in`, `mm` or `cm`; a bare number is in inches, the internal
// unit. "0.25in", "6.35mm", "0.635cm" and "0.25" are the same length.

#include <optional>
#include <string_view>

namespace rotafab::profiles {

// The length in inches, or nullopt when the text is not a finite number with
// one of the units.
std::optional<double> parseLength(std::string_view text);

}  // namespace rotafab::profiles
