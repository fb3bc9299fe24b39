#pragma once
// Machine and material profiles (docs/CONTRACT.md, "Profiles"): what a cutter is (bed,
// driver, connection, the colour table of the dissertation's fig. 65 and which
// colour each operation is drawn in) and what a material needs (thickness,
// kerf, fastener hole, power and speed per machine). Lengths in inches.

#include <filesystem>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "profiles/Operation.h"

namespace rotafab::profiles {

struct Bed {
  double width = 32.0;  // inches
  double height = 18.0;
  double margin = 0.25;     // on every side; nothing is drawn nearer the edge
  std::string unit = "in";  // the unit the profile gives the width in: how it is shown
};

enum class LaserMode { Vector, Raster, RasterAndVector };

// One row of fig. 65: a colour and what the cutter does with lines drawn in it.
struct ColourSetting {
  std::string name;  // "blue"
  Rgb rgb;
  LaserMode mode = LaserMode::Vector;
  double power = 50.0;  // percent
  // Percent at the slowest, where the head slows into a corner (a Ruida
  // controller ramps between it and `power`); unset: `power` throughout.
  std::optional<double> minPower;
  double speed = 100.0;  // percent of the machine's maximum
  int ppi = 500;         // pulses per inch
  int passes = 1;
  bool zAxis = false;
};

// How the machine moves (YAML `motion`), for the cutting time `make`
// estimates; a driver that reads its controller's settings (GRBL's $110,
// $120, $11) uses those instead when it runs the job.
struct MachineMotion {
  double maxSpeed = 0;           // in/s, each axis's
  double acceleration = 0;       // in/s^2
  double junctionDeviation = 0;  // inches; 0: it stops at every corner (no look-ahead)
};

// The material of a job that names none.
inline constexpr std::string_view kDefaultMaterial = "posterboard";

struct MachineProfile {
  std::string name;
  std::string description;
  Bed bed;
  std::string driver;      // "spool", "grbl" or "m2nano"
  std::string connection;  // the default device URI (docs/CONTRACT.md, "Devices")
  std::vector<ColourSetting> colours;
  std::map<Operation, std::string> operationColour;  // every operation has one
  std::optional<MachineMotion> motion;
  // Sheet files that `make` writes for this machine besides EPS and SVG
  // (docs/CONTRACT.md, "make"), as its software wants them: "dxf"
  // (`formats: [dxf]`).
  std::vector<std::string> formats;
  // Percent of full power the head traces a sheet's box at, to be seen
  // (`frame_power`, GRBL only); 0, the default: with the laser off.
  double framePower = 0;
  std::filesystem::path source;

  // The colour table row that `operation` is drawn in.
  [[nodiscard]] const ColourSetting& settingFor(Operation operation) const;
};

// The most `frame_power` may be: a mark to see, never a cut.
inline constexpr double kMostFramePower = 5;

// How a frame at `framePower` percent lights the laser, for people: "laser
// off", "laser at 1% power".
std::string frameLight(double framePower);

struct PowerSpeed {
  std::optional<double> power;  // percent; unset: the machine's colour table
  std::optional<double> minPower;
  std::optional<double> speed;
  std::optional<int> passes;
};

struct MaterialProfile {
  std::string name;
  std::string description;
  double thickness = 0.0;  // inches
  double kerf = 0.0;       // width of the cut, inches
  double fastenerDiameter = 0.125;
  // For the structure's mass and centre of mass (will it stand?): grams per
  // square metre of the sheet (YAML `areal_density`), 0 when the profile does
  // not say; grams per fastener with its nut or clip (`fastener_mass`).
  double arealDensity = 0.0;
  double fastenerMass = 0.0;
  // The units the profile gives the thickness, kerf and fastener in: how they are shown.
  struct WrittenUnits {
    std::string thickness = "in", kerf = "in", fastener = "in";
  } units;
  std::map<std::string, std::map<Operation, PowerSpeed>> machines;  // machine name -> overrides
  std::filesystem::path source;
};

// What the laser does for one operation on one machine with one material:
// the machine's colour table row, with the material's overrides for that
// machine (`machines:` in the material profile).
struct OperationSettings {
  double power = 0;  // percent
  double speed = 0;  // percent of the machine's maximum
  int passes = 1;
  double minPower = 0;  // percent, at most `power` (ColourSetting::minPower)
  friend bool operator==(const OperationSettings&, const OperationSettings&) = default;
};
OperationSettings operationSettings(const MachineProfile& machine, const MaterialProfile& material,
                                    Operation operation);

// What changes when a job made for (`madeFor`, `madeWith`) is cut on
// (`cutOn`, `cutWith`), one phrase each, for people: "cut: 100% power at
// 100% speed, 2 passes instead of 100% at 25%, 4 passes", "material:
// posterboard (0.06 in) instead of plywood-3mm (0.118 in)". Empty when the
// machine and the material are the job's own and their settings are too.
std::vector<std::string> settingChanges(const MachineProfile& madeFor, const MaterialProfile& madeWith,
                                        const MachineProfile& cutOn, const MaterialProfile& cutWith);

// Thrown for an invalid profile: "FILE:LINE:COL: key: what is wrong".
class ProfileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Read and validate one profile file. A file holds one profile, `kind:
// machine` or `kind: material`. Throws ProfileError.
MachineProfile loadMachineProfile(const std::filesystem::path& file);
MaterialProfile loadMaterialProfile(const std::filesystem::path& file);

// The folders searched for profiles, first match wins: ./profiles (the project),
// $XDG_CONFIG_HOME/rotafab/profiles (else ~/.config/rotafab/profiles), then the
// system folder (/usr/share/rotafab/profiles, or this source tree's profiles/
// when it exists). Each holds machines/*.yaml and materials/*.yaml.
std::vector<std::filesystem::path> profileSearchPath();

struct ProfileCatalogue {
  std::vector<MachineProfile> machines;  // by name; an earlier folder shadows a later one
  std::vector<MaterialProfile> materials;
  std::vector<std::string> errors;  // one line per invalid file
};

ProfileCatalogue loadProfiles(const std::vector<std::filesystem::path>& searchPath);

// The named profile from the search path; ProfileError naming the ones there are.
MachineProfile findMachine(const ProfileCatalogue& catalogue, const std::string& name);
MaterialProfile findMaterial(const ProfileCatalogue& catalogue, const std::string& name);

// The first machine on the search path that the driver drives ("grbl", ...), or nothing.
std::optional<MachineProfile> firstMachineFor(const ProfileCatalogue& catalogue, std::string_view driver);

}  // namespace rotafab::profiles
