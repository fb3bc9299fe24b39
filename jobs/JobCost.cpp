#include "jobs/JobCost.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/Duration.h"

namespace rotafab::jobs {

double JobCost::totalSeconds() const { return std::accumulate(cuttingSeconds.begin(), cuttingSeconds.end(), 0.0); }

double JobCost::assemblySeconds() const {
  return panels * kAssemblySecondsPerPanel + fasteners * kAssemblySecondsPerFastener;
}

nlohmann::ordered_json costJson(const JobCost& cost) {
  nlohmann::ordered_json json = {
      {"material", cost.material},
      {"sheets", cost.sheets},
      {"sheet_size", {cost.sheetWidth, cost.sheetHeight}},
      {"fasteners", {{"count", cost.fasteners}, {"diameter", cost.fastenerDiameter}}},
      {"cutting_seconds",
       cost.cuttingSeconds.empty() ? nlohmann::ordered_json() : nlohmann::ordered_json(cost.totalSeconds())},
      {"sheet_cutting_seconds", cost.cuttingSeconds},
      {"motion", cost.motionGiven ? "profile" : "defaults"}};
  // Extension: one person's time to assemble it, seconds (JobCost.h's rate).
  if (cost.panels > 0) {
    json["panels"] = cost.panels;
    json["assembly_seconds"] = std::round(cost.assemblySeconds());
  }
  return json;
}

std::string costLine(const JobCost& cost, core::LengthUnit unit) {
  std::string line = fmt::format("{} sheet{} of {} ({})", cost.sheets, cost.sheets == 1 ? "" : "s", cost.material,
                                 unit.size(cost.sheetWidth, cost.sheetHeight, 3));
  if (cost.fasteners > 0) {
    // Fasteners are sold by their metric size too: inches give it beside.
    line += fmt::format(" and {} fastener{} of {}", cost.fasteners, cost.fasteners == 1 ? "" : "s",
                        unit(cost.fastenerDiameter, 3));
    if (!unit.metric()) line += fmt::format(" ({:.1f} mm)", cost.fastenerDiameter * 25.4);
  }
  if (!cost.cuttingSeconds.empty()) {
    line += fmt::format("; cutting about {}", core::minutes(cost.totalSeconds()));
    if (cost.cuttingSeconds.size() > 1) {
      const auto [shortest, longest] = std::minmax_element(cost.cuttingSeconds.begin(), cost.cuttingSeconds.end());
      line += fmt::format(" ({} to {} a sheet)", core::minutes(*shortest), core::minutes(*longest));
    }
    if (!cost.motionGiven) line += ", at GRBL's default speeds (the machine profile gives no motion)";
  }
  if (cost.panels > 0)
    line += fmt::format("; assembling about {} of one person's time", core::minutes(cost.assemblySeconds()));
  return line;
}

JobCost costFromJson(const nlohmann::json& json) {
  JobCost cost;
  cost.material = json.at("material").get<std::string>();
  cost.sheets = json.at("sheets").get<size_t>();
  cost.sheetWidth = json.at("sheet_size").at(0).get<double>(),
  cost.sheetHeight = json.at("sheet_size").at(1).get<double>();
  cost.fasteners = json.at("fasteners").at("count").get<int>();
  cost.fastenerDiameter = json.at("fasteners").at("diameter").get<double>();
  cost.cuttingSeconds = json.at("sheet_cutting_seconds").get<std::vector<double>>();
  cost.motionGiven = json.at("motion").get<std::string>() == "profile";
  cost.panels = json.value("panels", 0);
  return cost;
}

}  // namespace rotafab::jobs
