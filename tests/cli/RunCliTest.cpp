// `rotafab run` through the built program against the simulated GRBL: a
// `make` output cut to the end with progress, the dry run's G-code, Ctrl-C
// stopping safely, and one-line errors with the contract's exit statuses (docs/CONTRACT.md).

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "cli/CliSupport.h"
#include "support/TestSupport.h"

namespace rotafab::test {
namespace {

// The cube's bands made once for each set of `make` options, shared by the tests.
std::filesystem::path madeCube(const std::string& options) {
  static TempDir dir;
  static std::map<std::string, std::filesystem::path> made;
  const auto [it, fresh] = made.try_emplace(options, dir.path() / ("cube-" + std::to_string(made.size())));
  if (fresh) {
    const CommandResult r = run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                                " --structure band --time 0 " + options + " --out " + quoted(it->second));
    EXPECT_EQ(r.status, 0) << r.err;
  }
  return it->second;
}
// For the GRBL machine's bed, and for the K40's (M2 Nano).
std::filesystem::path cubeJob() { return madeCube("--machine grbl-diode-400"); }
std::filesystem::path k40Job() { return madeCube("--machine k40-m2nano --size 4in"); }
// And for a CO2 laser on a Ruida controller.
std::filesystem::path ruidaJob() { return madeCube("--machine ruida-co2-60w --material plywood-3mm --size 150mm"); }

TEST(RunCli, CutsAMakeOutputOnTheSimulatedGrblToTheEnd) {
  const CommandResult r = run(kCli + " run " + quoted(cubeJob()) + " --device 'sim:grbl?speed=200'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("Grbl 1.1h ['$' for help] (receive buffer 128 bytes, laser mode on)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("] 100%  stroke 108 of 108"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("1 sheet cut on sim:grbl?speed=200: 108 strokes"), std::string::npos) << r.out;
  // The sheet's kit, as the operator loads it: what the builders can do once it is cut.
  EXPECT_NE(r.err.find("(its kit: steps 1-6; once cut, steps 1-6 can be done)"), std::string::npos) << r.err;
  // The estimate and the bar count the simulator's time, 200 times the machine's: seconds, not minutes.
  std::smatch about;
  ASSERT_TRUE(std::regex_search(r.err, about, std::regex(R"(about (\d+)s \((\d+)m (\d+)s on the machine simulated\))")))
      << r.err;
  const double machine = std::stoi(about[2]) * 60 + std::stoi(about[3]);
  EXPECT_NEAR(std::stoi(about[1]), machine / 200, 1.0);
  // make's cutting time for the profile's machine is the time the run estimates on the controller.
  const auto manifest = nlohmann::json::parse(readFile(cubeJob() / "manifest.json"));
  EXPECT_NEAR(manifest.at("cost").at("sheet_cutting_seconds").at(0).get<double>(), machine, 1.0);
  const std::regex timeLeft(R"(, (\S+) left)");
  for (std::sregex_iterator left(r.err.begin(), r.err.end(), timeLeft), end; left != end; ++left) {
    EXPECT_TRUE(std::regex_match((*left)[1].str(), std::regex(R"(\d+s)"))) << (*left)[1];
    EXPECT_LE(std::stoi((*left)[1]), std::stoi(about[1]));
  }
}

// The controller's faults as the operator meets them, on the simulated GRBL
// told to have them: a stall (Run, standing still) and a run of garbage stop
// the job with the laser confirmed off (exit 3, where the job stopped); line
// noise once (a garbled report and line) is skipped and the job ends.
TEST(RunCli, FaultsOfTheControllerAsTheOperatorMeetsThem) {
  struct Case {
    const char* fault;
    int status;
    const char* says;
  };
  for (const Case& c : {Case{"stall", 3, "the machine stopped moving: it says Run"},
                        Case{"garbage", 3, "3 lines in a row that are no GRBL reply"}, Case{"noise", 0, ""}}) {
    SCOPED_TRACE(c.fault);
    const CommandResult r =
        run(kCli + " run " + quoted(cubeJob()) + " --device 'sim:grbl?speed=50&fault=" + c.fault + "&after=30'");
    EXPECT_EQ(r.status, c.status) << r.err;
    if (c.status == 0) {
      EXPECT_NE(r.out.find("1 sheet cut on sim:grbl"), std::string::npos) << r.out;
      continue;
    }
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("the controller confirmed the laser off"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("stopped at sheet 1, with "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("once it is fixed, go on with --sheet 1"), std::string::npos) << r.err;
  }
  const CommandResult typo = run(kCli + " run " + quoted(cubeJob()) + " --device 'sim:grbl?fault=fire'");
  EXPECT_EQ(typo.status, 1);
  EXPECT_NE(typo.err.find("fault=KIND (stall, noise, garbage, alarm, silence or unplug)"), std::string::npos)
      << typo.err;
}

// A job carries its machine and material to the cutter: run cuts it with
// the power, speed and passes it was made for, on the machine profile's
// connection when no --device is given; another material or machine says
// what changes and, with no terminal to ask, needs --force.
TEST(RunCli, AJobIsCutWithTheMachineAndMaterialItWasMadeFor) {
  const auto job = madeCube("--machine grbl-diode-400 --material plywood-3mm");
  const auto manifest = nlohmann::json::parse(readFile(job / "manifest.json"));
  EXPECT_EQ(manifest.at("machine"), "grbl-diode-400");
  EXPECT_EQ(manifest.at("material"), "plywood-3mm");
  TempDir dir;
  const auto dryRun = [&](const std::string& options, const std::string& file) {
    return run(kCli + " run " + quoted(job) + " --sheet 1 " + options + " --dry-run --out " +
               quoted(dir.path() / file));
  };
  const CommandResult own = dryRun("--device sim:grbl", "own.gcode");
  ASSERT_EQ(own.status, 0) << own.err;
  const CommandResult named = dryRun("--device sim:grbl --material plywood-3mm", "named.gcode");
  ASSERT_EQ(named.status, 0) << named.err;
  EXPECT_EQ(named.err.find("instead of"), std::string::npos) << "the job's own material changes nothing";
  EXPECT_EQ(readFile(dir.path() / "own.gcode"), readFile(dir.path() / "named.gcode"));
  // Plywood's settings: 4 passes of each cut (posterboard's: 2).
  EXPECT_NE(own.out.find("(168 strokes)"), std::string::npos) << own.out;

  const CommandResult other = dryRun("--device sim:grbl --material posterboard", "other.gcode");
  EXPECT_EQ(other.status, 1);
  EXPECT_NE(other.err.find("was made for grbl-diode-400 with plywood-3mm; cutting it on grbl-diode-400 with "
                           "posterboard changes material: posterboard (0.8 mm) instead of plywood-3mm (3 mm); cut: "),
            std::string::npos)
      << other.err;
  EXPECT_NE(other.err.find("add --force"), std::string::npos) << other.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "other.gcode"));
  const CommandResult forced = dryRun("--device sim:grbl --material posterboard --force", "forced.gcode");
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_NE(forced.err.find("cut with --force: material: posterboard"), std::string::npos) << forced.err;
  EXPECT_NE(forced.out.find("(108 strokes)"), std::string::npos) << forced.out;

  // Cut, it says what to load: the material, its thickness and the sheet's size.
  const CommandResult cut = run(kCli + " run " + quoted(job) + " --sheet 1 --device 'sim:grbl?speed=2000'");
  ASSERT_EQ(cut.status, 0) << cut.err;
  EXPECT_NE(cut.err.find("run: sheet 1 (1 of 1), plywood-3mm (3 mm), 400 x 400 mm: 168 strokes"), std::string::npos)
      << cut.err;
  // In the job's unit (the bed's, millimetres, as none was asked), or the one asked.
  EXPECT_NE(cut.err.find(" mm to burn, about "), std::string::npos) << cut.err;
  EXPECT_NE(cut.out.find(" mm burnt, in "), std::string::npos) << cut.out;
  const CommandResult inches =
      run(kCli + " run " + quoted(job) + " --sheet 1 --device 'sim:grbl?speed=2000' --units in");
  ASSERT_EQ(inches.status, 0) << inches.err;
  EXPECT_NE(inches.err.find("run: sheet 1 (1 of 1), plywood-3mm (0.118 in), 15.748 x 15.748 in: 168 strokes, "),
            std::string::npos)
      << inches.err;
  EXPECT_NE(inches.out.find(" in burnt, in "), std::string::npos) << inches.out;
  // No --device: the machine profile's connection (a dry run does not open it).
  const CommandResult profiled = dryRun("", "profiled.gcode");
  ASSERT_EQ(profiled.status, 0) << profiled.err;
  EXPECT_NE(profiled.out.find("G-code for 1 sheet (168 strokes)"), std::string::npos) << profiled.out;
  // A job made where a profile is that this computer lacks: named, and cut only with one asked for.
  TempDir elsewhere;
  std::filesystem::copy(job, elsewhere.path() / "job", std::filesystem::copy_options::recursive);
  const auto copied = elsewhere.path() / "job";
  std::string text = readFile(copied / "manifest.json");
  text.replace(text.find("\"grbl-diode-400\""), 16, "\"their-laser\"");
  { std::ofstream(copied / "manifest.json") << text; }
  const CommandResult unknown =
      run(kCli + " run " + quoted(copied) + " --sheet 1 --device sim:grbl --dry-run --out " + quoted(dir.path() / "u"));
  EXPECT_EQ(unknown.status, 1);
  EXPECT_NE(unknown.err.find("manifest.json: names the machine their-laser, which no profile here has"),
            std::string::npos)
      << unknown.err;
  const CommandResult asked = run(kCli + " run " + quoted(copied) +
                                  " --sheet 1 --device sim:grbl --machine grbl-diode-400 --force --dry-run --out " +
                                  quoted(dir.path() / "n.gcode"));
  EXPECT_EQ(asked.status, 0) << asked.err;
  EXPECT_NE(asked.err.find("machine: grbl-diode-400 instead of their-laser (no profile here)"), std::string::npos)
      << asked.err;
  // A device another driver drives: another machine, said and refused.
  const CommandResult onGrbl = run(kCli + " run " + quoted(k40Job()) + " --sheet 1 --device sim:grbl --dry-run --out " +
                                   quoted(dir.path() / "k40.gcode"));
  EXPECT_EQ(onGrbl.status, 1);
  EXPECT_NE(onGrbl.err.find("machine: grbl-diode-400 instead of k40-m2nano"), std::string::npos) << onGrbl.err;
}

// A dry run of a folder of several sheets writes every sheet, one file
// each (one file of several would be cut back to back, onto one sheet).
TEST(RunCli, ADryRunOfSeveralSheetsWritesOneFileEach) {
  TempDir dir;
  const auto job = dir.path() / "ball";
  const CommandResult made = run(kCli + " make " + quoted(kSource / "examples/soccer-ball.obj") +
                                 " --structure band --machine grbl-diode-400 --time 0 --out " + quoted(job));
  ASSERT_EQ(made.status, 0) << made.err;
  const size_t sheets = nlohmann::json::parse(readFile(job / "manifest.json")).at("sheets").size();
  ASSERT_GT(sheets, 1u);
  const CommandResult r =
      run(kCli + " run " + quoted(job) + " --device sim:grbl --dry-run --out " + quoted(dir.path() / "ball.gcode"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "ball.gcode"));
  for (size_t s = 1; s <= sheets; ++s) {
    const auto file = dir.path() / fmt::format("ball-sheet-{:03}.gcode", s);
    EXPECT_NE(r.out.find(file.string() + ": G-code for 1 sheet ("), std::string::npos) << r.out;
    const std::string gcode = readFile(file);
    EXPECT_TRUE(gcode.starts_with("G21\n")) << file;
    EXPECT_NE(gcode.find("\nM5 S0\n"), std::string::npos) << file << ": the laser off at its end";
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / fmt::format("ball-sheet-{:03}.gcode", sheets + 1)));
}

// A simulator runs fast unless asked for real time, and says the time the
// machine it stands for would take.
TEST(RunCli, TheSimulatorRunsFastByDefaultAndSaysTheMachinesTime) {
  const CommandResult r = run(kCli + " run " + quoted(k40Job()) + " --sheet 1 --device sim:m2nano");
  ASSERT_EQ(r.status, 0) << r.err;
  std::smatch said;
  ASSERT_TRUE(std::regex_search(r.err, said, std::regex(R"(about (\d+)s \((\d+)m (\d+)s on the machine simulated\))")))
      << r.err;
  const double machine = std::stoi(said[2].str()) * 60 + std::stoi(said[3].str());
  EXPECT_NEAR(machine / 50, std::stoi(said[1].str()), 1.0) << "50 times faster than the machine (seconds rounded)";
}

TEST(RunCli, DryRunWritesTheGCodeTheDriverSends) {
  TempDir dir;
  const auto file = dir.path() / "cube.gcode";
  const CommandResult r =
      run(kCli + " run " + quoted(cubeJob()) + " --device sim:grbl --dry-run --out " + quoted(file));
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream lines(readFile(file));
  std::vector<std::string> all;
  for (std::string line; std::getline(lines, line);) all.push_back(line);
  ASSERT_GT(all.size(), 10u);
  EXPECT_EQ(all[0], "G21");
  EXPECT_EQ(all[3], "M4 S0");
  EXPECT_EQ(all[all.size() - 2], "M5 S0");
  int rapids = 0;
  for (const auto& line : all) {
    rapids += line.starts_with("G0 ");
    EXPECT_LE(line.size(), 79u) << "GRBL takes at most 79 characters a line";
  }
  EXPECT_EQ(rapids, 108 + 1);  // one per stroke, and home
}

// The M2 Nano's dry run: an .egv file with the header K40 Whisperer and
// MeerK40t expect, and nothing but LHYMICRO-GL in its body.
TEST(RunCli, M2NanoDryRunWritesAnEgvFile) {
  TempDir dir;
  const auto egv = dir.path() / "cube.egv";
  const CommandResult r = run(kCli + " run " + quoted(k40Job()) + " --sheet 1 --device m2nano://usb/1a86:5512 " +
                              "--dry-run --out " + quoted(egv));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = readFile(egv);
  EXPECT_EQ(text.rfind("Document type : LHYMICRO-GL file\nFile version: 1.0.01\nCopyright: Unknown\n", 0), 0u);
  EXPECT_NE(text.find("\n\n%0%0%0%0%\nIPP\nI"), std::string::npos);
  EXPECT_TRUE(text.ends_with("FNSE\n"));
  const std::string body = text.substr(text.find("%0%0%0%0%\n") + 10);
  EXPECT_EQ(body.find_first_not_of("ABCDEFGILMNPRSTUVabcdefghijklmnopqrstuvwxyz|0123456789@\n"), std::string::npos);
}

// The simulated M2 Nano, plugged in through umockdev: the program starts
// again under umockdev's preload and drives it over libusb to the end.
TEST(RunCli, CutsAMakeOutputOnTheSimulatedM2NanoToTheEnd) {
  const CommandResult r = run(kCli + " run " + quoted(k40Job()) + " --sheet 1 --device 'sim:m2nano?speed=100'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("Lihuiyu M2 Nano on usb 001:004 (1a86:5512), CH341 version 48"), std::string::npos) << r.err;
  // "] 100%  stroke N of N": every stroke acknowledged.
  const auto at = r.err.find("] 100%  stroke ");
  ASSERT_NE(at, std::string::npos) << r.err;
  std::istringstream counts(r.err.substr(at + 15));
  size_t done = 0, of = 0;
  std::string word;
  counts >> done >> word >> of;
  EXPECT_EQ(word, "of");
  EXPECT_GT(done, 10u);
  EXPECT_EQ(done, of);
  EXPECT_NE(r.out.find("1 sheet cut on sim:m2nano?speed=100: " + std::to_string(done) + " strokes"), std::string::npos)
      << r.out;
}

// Ctrl-C mid-job: the driver stops the machine, and the operator is told
// where the job stopped and that the controller confirmed the laser off: no
// error, the status of a command its signal stopped (128 + SIGINT).
void interruptMidJob(const std::filesystem::path& job, const std::string& device) {
  // SIGINT once the job streams (after "run: sheet" on stderr).
  TempDir dir;
  const auto err = dir.path() / "err";
  const CommandResult r =
      run("(" + kCli + " run " + quoted(job) + " --sheet 1 --device " + device + " 2> " + quoted(err) +
          " & pid=$!; for i in $(seq 400); do grep -q 'run: sheet' " + quoted(err) +
          " && break; sleep 0.05; done; grep -q 'run: sheet' " + quoted(err) +
          " || { kill -KILL $pid; exit 99; }; sleep 2.5; kill -INT $pid; wait $pid; status=$?; cat " + quoted(err) +
          " >&2; exit $status)");
  EXPECT_EQ(r.status, 130) << device << ": " << r.err;
  std::smatch stopped;
  ASSERT_TRUE(std::regex_search(
      r.err, stopped,
      std::regex(R"(run: stopped at sheet 1, with (\d+) of its (\d+) strokes cut; the controller confirmed the laser )"
                 R"(off; to go on, (?:load sheet 1 and run it with --sheet 1|leave sheet 1 and run it with --sheet 1 )"
                 R"(--from-stroke (\d+) --frame)\n)")))
      << device << ": " << r.err;
  const int cut = std::stoi(stopped[1].str()), strokes = std::stoi(stopped[2].str());
  EXPECT_LT(cut, strokes) << "stopped mid-sheet";
  EXPECT_EQ(r.err.find("error:"), std::string::npos) << "Ctrl-C is the operator's choice: " << r.err;
  // (GRBL's position says which strokes are cut; the M2 Nano's queue is counted from what was sent.)
  if (device.find("grbl") != std::string::npos) {
    EXPECT_GT(cut, 0) << "2.5 s into the sheet: " << r.err;
  }
  if (cut == 0) return;
  // Gone on with as it says (framed, and --yes for no terminal): the strokes cut are not cut again.
  EXPECT_EQ(std::stoi(stopped[3].str()), cut + 1);
  const std::string fast = std::regex_replace(device, std::regex("speed=1"), "speed=200");
  const CommandResult rest = run(kCli + " run " + quoted(job) + " --sheet 1 --from-stroke " + stopped[3].str() +
                                 " --frame --yes --device " + fast + " < /dev/null");
  ASSERT_EQ(rest.status, 0) << rest.err;
  EXPECT_NE(rest.err.find("run: framing (laser off)"), std::string::npos) << rest.err;
  EXPECT_NE(rest.err.find(fmt::format("strokes {} to {} (the {} before were cut)", cut + 1, strokes, cut)),
            std::string::npos)
      << rest.err;
  EXPECT_NE(rest.out.find(fmt::format("{} strokes", strokes - cut)), std::string::npos) << rest.out;
}

// Framing waits for the operator: without a terminal to ask, --frame needs --yes.
TEST(RunCli, FramingWaitsForTheOperatorOrYes) {
  const CommandResult asked = run(kCli + " run " + quoted(cubeJob()) + " --device sim:grbl --frame < /dev/null");
  EXPECT_EQ(asked.status, 1) << asked.err;
  EXPECT_NE(asked.err.find("no terminal to ask: add --yes to cut once framed"), std::string::npos) << asked.err;
  const CommandResult yes =
      run(kCli + " run " + quoted(cubeJob()) + " --device 'sim:grbl?speed=200' --frame --yes < /dev/null");
  ASSERT_EQ(yes.status, 0) << yes.err;
  EXPECT_LT(yes.err.find("run: framing (laser off)"), yes.err.find("] 100%")) << yes.err;
  const CommandResult beyond =
      run(kCli + " run " + quoted(cubeJob()) + " --sheet 1 --from-stroke 500 --device sim:grbl");
  EXPECT_EQ(beyond.status, 1);
  EXPECT_NE(beyond.err.find("--from-stroke 500: sheet 1 has 108 strokes"), std::string::npos) << beyond.err;
}

TEST(RunCli, InterruptStopsTheJobWithTheLaserOff) {
  // (In real time: a fast simulator may have ended the sheet before the signal.)
  interruptMidJob(cubeJob(), "'sim:grbl?speed=1'");
  interruptMidJob(k40Job(), "'sim:m2nano?speed=1'");
  interruptMidJob(ruidaJob(), "'sim:ruida?speed=1'");
}

// A sheet cut on the simulated Ruida over loopback UDP, and its .rd file
// read by a decoder written from the public descriptions alone: the file
// holds exactly the cuts the controller made.
TEST(RunCli, CutsASheetOnTheSimulatedRuidaAsItsRdFileSays) {
  TempDir dir;
  const auto cuts = dir.path() / "cuts", rd = dir.path() / "sheet.rd";
  const CommandResult r =
      run(kCli + " run " + quoted(ruidaJob()) + " --sheet 1 --device 'sim:ruida?speed=500&cuts=" + cuts.string() + "'");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("Ruida controller (card 0x65106510, bed 700 x 500 mm) on ruida://127.0.0.1:"), std::string::npos)
      << r.err;
  EXPECT_NE(r.out.find("1 sheet cut on sim:ruida?speed=500&cuts="), std::string::npos) << r.out;
  // A dry run opens nothing: no controller answers at 192.0.2.1 (TEST-NET-1).
  const CommandResult dry =
      run(kCli + " run " + quoted(ruidaJob()) + " --sheet 1 --device ruida://192.0.2.1 --dry-run --out " + quoted(rd));
  ASSERT_EQ(dry.status, 0) << dry.err;
  EXPECT_NE(dry.out.find("as RDWorks saves it (.rd, magic 0x88)"), std::string::npos) << dry.out;
  const CommandResult decoded =
      run("/usr/bin/python3 " + quoted(kSource / "tests/support/ruida_decode.py") + " " + quoted(rd));
  ASSERT_EQ(decoded.status, 0) << decoded.err;
  std::istringstream fromFile(decoded.out), fromController(readFile(cuts));
  size_t count = 0;
  for (std::string a, b; std::getline(fromController, a);) {
    ASSERT_TRUE(std::getline(fromFile, b)) << "the controller cut more than the file holds";
    EXPECT_EQ(b.substr(0, a.size()), a) << "cut " << count;
    ++count;
  }
  EXPECT_GT(count, 100u);
  std::string more;
  EXPECT_FALSE(std::getline(fromFile, more)) << "the file holds more than was cut: " << more;
}

// A controller that stops answering mid-job (switched off): exit status 3
// within seconds, naming the controller, and saying the laser was not confirmed off.
TEST(RunCli, ARuidaThatStopsAnsweringEndsTheRunWithStatus3) {
  const auto job = ruidaJob();
  TempDir dir;
  const auto laser = dir.path() / "laser";
  const auto start = std::chrono::steady_clock::now();
  const CommandResult r =
      run(kCli + " run " + quoted(job) +
          " --sheet 1 --device 'sim:ruida?speed=50&fault=silence&after=24&witness=" + laser.string() + "'");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(15));
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("the controller stopped answering"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the controller did not confirm the laser off: switch it off at the machine"), std::string::npos)
      << r.err;
  // It had lit the laser, and switched off, the laser went off with it.
  const std::string changes = readFile(laser);
  EXPECT_NE(changes.find("on\n"), std::string::npos) << changes;
  EXPECT_TRUE(changes.ends_with("off\n")) << changes;
}

TEST(RunCli, ErrorsAreOneLineWithTheirStatus) {
  TempDir dir;
  // A sheet for the 32 x 18 in workshop bed does not go on a 400 mm GRBL bed.
  const CommandResult big = run(kCli + " make " + quoted(kSource / "examples/cube.obj") +
                                " --structure band --time 0 --out " + quoted(dir.path() / "big"));
  ASSERT_EQ(big.status, 0) << big.err;
  const auto fails = [&](const std::string& args, int status, const std::string& says) {
    const CommandResult r = run(kCli + " run " + args);
    EXPECT_EQ(r.status, status) << args << ": " << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    int errors = 0;
    std::istringstream lines(r.err);
    for (std::string line; std::getline(lines, line);) errors += line.starts_with("error: ");
    EXPECT_EQ(errors, 1) << args << ": " << r.err;
  };
  fails(quoted(dir.path() / "big") + " --device sim:grbl", 1, "larger than the bed of grbl-diode-400");
  fails(quoted(cubeJob()) + " --device grbl://ttyUSB0", 1, "must be an absolute path");
  fails(quoted(cubeJob()) + " --device sim:grbl?speed=fast", 1, "speed=N");
  fails(quoted(cubeJob()) + " --device sim:grbl --sheet 4", 1, "--sheet 4");
  fails(quoted(cubeJob()) + " --device sim:grbl --dry-run", 1, "--dry-run needs --out");
  fails(quoted(dir.path()) + " --device sim:grbl", 1, "no manifest.json");
  fails(quoted(cubeJob()) + " --device grbl:///dev/rotafab-no-such-port", 3, "cannot open it");
  fails(quoted(cubeJob()) + " --device grbl:///dev/rotafab-no-such-port", 3,
        "(disconnected; nothing that lights the laser was sent)");
  // --out without --dry-run would cut for real: refused as a usage error
  // before any device is opened (this one cannot be: that would be status 3).
  fails(quoted(cubeJob()) + " --device grbl:///dev/rotafab-no-such-port --out " + quoted(dir.path() / "x.gcode"), 2,
        "--out: needs --dry-run: without it, run cuts on the device and writes no file");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "x.gcode"));
  fails(quoted(cubeJob()) + " --device m2nano://usb/1a86:5512 --machine grbl-diode-400 --dry-run --out " +
            quoted(dir.path() / "x.egv"),
        1, "is driven by grbl");
  fails(quoted(k40Job()) + " --sheet 1 --device m2nano://usb/1a86:5512?bus=250", 3, "no such USB device");
  fails(quoted(k40Job()) + " --device m2nano://usb/1a86", 1, "m2nano://usb/VENDOR:PRODUCT");
  fails(quoted(k40Job()) + " --device 'm2nano://usb/1a86:5512?port=2'", 1, "bus=N and address=N");
}

}  // namespace
}  // namespace rotafab::test

namespace rotafab::test {
namespace {

// `rotafab devices` in a faked sysfs (umockdev): a GRBL board behind a CH340
// adapter (a serial port, found by libserialport) and a K40's M2 Nano (a CH341
// in parallel mode, no serial port: found by libusb).
TEST(DevicesCli, ListsTheCuttersOfAFakedSysfs) {
  const auto testbed = std::filesystem::path(ROTAFAB_SOURCE_DIR) / "tests/data/devices/cutters.umockdev";
  // (umockdev preloads its library ahead of the sanitizers' runtime: tell ASan that is fine)
  const std::string umockdev = "ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 umockdev-run --device " +
                               quoted(testbed) + " -- " + std::string(ROTAFAB_CLI);
  const CommandResult r = run(umockdev + " devices --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto list = nlohmann::json::parse(r.out);
  ASSERT_EQ(list.size(), 2u) << r.out;
  EXPECT_EQ(list[0].at("port"), "/dev/ttyUSB0");
  EXPECT_EQ(list[0].at("usb").at("vendor"), "1a86");
  EXPECT_EQ(list[0].at("usb").at("product"), "7523");
  EXPECT_EQ(list[0].at("usb").at("serial"), "GRBL-0042");
  EXPECT_EQ(list[0].at("driver"), "grbl");
  EXPECT_EQ(list[0].at("uri"), "grbl:///dev/ttyUSB0?baud=115200");
  EXPECT_EQ(list[1].at("port"), "usb:001:004");
  EXPECT_EQ(list[1].at("driver"), "m2nano");
  EXPECT_EQ(list[1].at("uri"), "m2nano://usb/1a86:5512");
  const CommandResult text = run(umockdev + " devices");
  EXPECT_NE(text.out.find("grbl driver: --device grbl:///dev/ttyUSB0?baud=115200"), std::string::npos) << text.out;
  EXPECT_EQ(text.out.find("sim:grbl"), std::string::npos) << "cutters were found: no simulator to suggest";
}

// Nothing plugged in (an empty sysfs): said so, with the simulator to try instead.
TEST(DevicesCli, NothingFoundSuggestsTheSimulator) {
  const CommandResult r = run("ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 umockdev-run -- " +
                              std::string(ROTAFAB_CLI) + " devices");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.out.starts_with("no serial port or cutter found (")) << r.out;
  EXPECT_NE(r.out.find("--device sim:grbl\n"), std::string::npos) << r.out;
  EXPECT_EQ(run("ASAN_OPTIONS=verify_asan_link_order=0:detect_leaks=0 umockdev-run -- " + std::string(ROTAFAB_CLI) +
                " devices --json")
                .out,
            "[]\n");
}

}  // namespace
}  // namespace rotafab::test

namespace rotafab::test {
namespace {

// The spool: each sheet as EPS in the folder, which Ghostscript reads, in
// the machine's colours; with a printer, handed to `lp` (here a stand-in
// that records its arguments), and lp's refusal is a device fault.
TEST(RunCli, TheSpoolWritesEpsAndHandsItToLp) {
  TempDir dir;
  const auto job = dir.path() / "job";
  const CommandResult made =
      run(kCli + " make " + quoted(kSource / "examples/cube.obj") + " --structure band --time 0 --out " + quoted(job));
  ASSERT_EQ(made.status, 0) << made.err;
  const auto spool = dir.path() / "spool";
  const CommandResult r =
      run(kCli + " run " + quoted(job) + " --device " + quoted(std::filesystem::path("spool:" + spool.string())));
  ASSERT_EQ(r.status, 0) << r.err;
  // The spool writes a sheet (and hands it to lp): a print driver cuts it later, not this run.
  EXPECT_NE(r.out.find("1 sheet written as EPS by spool:"), std::string::npos) << r.out;
  const CommandResult gs = run("gs -q -dNOPAUSE -dBATCH -sDEVICE=bbox " + quoted(spool / "sheet-001.eps"));
  ASSERT_EQ(gs.status, 0) << gs.err;
  const auto at = gs.err.find("%%BoundingBox: ");
  ASSERT_NE(at, std::string::npos) << gs.err;
  std::istringstream box(gs.err.substr(at + 15));
  int left = -1, bottom = -1, right = -1;
  box >> left >> bottom >> right;
  EXPECT_GE(right, 0) << gs.err;
  EXPECT_LE(right, 32 * 72 + 1);
  EXPECT_NE(readFile(spool / "sheet-001.eps").find("% cut\n0 0 1 c\n"), std::string::npos) << "cuts in blue";

  const auto bin = dir.path() / "bin";
  std::filesystem::create_directories(bin);
  dir.write("bin/lp", "#!/bin/sh\necho \"$@\" > " + quoted(dir.path() / "lp-args") + "\n[ \"$2\" = laser1 ]\n");
  std::filesystem::permissions(bin / "lp", std::filesystem::perms::owner_all);
  const std::string withLp = "PATH=" + quoted(bin) + ":$PATH ";
  const CommandResult printed = run(withLp + kCli + " run " + quoted(job) + " --device " +
                                    quoted(std::filesystem::path("spool:" + spool.string() + "?printer=laser1")));
  ASSERT_EQ(printed.status, 0) << printed.err;
  EXPECT_NE(printed.out.find("1 sheet sent to the printer by spool:"), std::string::npos) << printed.out;
  EXPECT_EQ(readFile(dir.path() / "lp-args"),
            "-d laser1 -t rotafab sheet 1 -- " + (spool / "sheet-001.eps").string() + "\n");
  const CommandResult refused = run(withLp + kCli + " run " + quoted(job) + " --device " +
                                    quoted(std::filesystem::path("spool:" + spool.string() + "?printer=nope")));
  EXPECT_EQ(refused.status, 3) << refused.err;
  EXPECT_NE(refused.err.find("lp -d nope refused"), std::string::npos) << refused.err;
  // A refused file never reached a laser, and the message says so, not to switch the laser off.
  EXPECT_NE(refused.err.find("stopped at sheet 1, before any of it was sent; nothing that lights the laser was sent)"),
            std::string::npos)
      << refused.err;
  // No lp at all: the same.
  const std::filesystem::path empty = dir.path() / "empty";
  std::filesystem::create_directories(empty);
  const CommandResult noLp = run("PATH=" + quoted(empty) + " " + kCli + " run " + quoted(job) + " --device " +
                                 quoted(std::filesystem::path("spool:" + spool.string() + "?printer=laser1")));
  EXPECT_EQ(noLp.status, 3) << noLp.err;
  EXPECT_NE(noLp.err.find("cannot run lp (install cups-client) (disconnected; stopped at sheet 1, before any "
                          "of it was sent; nothing that lights the laser was sent)"),
            std::string::npos)
      << noLp.err;
  EXPECT_EQ(noLp.err.find("switch it off"), std::string::npos) << noLp.err;
}

}  // namespace
}  // namespace rotafab::test
