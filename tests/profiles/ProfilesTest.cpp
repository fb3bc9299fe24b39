// Machine and material profiles: the shipped ones load, lengths take units,
// and every invalid profile is refused with FILE:LINE:COL: key: what is wrong.

#include <gtest/gtest.h>

#include "profiles/Length.h"
#include "profiles/Profiles.h"
#include "support/ProfileSamples.h"
#include "support/TestSupport.h"

namespace rotafab::profiles {
namespace {

using test::kGoodMachine;
using test::replaced;

const std::filesystem::path kShipped = std::filesystem::path(ROTAFAB_SOURCE_DIR) / "profiles";

TEST(Length, UnitsAndBareInches) {
  EXPECT_DOUBLE_EQ(*parseLength("0.25in"), 0.25);
  EXPECT_DOUBLE_EQ(*parseLength("6.35mm"), 0.25);
  EXPECT_DOUBLE_EQ(*parseLength("0.635cm"), 0.25);
  EXPECT_DOUBLE_EQ(*parseLength("0.25"), 0.25);
  EXPECT_DOUBLE_EQ(*parseLength(" 3 mm "), 3 / 25.4);
  EXPECT_DOUBLE_EQ(*parseLength("-1in"), -1.0);
  EXPECT_DOUBLE_EQ(*parseLength("2ft"), 24.0);
  EXPECT_DOUBLE_EQ(*parseLength("1.27m"), 50.0);
  EXPECT_DOUBLE_EQ(*parseLength("0.5 m"), 0.5 / 0.0254);
  EXPECT_EQ(writtenUnit("2ft"), "ft");
  EXPECT_EQ(writtenUnit("3mm"), "mm");
  EXPECT_EQ(formatLength(24.0, "ft"), "2 ft");
  for (const char* bad : {"", "in", "m", "wide", "3furlongs", "3yd", "1e999in", "nan", "3 in in", "0x10", "3 mm m"}) {
    EXPECT_FALSE(parseLength(bad).has_value()) << bad;
  }
}

// WIDTHxHEIGHT: a unit at the end is both numbers' ("800x600mm" is not 800
// in by 600 mm), or each has its own; none is inches.
TEST(Length, SizesTakeOneUnitForBothOrOneEach) {
  const auto expectSize = [](const char* text, double width, double height) {
    const auto size = parseSize(text);
    ASSERT_TRUE(size.has_value()) << text;
    EXPECT_NEAR(size->first, width, 1e-12) << text;
    EXPECT_NEAR(size->second, height, 1e-12) << text;
  };
  expectSize("800x600mm", 800 / 25.4, 600 / 25.4);
  expectSize("800mmx600mm", 800 / 25.4, 600 / 25.4);
  expectSize("31.5x17.5", 31.5, 17.5);
  expectSize("32inx18in", 32, 18);
  expectSize("81.28cmx18in", 32, 18);
  expectSize("32x45.72cm", 32 / 2.54, 18);
  expectSize("2.5x1.5ft", 30, 18);
  for (const char* bad : {"", "32", "32x", "x18", "32x18x2", "32inx18", "32 by 18", "axb", "32x18yd"}) {
    EXPECT_FALSE(parseSize(bad).has_value()) << bad;
  }
}

TEST(Profiles, ShippedProfilesLoad) {
  const ProfileCatalogue catalogue = loadProfiles({kShipped});
  EXPECT_TRUE(catalogue.errors.empty()) << catalogue.errors.front();
  ASSERT_GE(catalogue.machines.size(), 3u);
  ASSERT_GE(catalogue.materials.size(), 3u);
  const MachineProfile workshop = findMachine(catalogue, "workshop-32x18");
  EXPECT_EQ(workshop.bed.width, 32.0);
  EXPECT_EQ(workshop.bed.height, 18.0);
  EXPECT_EQ(workshop.bed.margin, 0.25);
  // motion: 6000mm/min, 500mm/s2, 0.01mm, in inches and seconds.
  const auto grbl = findMachine(catalogue, "grbl-diode-400");
  ASSERT_TRUE(grbl.motion);
  EXPECT_DOUBLE_EQ(grbl.motion->maxSpeed, 100 / 25.4);
  EXPECT_DOUBLE_EQ(grbl.motion->acceleration, 500 / 25.4);
  EXPECT_DOUBLE_EQ(grbl.motion->junctionDeviation, 0.01 / 25.4);
  EXPECT_EQ(workshop.driver, "spool");
  EXPECT_EQ(workshop.colours.size(), 8u);  // fig. 65's eight rows
  // The dissertation's colours: cut blue, score red, etch yellow, outline green.
  EXPECT_EQ(workshop.settingFor(Operation::Cut).rgb, (Rgb{0, 0, 255}));
  EXPECT_EQ(workshop.settingFor(Operation::Score).rgb, (Rgb{255, 0, 0}));
  EXPECT_EQ(workshop.settingFor(Operation::Etch).rgb, (Rgb{255, 255, 0}));
  EXPECT_EQ(workshop.settingFor(Operation::Outline).rgb, (Rgb{0, 255, 0}));
  EXPECT_EQ(workshop.settingFor(Operation::Cut).power, 50.0);
  EXPECT_EQ(findMachine(catalogue, "grbl-diode-400").driver, "grbl");
  EXPECT_NEAR(findMachine(catalogue, "k40-m2nano").bed.width, 300 / 25.4, 1e-12);
  const MaterialProfile plywood = findMaterial(catalogue, "plywood-3mm");
  EXPECT_NEAR(plywood.kerf, 0.15 / 25.4, 1e-12);
  EXPECT_EQ(plywood.machines.at("grbl-diode-400").at(Operation::Cut).passes, 4);
  // Every shipped material weighs something: `make` says the structure's mass.
  for (const MaterialProfile& material : catalogue.materials) {
    EXPECT_GT(material.arealDensity, 0) << material.name;
    EXPECT_GT(material.fastenerMass, 0) << material.name;
  }
  EXPECT_EQ(plywood.arealDensity, 2000);
  EXPECT_THROW(findMachine(catalogue, "nope"), ProfileError);
}

TEST(Profiles, EarlierFolderShadowsLater) {
  test::TempDir dir;
  std::filesystem::create_directories(dir.path() / "machines");
  std::string text = test::readFile(kShipped / "machines/workshop-32x18.yaml");
  text.replace(text.find("margin: 0.25in"), 14, "margin: 0.5in");
  dir.write("machines/workshop.yaml", text);
  const ProfileCatalogue catalogue = loadProfiles({dir.path(), kShipped});
  EXPECT_EQ(findMachine(catalogue, "workshop-32x18").bed.margin, 0.5);
}

// Loads `text` as a machine (or material) profile file and returns the error.
std::string refusal(const std::string& text, bool material = false) {
  test::TempDir dir;
  const auto file = dir.write("p.yaml", text);
  try {
    if (material) {
      loadMaterialProfile(file);
    } else {
      loadMachineProfile(file);
    }
  } catch (const ProfileError& error) {
    std::string message = error.what();
    const std::string prefix = file.string();
    return message.starts_with(prefix) ? "p.yaml" + message.substr(prefix.size()) : message;
  }
  return "(accepted)";
}

TEST(Profiles, GoodMachineLoads) { EXPECT_EQ(refusal(kGoodMachine), "(accepted)"); }

TEST(Profiles, EveryInvalidMachineIsRefusedWithItsPlace) {
  const std::string good = kGoodMachine;
  struct Case {
    const char* what;
    std::string text;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"unknown key", replaced(good, "driver: spool", "drivr: spool"),
       "p.yaml:4:1: drivr: unknown key (expected one of: kind, name, description, bed, driver, connection, colours, "
       "operations, motion, formats, frame_power)"},
      // A frame to see by: a few percent on a GRBL machine, never a cut; a spool and the M2 Nano have none.
      {"frame power of a print driver", replaced(good, "driver: spool\n", "driver: spool\nframe_power: 1\n"),
       "p.yaml:5:14: frame_power: a print driver does not frame"},
      {"frame power that could cut",
       replaced(good, "driver: spool\nconnection: spool:out\n",
                "driver: grbl\nconnection: grbl:///dev/ttyUSB0\nframe_power: 20\n"),
       "p.yaml:6:14: frame_power: must be between 0 and 5, not 20"},
      {"frame power of the M2 Nano",
       replaced(good, "driver: spool\nconnection: spool:out\n",
                "driver: m2nano\nconnection: m2nano://usb/1a86:5512\nframe_power: 1\n"),
       "p.yaml:6:14: frame_power: the M2 Nano's power is set by the knob on the machine: it frames with the laser "
       "off"},
      {"unknown sheet format", replaced(good, "driver: spool", "formats: [dxf, pdf]\ndriver: spool"),
       "p.yaml:4:16: formats[1]: expected eps, svg or dxf, found 'pdf'"},
      {"formats not a list", replaced(good, "driver: spool", "formats: dxf\ndriver: spool"),
       "p.yaml:4:10: formats: expected a list of sheet formats, e.g. [dxf]"},
      {"wrong type", replaced(good, "width: 32in", "width: wide"),
       "p.yaml:3:14: bed.width: expected a length such as 0.25in, 6.35mm or 0.635cm, found 'wide'"},
      {"negative power", replaced(good, "power: 50", "power: -5"),
       "p.yaml:7:35: colours.blue.power: must be between 0 and 100, not -5"},
      {"power not a number", replaced(good, "power: 50", "power: lots"),
       "p.yaml:7:35: colours.blue.power: expected a number, found 'lots'"},
      {"bed smaller than margins", replaced(good, "margin: 0.25in", "margin: 9in"),
       "p.yaml:3:6: bed: margins of 9in on every side leave no usable area on a 32 x 18 in bed"},
      {"colour used twice", replaced(good, "score: red", "score: blue"),
       "p.yaml:11:32: operations.score: colour 'blue' is already used by operations.cut: each operation needs its own "
       "colour"},
      {"same rgb twice", replaced(good, "rgb: [255, 0, 0]", "rgb: [0, 0, 255]"),
       "p.yaml:8:14: colours.red.rgb: the same RGB as colours.blue: the cutter could not tell them apart"},
      {"colour defined twice", replaced(good, "  red: {rgb: [255, 0, 0]}", "  blue: {rgb: [255, 0, 0]}"),
       "p.yaml:8:3: colours.blue: given twice"},
      {"unknown colour", replaced(good, "etch: yellow", "etch: purple"),
       "p.yaml:11:43: operations.etch: colour 'purple' is not in the colour table (blue, red, yellow, green)"},
      // Not given: the key that is missing, not a colour the user never wrote.
      {"operation left out", replaced(replaced(good, ", outline: green", ""), "  green: {rgb: [0, 255, 0]}\n", ""),
       "p.yaml:10:13: operations: outline is missing: give the colour of the table that draws the material's edge "
       "(never burnt) (blue, red, yellow); its default, green, is not in the table"},
      {"a bed in millimetres without the unit", replaced(good, "width: 32in, height: 18in", "width: 400, height: 430"),
       "p.yaml:3:14: bed.width: 400 without a unit, which would be 400 inches; write 400mm or 400in"},
      {"rgb out of range", replaced(good, "rgb: [255, 0, 0]", "rgb: [256, 0, 0]"),
       "p.yaml:8:15: colours.red.rgb[0]: must be between 0 and 255, not 256"},
      {"missing bed", replaced(good, "bed: {width: 32in, height: 18in, margin: 0.25in}\n", ""),
       "p.yaml:1:1: bed: missing"},
      {"wrong kind", replaced(good, "kind: machine", "kind: material"),
       "p.yaml:1:7: kind: expected 'machine', found 'material'"},
      {"unknown driver", replaced(good, "driver: spool", "driver: lasersaur"),
       "p.yaml:4:9: driver: expected spool, grbl, m2nano or ruida, found 'lasersaur'"},
      {"connection for another driver", replaced(good, "connection: spool:out", "connection: grbl:///dev/ttyUSB0"),
       "p.yaml:5:13: connection: 'grbl:///dev/ttyUSB0' is not a spool device URI (expected spool:)"},
      {"speed without a unit",
       replaced(good, "driver: spool\n", "driver: spool\nmotion: {speed: 100/s, acceleration: 5in/s2}\n"),
       "p.yaml:5:17: motion.speed: expected a speed such as 100mm/s, 6000mm/min or 4in/s, found '100/s'"},
      {"acceleration as a speed",
       replaced(good, "driver: spool\n", "driver: spool\nmotion: {speed: 4in/s, acceleration: 5in/s}\n"),
       "p.yaml:5:38: motion.acceleration: expected an acceleration such as 500mm/s2 or 20in/s2, found '5in/s'"},
      {"syntax error", replaced(good, "colours:\n", "colours: [\n"), ""},
      {"not a map", "- just\n- a list\n", "p.yaml:1:1: profile: expected a map of keys (kind, name, ...)"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.what);
    const std::string message = refusal(c.text);
    if (c.message.empty()) {
      EXPECT_TRUE(message.starts_with("p.yaml:") && message.find(": syntax: ") != std::string::npos) << message;
    } else {
      EXPECT_EQ(message, c.message);
    }
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
}

TEST(Profiles, EveryInvalidMaterialIsRefusedWithItsPlace) {
  const std::string good =
      "kind: material\n"
      "name: card\n"
      "thickness: 1.5mm\n"
      "kerf: 0.1mm\n"
      "machines:\n"
      "  workshop-32x18: {cut: {power: 60, speed: 40}}\n";
  EXPECT_EQ(refusal(good, true), "(accepted)");
  EXPECT_EQ(refusal(replaced(good, "kerf: 0.1mm", "kerf: -0.1mm"), true),
            "p.yaml:4:7: kerf: must be at least 0in, not -0.1mm");
  EXPECT_EQ(refusal(replaced(good, "thickness: 1.5mm", "thickness: 0"), true),
            "p.yaml:3:12: thickness: must be more than 0in, not 0");
  EXPECT_EQ(refusal(replaced(good, "thickness: 1.5mm", "thickness: 3"), true),
            "p.yaml:3:12: thickness: 3 without a unit, which would be 3 inches; write 3mm or 3in");
  EXPECT_EQ(refusal(replaced(good, "thickness: 1.5mm", "thickness: 0.125"), true), "(accepted)")
      << "a bare number of inches that reads as one";
  EXPECT_EQ(refusal(replaced(good, "{cut: {power", "{slice: {power"), true),
            "p.yaml:6:20: machines.workshop-32x18.slice: unknown key (expected one of: cut, score, etch, outline)");
  EXPECT_EQ(refusal(replaced(good, "speed: 40", "speed: 0"), true),
            "p.yaml:6:44: machines.workshop-32x18.cut.speed: must be between 0.1 and 100, not 0");
  EXPECT_EQ(refusal(replaced(good, "kerf: 0.1mm\n", ""), true), "p.yaml:1:1: kerf: missing");
  EXPECT_EQ(refusal(replaced(good, "kerf: 0.1mm\n", "kerf: 0.1mm\nareal_density: 300\nfastener_mass: 0.5\n"), true),
            "(accepted)");
  EXPECT_EQ(refusal(replaced(good, "kerf: 0.1mm\n", "kerf: 0.1mm\nareal_density: 0\n"), true),
            "p.yaml:5:16: areal_density: must be between 1 and 100000, not 0");
  EXPECT_EQ(refusal(replaced(good, "kerf: 0.1mm\n", "kerf: 0.1mm\nfastener_mass: heavy\n"), true),
            "p.yaml:5:16: fastener_mass: expected a number, found 'heavy'");
}

}  // namespace
}  // namespace rotafab::profiles
