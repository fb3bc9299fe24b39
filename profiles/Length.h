#pragma once
// Lengths as users write them (docs/CONTRACT.md, "Units and scale"): a number with an
// optional unit, `in`, `mm` or `cm`; a bare number is in inches, the internal
// unit. "0.25in", "6.35mm", "0.635cm" and "0.25" are the same length.

#include <optional>
#include <string>
#include <string_view>
#include <utility>

namespace rotafab::profiles {

// The length in inches, or nullopt when the text is not a finite number with
// one of the units.
std::optional<double> parseLength(std::string_view text);

// A length option's value in inches (`flag`, "--kerf", names it in the
// message); zero allowed unless `positive`. Throws core::UserError: "--kerf
// 2furlongs: expected a length such as 0.125in, 3.2mm, 0.32cm, 2ft or 1.2m".
double lengthOption(const std::string& text, std::string_view flag, bool positive = false);

// The unit a length is written in: "in", "mm", "cm", "ft" or "m" ("in" for a bare number).
std::string_view writtenUnit(std::string_view text);

// `inches` in `unit` for people, to 4 significant digits: "400 mm", "0.125 in".
std::string formatLength(double inches, std::string_view unit);

// The unit's count per inch (25.4 for "mm"), or 1 for inches or an unknown unit.
double unitsPerInch(std::string_view unit);

// A size WIDTHxHEIGHT (docs/CONTRACT.md, "Units and scale": a unit written once
// at the end applies to both numbers, "800x600mm"; or one each, "32inx18in";
// none, inches: "31.5x17.5"), in inches; nullopt when it is not two lengths
// joined by an x, or when only the first has a unit ("32inx18": which unit the
// second has is a guess).
std::optional<std::pair<double, double>> parseSize(std::string_view text);

}  // namespace rotafab::profiles
