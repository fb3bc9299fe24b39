#pragma once
// A small sheet for toolpath tests (an etch, a score, two parts with a hole
// each) and the GRBL machine profile it is planned for.

#include <string>

#include "profiles/Profiles.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::test {

using jobs::Operation;
using jobs::SheetDrawing;

inline SheetDrawing sheet() {
  SheetDrawing s;
  s.width = 15, s.height = 15, s.margin = 0.25;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  s.paths.push_back({Operation::Outline, {{0, 0}, {15, 0}, {15, 15}, {0, 15}}, true});
  s.paths.push_back({Operation::Etch, {{1, 1}, {1.5, 1.2}, {2, 1}}, false});
  s.paths.push_back({Operation::Score, {{4, 3}, {1, 3}}, false});
  for (double x : {6.0, 1.0}) {
    s.paths.push_back({Operation::Cut, {{x + 1, 5}, {x + 2, 5}, {x + 2, 6}, {x + 1, 6}}, true});  // a hole
    s.paths.push_back({Operation::Cut, {{x, 4}, {x + 4, 4}, {x + 4, 8}, {x, 8}}, true});          // its part
  }
  return s;
}

inline const profiles::MachineProfile& grblMachine() {
  static const auto machine =
      profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/grbl-diode-400.yaml");
  return machine;
}

}  // namespace rotafab::test
