#include "jobs/NestingInstance.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "toolpath/JsonErrors.h"

namespace rotafab::jobs {

// Reads the instance: one part per copy of each item. Names the element at fault.
NestingInstance readNestingInstance(const std::string& file) {
  NestingInstance result;
  auto& parts = result.parts;
  std::ifstream in(file);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot open the file", file));
  nlohmann::json instance;
  try {
    instance = nlohmann::json::parse(in);
  } catch (const nlohmann::json::parse_error& error) {
    throw std::invalid_argument(fmt::format("{}: not JSON: {}", file, jsonErrorText(error)));
  }
  auto fail = [&](const std::string& where, const std::string& what) {
    return std::invalid_argument(fmt::format("{}: {}: {}", file, where, what));
  };
  if (!instance.is_object() || !instance.contains("items") || !instance["items"].is_array()) {
    throw fail("items", "expected an object with an \"items\" list");
  }
  result.stripHeight = instance.value("strip_height", 0.0);
  for (size_t i = 0; i < instance["items"].size(); ++i) {
    const auto& item = instance["items"][i];
    const std::string at = fmt::format("items[{}]", i);
    if (!item.is_object()) throw fail(at, "expected an object");
    NestingInstance::Item entry;
    entry.id = item.contains("id") && item["id"].is_number_integer() ? item["id"].get<int>() : static_cast<int>(i);
    if (item.contains("demand")) {
      if (!item["demand"].is_number_integer() || item["demand"].get<int>() < 1 || item["demand"].get<int>() > 100000) {
        throw fail(at + ".demand", "expected a whole number from 1");
      }
      entry.demand = item["demand"].get<int>();
    }
    std::vector<double> rotations{0.0};
    if (item.contains("allowed_orientations")) {
      rotations.clear();
      for (const auto& r : item["allowed_orientations"]) {
        if (!r.is_number()) throw fail(at + ".allowed_orientations", "expected numbers (degrees)");
        rotations.push_back(r.get<double>());
      }
      if (rotations.empty()) throw fail(at + ".allowed_orientations", "is empty");
    }
    const auto shape = item.value("shape", nlohmann::json::object());
    if (shape.value("type", "") != "simple_polygon") throw fail(at + ".shape.type", "only simple_polygon is supported");
    if (!shape.contains("data") || !shape["data"].is_array())
      throw fail(at + ".shape.data", "expected a list of points");
    Polygon2 outline;
    for (size_t k = 0; k < shape["data"].size(); ++k) {
      const auto& point = shape["data"][k];
      if (!point.is_array() || point.size() != 2 || !point[0].is_number() || !point[1].is_number()) {
        throw fail(fmt::format("{}.shape.data[{}]", at, k), "expected [x, y]");
      }
      outline.emplace_back(point[0].get<double>(), point[1].get<double>());
      if (!outline.back().allFinite()) throw fail(fmt::format("{}.shape.data[{}]", at, k), "not a finite point");
    }
    if (outline.size() > 1 && outline.front() == outline.back()) outline.pop_back();  // closed rings repeat the start
    if (outline.size() < 3 || std::abs(polygonArea(outline)) <= 0) {
      throw fail(at + ".shape.data", "expected a polygon of at least 3 points with area");
    }
    for (int copy = 0; copy < entry.demand; ++copy) {
      NestingPart part;
      part.name = fmt::format("item {} copy {}", entry.id, copy + 1);
      part.outline = outline;
      part.rotations = rotations;
      part.order = static_cast<int>(parts.size());
      parts.push_back(std::move(part));
      result.itemOfPart.push_back(entry.id);
      result.copyOfPart.push_back(copy);
    }
    result.items.push_back(entry);
  }
  if (parts.empty()) throw fail("items", "no items");
  return result;
}

nlohmann::ordered_json layoutJson(const NestingInstance& instance, const NestingResult& result, double margin) {
  nlohmann::ordered_json layout = {{"placements", nlohmann::ordered_json::array()}};
  for (size_t cut = 0; cut < result.placements.size(); ++cut) {
    const auto& p = result.placements[cut];
    layout["placements"].push_back({{"item", instance.itemOfPart[p.part]},
                                    {"copy", instance.copyOfPart[p.part]},
                                    {"sheet", p.sheet},
                                    {"x", p.x + margin},
                                    {"y", p.y + margin},
                                    {"rotation", p.rotation},
                                    {"moved", static_cast<int>(cut) - instance.parts[p.part].order}});
  }
  return layout;
}

}  // namespace rotafab::jobs
