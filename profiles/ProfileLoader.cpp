// Reading and validating profile files. Every refusal is one line,
// "FILE:LINE:COL: key: what is wrong", pointing at the key or value at fault.

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>

#include "profiles/Length.h"
#include "profiles/Profiles.h"
#include "profiles/YamlReader.h"

namespace rotafab::profiles {
namespace {

using ProfileReader = YamlReader;

void requireKind(const ProfileReader& reader, const YAML::Node& root, const std::string& kind) {
  if (!root["kind"]) reader.fail(root, "kind", fmt::format("missing (this should be 'kind: {}')", kind));
  const std::string found = reader.text(root["kind"], "kind");
  if (found != kind) reader.fail(root["kind"], "kind", fmt::format("expected '{}', found '{}'", kind, found));
}

LaserMode laserMode(const ProfileReader& reader, const YAML::Node& node, const std::string& key) {
  const std::string mode = reader.text(node, key);
  if (mode == "vector") return LaserMode::Vector;
  if (mode == "raster") return LaserMode::Raster;
  if (mode == "raster+vector") return LaserMode::RasterAndVector;
  reader.fail(node, key, fmt::format("expected vector, raster or raster+vector, found '{}'", mode));
}

// The URI schemes each driver accepts (docs/CONTRACT.md, "Devices").
void checkConnection(const ProfileReader& reader, const YAML::Node& node, const std::string& driver,
                     const std::string& uri) {
  const std::map<std::string, std::vector<std::string>> schemes{
      {"spool", {"spool:"}},
      {"grbl", {"grbl://", "grbl+tcp://", "sim:grbl"}},
      {"m2nano", {"m2nano://", "sim:m2nano"}},
      {"ruida", {"ruida://", "ruida+serial://", "sim:ruida"}}};
  for (const auto& scheme : schemes.at(driver))
    if (uri.starts_with(scheme)) return;
  reader.fail(
      node, "connection",
      fmt::format("'{}' is not a {} device URI (expected {})", uri, driver, fmt::join(schemes.at(driver), " or ")));
}

// The largest bed side read as inches without a unit (a 2.5 m machine):
// "bed: {width: 400}" is far more likely millimetres.
constexpr double kMostBareBedInches = 100.0;

}  // namespace

const ColourSetting& MachineProfile::settingFor(Operation operation) const {
  const std::string& colour = operationColour.at(operation);
  return *std::find_if(colours.begin(), colours.end(), [&](const ColourSetting& c) { return c.name == colour; });
}

std::string frameLight(double framePower) {
  return framePower > 0 ? fmt::format("laser at {:g}% power", framePower) : "laser off";
}

MachineProfile loadMachineProfile(const std::filesystem::path& file) {
  const ProfileReader reader(file);
  const YAML::Node root = reader.load();
  requireKind(reader, root, "machine");
  reader.keys(root, "",
              {"kind", "name", "description", "bed", "driver", "connection", "colours", "operations", "motion",
               "formats", "frame_power"},
              {"name", "bed", "driver", "connection", "colours"});
  MachineProfile machine;
  machine.source = file;
  machine.name = reader.text(root["name"], "name");
  if (root["description"]) machine.description = reader.text(root["description"], "description");

  const YAML::Node bed = root["bed"];
  reader.keys(bed, "bed", {"width", "height", "margin"}, {"width", "height"});
  machine.bed.width = reader.length(bed["width"], "bed.width", 0.0, false, kMostBareBedInches);
  machine.bed.unit = writtenUnit(bed["width"].Scalar());
  machine.bed.height = reader.length(bed["height"], "bed.height", 0.0, false, kMostBareBedInches);
  if (bed["margin"]) machine.bed.margin = reader.length(bed["margin"], "bed.margin", 0.0, true, 4.0);
  if (2 * machine.bed.margin >= std::min(machine.bed.width, machine.bed.height)) {
    reader.fail(bed, "bed",
                fmt::format("margins of {}in on every side leave no usable area on a {} x {} in bed",
                            machine.bed.margin, machine.bed.width, machine.bed.height));
  }

  if (const YAML::Node motion = root["motion"]) {
    reader.keys(motion, "motion", {"speed", "acceleration", "junction_deviation"}, {"speed", "acceleration"});
    MachineMotion m;
    m.maxSpeed = reader.rate(motion["speed"], "motion.speed", 1);
    m.acceleration = reader.rate(motion["acceleration"], "motion.acceleration", 2);
    if (motion["junction_deviation"]) {
      m.junctionDeviation = reader.length(motion["junction_deviation"], "motion.junction_deviation", 0.0, true, 0.5);
    }
    machine.motion = m;
  }

  if (const YAML::Node formats = root["formats"]) {
    if (!formats.IsSequence()) reader.fail(formats, "formats", "expected a list of sheet formats, e.g. [dxf]");
    for (size_t i = 0; i < formats.size(); ++i) {
      const std::string at = fmt::format("formats[{}]", i);
      const std::string format = reader.text(formats[i], at);
      if (format != "eps" && format != "svg" && format != "dxf") {
        reader.fail(formats[i], at, fmt::format("expected eps, svg or dxf, found '{}'", format));
      }
      machine.formats.push_back(format);
    }
  }

  machine.driver = reader.text(root["driver"], "driver");
  if (machine.driver != "spool" && machine.driver != "grbl" && machine.driver != "m2nano" &&
      machine.driver != "ruida") {
    reader.fail(root["driver"], "driver",
                fmt::format("expected spool, grbl, m2nano or ruida, found '{}'", machine.driver));
  }
  machine.connection = reader.text(root["connection"], "connection");
  checkConnection(reader, root["connection"], machine.driver, machine.connection);
  if (const YAML::Node power = root["frame_power"]) {
    // A marking power to see the frame by (a diode's dot), never one that cuts.
    if (machine.driver != "grbl") {
      reader.fail(power, "frame_power",
                  machine.driver == "m2nano"
                      ? "the M2 Nano's power is set by the knob on the machine: it frames with the laser off"
                  : machine.driver == "ruida" ? "a Ruida controller frames with the laser off (a CO2 laser's "
                                                "lowest power already burns)"
                                              : "a print driver does not frame");
    }
    machine.framePower = reader.number(power, "frame_power", 0, kMostFramePower);
  }

  const YAML::Node colours = root["colours"];
  if (!colours.IsMap() || colours.size() == 0) reader.fail(colours, "colours", "expected a table of colours (fig. 65)");
  std::vector<std::string> colourKeys;
  for (const auto& entry : colours) colourKeys.push_back(entry.first.as<std::string>(""));
  reader.keys(colours, "colours", colourKeys, {});  // refuses a colour given twice
  for (const auto& entry : colours) {
    ColourSetting setting;
    setting.name = entry.first.as<std::string>("");
    const std::string at = "colours." + setting.name;
    const YAML::Node row = entry.second;
    reader.keys(row, at, {"rgb", "mode", "power", "min_power", "speed", "ppi", "passes", "z_axis"}, {"rgb"});
    setting.rgb = reader.rgb(row["rgb"], at + ".rgb");
    if (row["mode"]) setting.mode = laserMode(reader, row["mode"], at + ".mode");
    if (row["power"]) setting.power = reader.number(row["power"], at + ".power", 0.0, 100.0);
    if (row["min_power"]) {
      setting.minPower = reader.number(row["min_power"], at + ".min_power", 0.0, setting.power);
    }
    if (row["speed"]) setting.speed = reader.number(row["speed"], at + ".speed", 0.1, 100.0);
    if (row["ppi"]) setting.ppi = reader.integer(row["ppi"], at + ".ppi", 1, 10000);
    if (row["passes"]) setting.passes = reader.integer(row["passes"], at + ".passes", 1, 100);
    if (row["z_axis"]) setting.zAxis = reader.boolean(row["z_axis"], at + ".z_axis");
    for (const auto& earlier : machine.colours) {
      if (earlier.rgb == setting.rgb) {
        reader.fail(row["rgb"], at + ".rgb",
                    fmt::format("the same RGB as colours.{}: the cutter could not tell them apart", earlier.name));
      }
    }
    machine.colours.push_back(std::move(setting));
  }

  // Operation -> colour; the dissertation's defaults where not given.
  const std::map<Operation, std::string> defaults{
      {Operation::Cut, "blue"}, {Operation::Score, "red"}, {Operation::Etch, "yellow"}, {Operation::Outline, "green"}};
  const YAML::Node operations = root["operations"];
  if (operations) reader.keys(operations, "operations", {"cut", "score", "etch", "outline"}, {});
  auto hasColour = [&](const std::string& name) {
    return std::any_of(machine.colours.begin(), machine.colours.end(),
                       [&](const ColourSetting& c) { return c.name == name; });
  };
  for (Operation operation : kAllOperations) {
    const std::string key = "operations." + std::string(operationName(operation));
    const YAML::Node given = operations ? operations[std::string(operationName(operation))] : YAML::Node();
    const std::string colour = given ? reader.text(given, key) : defaults.at(operation);
    const YAML::Node at = given ? given : (operations ? operations : root);
    if (!hasColour(colour)) {
      std::vector<std::string> table;
      for (const ColourSetting& c : machine.colours) table.push_back(c.name);
      // (Not given: say the key that is missing, not a colour the user never wrote.)
      reader.fail(
          at, given ? key : "operations",
          given ? fmt::format("colour '{}' is not in the colour table ({})", colour, fmt::join(table, ", "))
                : fmt::format("{} is missing: give the colour of the table that {} ({}); its default, {}, is "
                              "not in the table",
                              operationName(operation), operationPurpose(operation), fmt::join(table, ", "), colour));
    }
    for (const auto& [other, otherColour] : machine.operationColour) {
      if (otherColour == colour) {
        reader.fail(at, key,
                    fmt::format("colour '{}' is already used by operations.{}: each operation needs its own colour",
                                colour, operationName(other)));
      }
    }
    machine.operationColour[operation] = colour;
  }
  return machine;
}

MaterialProfile loadMaterialProfile(const std::filesystem::path& file) {
  const ProfileReader reader(file);
  const YAML::Node root = reader.load();
  requireKind(reader, root, "material");
  reader.keys(
      root, "",
      {"kind", "name", "description", "thickness", "kerf", "fastener", "areal_density", "fastener_mass", "machines"},
      {"name", "thickness", "kerf"});
  MaterialProfile material;
  material.source = file;
  material.name = reader.text(root["name"], "name");
  if (root["description"]) material.description = reader.text(root["description"], "description");
  material.thickness = reader.length(root["thickness"], "thickness", 0.0, false, 2.0);
  material.units.thickness = writtenUnit(root["thickness"].Scalar());
  material.kerf = reader.length(root["kerf"], "kerf", 0.0, true, 0.25);
  if (material.kerf >= 0.25)
    reader.fail(root["kerf"], "kerf", "must be under 0.25in: a laser cut is a few thousandths wide");
  material.units.kerf = writtenUnit(root["kerf"].Scalar());
  if (root["fastener"]) {
    material.fastenerDiameter = reader.length(root["fastener"], "fastener", 0.0, false, 2.0);
    material.units.fastener = writtenUnit(root["fastener"].Scalar());
  }
  // Grams per square metre, as board and paper are sold (posterboard about
  // 350, 1/16 in chipboard about 1,000, 3 mm birch plywood about 2,000).
  if (root["areal_density"]) material.arealDensity = reader.number(root["areal_density"], "areal_density", 1.0, 1e5);
  if (root["fastener_mass"]) material.fastenerMass = reader.number(root["fastener_mass"], "fastener_mass", 0.0, 1e3);
  if (const YAML::Node machines = root["machines"]) {
    if (!machines.IsMap()) reader.fail(machines, "machines", "expected a map from machine name to settings");
    std::vector<std::string> names;
    for (const auto& entry : machines) names.push_back(entry.first.as<std::string>(""));
    reader.keys(machines, "machines", names, {});
    for (const auto& entry : machines) {
      const std::string machineName = entry.first.as<std::string>("");
      const std::string at = "machines." + machineName;
      reader.keys(entry.second, at, {"cut", "score", "etch", "outline"}, {});
      auto& overrides = material.machines[machineName];
      for (const auto& operationEntry : entry.second) {
        const std::string operation = operationEntry.first.as<std::string>("");
        const std::string key = at + "." + operation;
        const YAML::Node row = operationEntry.second;
        reader.keys(row, key, {"power", "min_power", "speed", "passes"}, {});
        PowerSpeed setting;
        if (row["power"]) setting.power = reader.number(row["power"], key + ".power", 0.0, 100.0);
        if (row["min_power"]) {
          setting.minPower = reader.number(row["min_power"], key + ".min_power", 0.0, setting.power.value_or(100.0));
        }
        if (row["speed"]) setting.speed = reader.number(row["speed"], key + ".speed", 0.1, 100.0);
        if (row["passes"]) setting.passes = reader.integer(row["passes"], key + ".passes", 1, 100);
        overrides[*operationNamed(operation)] = setting;
      }
    }
  }
  return material;
}

}  // namespace rotafab::profiles
