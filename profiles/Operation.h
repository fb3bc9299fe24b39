#pragma once
// The operations that a machine profile maps to colours (docs/CONTRACT.md,
// "Profiles"), and the colours themselves. Profiles own these: jobs and devices
// know profiles, never the other way round.

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rotafab::profiles {

// Defaults of the dissertation (fig. 64-65): cut = blue, etch = yellow,
// outline = green (the material's edge, not cut), score = red.
enum class Operation { Cut, Score, Etch, Outline };

inline constexpr std::array<Operation, 4> kAllOperations{Operation::Cut, Operation::Score, Operation::Etch,
                                                         Operation::Outline};

// "cut", "score", "etch", "outline".
std::string_view operationName(Operation operation);
std::optional<Operation> operationNamed(std::string_view name);
// What the operation does, for people: "scores fold lines".
std::string_view operationPurpose(Operation operation);

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

}  // namespace rotafab::profiles
