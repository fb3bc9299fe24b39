#include "profiles/Operation.h"

namespace rotafab::profiles {

std::string_view operationName(Operation operation) {
  switch (operation) {
    case Operation::Cut:
      return "cut";
    case Operation::Score:
      return "score";
    case Operation::Etch:
      return "etch";
    case Operation::Outline:
      return "outline";
  }
  return "unknown";  // not reached for a valid enumerator
}

std::string_view operationPurpose(Operation operation) {
  switch (operation) {
    case Operation::Cut:
      return "cuts through (outlines and holes)";
    case Operation::Score:
      return "scores fold lines";
    case Operation::Etch:
      return "etches the numbers";
    case Operation::Outline:
      return "draws the material's edge (never burnt)";
  }
  return "";
}

std::optional<Operation> operationNamed(std::string_view name) {
  for (Operation operation : kAllOperations)
    if (operationName(operation) == name) return operation;
  return std::nullopt;
}

}  // namespace rotafab::profiles
