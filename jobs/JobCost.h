#pragma once
// What a job takes, for the summary and the manifest: the sheets of which
// material, the fasteners to buy, and the cutting time.

#include <nlohmann/json.hpp>

#include "core/LengthUnit.h"

#include <string>
#include <vector>

namespace rotafab::jobs {

// What the job takes (docs/CONTRACT.md, "make": the summary, and the
// manifest's "cost"; docs/sheets.md, "What the job takes"): the sheets, the
// fasteners to buy, and the cutting time of each sheet as its toolpath runs
// on the machine of the profile (its `motion`).
struct JobCost {
  std::string material;
  size_t sheets = 0;
  double sheetWidth = 0, sheetHeight = 0;  // inches: the bed's
  int fasteners = 0;
  double fastenerDiameter = 0;         // inches
  std::vector<double> cuttingSeconds;  // per sheet; empty when no toolpath could be planned
  bool motionGiven = false;            // the machine profile gives its motion (else GRBL's defaults)
  int panels = 0;                      // to assemble (a panel's pieces are part of its step)
  [[nodiscard]] double totalSeconds() const;
  // One person's time to assemble it (assemblySeconds()).
  [[nodiscard]] double assemblySeconds() const;
};

// The dissertation's bunny (VI.2.2): 2,104 panels joined with 8,416
// fasteners by three students in 8 h 20 min, 25 person-hours; half of it
// taken as finding and placing the panels, half as fastening them, so
// that a job with more fasteners to a panel takes longer.
inline constexpr double kAssemblySecondsPerPanel = 25.0 * 3600 / 2 / 2104;
inline constexpr double kAssemblySecondsPerFastener = 25.0 * 3600 / 2 / 8416;

// The cost as manifest.json's "cost" (and the summary's), and back.
nlohmann::ordered_json costJson(const JobCost& cost);
JobCost costFromJson(const nlohmann::json& json);  // throws nlohmann::json::exception
// "2 sheets of posterboard (32 x 18 in) and 298 fasteners of 0.125 in (3.2 mm); cutting about 12m 30s;
// assembling about 1h 10m of one person's time", the lengths in `unit` (in
// millimetres: "(812.8 x 457.2 mm) and 298 fasteners of 3.2 mm").
std::string costLine(const JobCost& cost, core::LengthUnit unit = {});

}  // namespace rotafab::jobs
