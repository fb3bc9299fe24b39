#pragma once
// Instance files of the jagua-rs / sparrow format (docs/CONTRACT.md, "nest"):
// {"name", "strip_height", "items": [{"id", "demand", "allowed_orientations":
// [deg...], "shape": {"type": "simple_polygon", "data": [[x, y], ...]}}]}. One
// part per copy of each item, numbered in file order.

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "jobs/Nesting.h"

namespace rotafab::jobs {

struct NestingInstance {
  struct Item {
    int id = 0;
    int demand = 1;
  };
  std::vector<Item> items;
  std::vector<NestingPart> parts;  // every copy, in file order
  std::vector<int> itemOfPart;     // the item id of each part
  std::vector<int> copyOfPart;     // 0-based copy number of each part
  double stripHeight = 0;          // 0 when the file gives none
};

// Throws std::invalid_argument "FILE: items[3].shape.data: what is wrong".
NestingInstance readNestingInstance(const std::string& file);

// layout.json (docs/CONTRACT.md, "nest"): {"placements": [{"item", "copy",
// "sheet", "x", "y", "rotation"}]}, one per part copy in cutting order, on the
// bed (the usable area's placements moved by `margin`), with our extension
// "moved": how far the layout moved the part from its order in the file.
nlohmann::ordered_json layoutJson(const NestingInstance& instance, const NestingResult& result, double margin);

}  // namespace rotafab::jobs
