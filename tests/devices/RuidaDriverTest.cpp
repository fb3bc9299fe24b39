// The Ruida driver against the simulated controller on loopback UDP: the
// real driver through the real transport, packets checked, acknowledged,
// lost and corrupted; a sheet cut as its toolpath says; and every fault,
// cancel and stop ending with the controller's laser off and no hang.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "devices/ruida/RuidaDiscovery.h"
#include "devices/ruida/RuidaDriver.h"
#include "devices/sim/RuidaSimulator.h"
#include "profiles/Profiles.h"
#include "support/TestSupport.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::devices {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// A sheet: an etched label, a scored fold, and two parts with a hole each.
jobs::Toolpath sheet() {
  jobs::SheetDrawing s;
  s.width = 700 / 25.4, s.height = 500 / 25.4, s.margin = 0.2;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  s.paths.push_back({jobs::Operation::Etch, {{1, 1}, {1.5, 1.2}, {2, 1}}, false});
  s.paths.push_back({jobs::Operation::Score, {{1, 3}, {4, 3}}, false});
  for (double x : {1.0, 16.0}) {
    s.paths.push_back({jobs::Operation::Cut, {{x + 1, 5}, {x + 2, 5}, {x + 2, 6}, {x + 1, 6}}, true});
    s.paths.push_back({jobs::Operation::Cut, {{x, 4}, {x + 4, 4}, {x + 4, 8}, {x, 8}}, true});
  }
  // Enough small parts for the job to take several packets.
  for (int i = 0; i < 120; ++i) {
    const double x = 1 + (i % 60) * 0.5, y = 10 + (i / 60) * 0.5;
    s.paths.push_back({jobs::Operation::Cut, {{x, y}, {x + 0.3, y}, {x + 0.3, y + 0.3}, {x, y + 0.3}}, true});
  }
  const auto machine =
      profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/ruida-co2-60w.yaml");
  return jobs::planToolpath(s, machine, profiles::MaterialProfile{}, jobs::profileMotion(machine));
}

ruida::RuidaTimeouts quick() {
  ruida::RuidaTimeouts t;
  // Long enough not to send a packet again on a loaded machine (under the sanitizers).
  t.reply = 1000ms;
  t.sends = 4;
  t.poll = 20ms;
  t.stop = 2000ms;
  return t;
}

// For a controller that will not answer: the time a test waits for its
// silence is short (nothing it cuts is compared).
ruida::RuidaTimeouts impatient() {
  ruida::RuidaTimeouts t = quick();
  t.reply = 300ms;
  t.stop = 1000ms;
  return t;
}

struct Rig {
  explicit Rig(sim::RuidaSimulatorOptions options, ruida::RuidaTimeouts timeouts = quick())
      : simulator(std::move(options)),
        driver(
            [port = simulator.port(), timeouts] {
              return ruida::udpChannel(DatagramLink::open("127.0.0.1", port, 0), ruida::kDefaultMagic, timeouts);
            },
            ruida::kDefaultMagic, {}, timeouts, 1) {}
  sim::RuidaSimulator simulator;
  ruida::RuidaDriver driver;
};

sim::RuidaSimulatorOptions fast() {
  sim::RuidaSimulatorOptions options;
  options.timeScale = 500;
  options.bedWidth = 700, options.bedHeight = 500;
  return options;
}

// The cuts the toolpath asks for, in the controller's millimetres (top-left origin, y down).
std::vector<std::array<double, 4>> wanted(const jobs::Toolpath& toolpath) {
  std::vector<std::array<double, 4>> cuts;
  for (const jobs::ToolpathStroke& stroke : toolpath.strokes) {
    for (size_t i = 1; i < stroke.points.size(); ++i) {
      const jobs::Point2 a = stroke.points[i - 1], b = stroke.points[i];
      cuts.push_back({a.x() * 25.4, (toolpath.height - a.y()) * 25.4, b.x() * 25.4, (toolpath.height - b.y()) * 25.4});
    }
  }
  return cuts;
}

void expectCutAsAsked(const sim::RuidaSimulator& simulator, const jobs::Toolpath& toolpath) {
  const auto want = wanted(toolpath);
  const auto got = simulator.cuts();
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) {
    EXPECT_NEAR(got[i].x0, want[i][0], 0.001) << i;
    EXPECT_NEAR(got[i].y0, want[i][1], 0.001) << i;
    EXPECT_NEAR(got[i].x1, want[i][2], 0.001) << i;
    EXPECT_NEAR(got[i].y1, want[i][3], 0.001) << i;
  }
  EXPECT_TRUE(simulator.errors().empty()) << simulator.errors().front();
}

TEST(Ruida, ASheetIsCutOverLoopbackUdpAsItsToolpathSays) {
  Rig rig(fast());
  const std::string identity = rig.driver.connect();
  EXPECT_NE(identity.find("Ruida controller (card 0x65106510, bed 700 x 500 mm) on ruida://127.0.0.1:"),
            std::string::npos)
      << identity;
  const jobs::Toolpath toolpath = sheet();
  Progress last;
  rig.driver.run(
      toolpath, [&](const Progress& p) { last = p; }, core::Cancellation());
  EXPECT_EQ(last.strokesCut, toolpath.strokes.size());
  EXPECT_EQ(last.bytesAcknowledged, last.bytesTotal);
  expectCutAsAsked(rig.simulator, toolpath);
  // Each cut at its stroke's power.
  EXPECT_NEAR(rig.simulator.cuts().back().power, toolpath.strokes.back().power, 0.001);
  EXPECT_FALSE(rig.simulator.laserOn());
  EXPECT_FALSE(rig.simulator.jobRuns());
  EXPECT_EQ(rig.driver.resends(), 0u);
  EXPECT_EQ(rig.driver.status().state, "Idle");
}

TEST(Ruida, ALostPacketIsSentAgain) {
  auto options = fast();
  options.fault = sim::RuidaFault::Drop;
  options.after = 7;  // the job's first packet: after the connection's three reads, the status and the head's x and y
  Rig rig(options);
  const jobs::Toolpath toolpath = sheet();
  rig.driver.run(toolpath, {}, core::Cancellation());
  EXPECT_GE(rig.driver.resends(), 1u);
  expectCutAsAsked(rig.simulator, toolpath);
}

TEST(Ruida, APacketWhoseChecksumFailsIsRefusedAndSentAgain) {
  auto options = fast();
  options.fault = sim::RuidaFault::Corrupt;
  options.after = 8;  // the job's second packet
  Rig rig(options);
  const jobs::Toolpath toolpath = sheet();
  rig.driver.run(toolpath, {}, core::Cancellation());
  EXPECT_EQ(rig.simulator.naks(), 1u);
  EXPECT_GE(rig.driver.resends(), 1u);
  expectCutAsAsked(rig.simulator, toolpath);
}

// Switched off mid-job: a Timeout naming the controller and the packet,
// in seconds; the driver cannot confirm the laser off, and says so.
TEST(Ruida, AControllerThatStopsAnsweringIsATimeoutNotAHang) {
  auto options = fast();
  options.timeScale = 1;
  options.fault = sim::RuidaFault::Silence;
  options.after = 9;  // the job's third packet
  Rig rig(options, impatient());
  const auto start = Clock::now();
  try {
    rig.driver.run(sheet(), {}, core::Cancellation());
    FAIL() << "no fault";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Timeout);
    EXPECT_FALSE(fault.laserOffConfirmed);
    EXPECT_NE(std::string(fault.what()).find("stopped answering"), std::string::npos) << fault.what();
    EXPECT_NE(std::string(fault.what()).find("ruida://127.0.0.1:"), std::string::npos) << fault.what();
  }
  EXPECT_LT(Clock::now() - start, 15s);
  EXPECT_FALSE(rig.simulator.laserOn());
}

// A cancel while the laser cuts: the controller's stop, confirmed; nothing more is cut.
TEST(Ruida, ACancelStopsTheJobWithTheLaserOff) {
  auto options = fast();
  options.timeScale = 2;
  Rig rig(options);
  core::Cancellation cancel;
  std::thread canceller([&] {
    const auto until = Clock::now() + 10s;
    while (!rig.simulator.laserOn() && Clock::now() < until) std::this_thread::sleep_for(1ms);
    cancel.cancel();
  });
  const jobs::Toolpath toolpath = sheet();
  try {
    rig.driver.run(toolpath, {}, cancel);
    FAIL() << "no fault";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Cancelled);
    EXPECT_TRUE(fault.laserOffConfirmed);
  }
  canceller.join();
  EXPECT_EQ(rig.simulator.stops(), 1u);
  EXPECT_FALSE(rig.simulator.laserOn());
  EXPECT_FALSE(rig.simulator.jobRuns());
  const size_t cut = rig.simulator.cuts().size();
  EXPECT_LT(cut, wanted(toolpath).size());
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(rig.simulator.cuts().size(), cut);
}

TEST(Ruida, APauseHoldsWithTheLaserOffAndAResumeFinishesTheSheet) {
  auto options = fast();
  options.timeScale = 100;
  Rig rig(options);
  const jobs::Toolpath toolpath = sheet();
  std::atomic<bool> heldDark{false};
  std::thread operatorAtTheMachine([&] {
    const auto until = Clock::now() + 10s;
    while (!rig.simulator.laserOn() && Clock::now() < until) std::this_thread::sleep_for(1ms);
    rig.driver.pause();
    std::this_thread::sleep_for(300ms);
    const size_t cut = rig.simulator.cuts().size();
    std::this_thread::sleep_for(200ms);
    heldDark = !rig.simulator.laserOn() && rig.simulator.jobRuns() && rig.simulator.cuts().size() == cut;
    rig.driver.resume();
  });
  rig.driver.run(toolpath, {}, core::Cancellation());
  operatorAtTheMachine.join();
  EXPECT_TRUE(heldDark);
  EXPECT_EQ(rig.simulator.pauses(), 1u);
  expectCutAsAsked(rig.simulator, toolpath);
}

// A controller whose status never says a job runs: the sheet is done once
// the head has moved and come to rest, not before (nothing cut twice, no
// sheet loaded onto one still being cut).
TEST(Ruida, AControllerThatNeverSaysAJobRunsIsFollowedByItsHead) {
  auto options = fast();
  options.reportsJobs = false;
  Rig rig(options);
  const jobs::Toolpath toolpath = sheet();
  rig.driver.run(toolpath, {}, core::Cancellation());
  expectCutAsAsked(rig.simulator, toolpath);  // all of it, by the time run() returned
  rig.driver.frame(toolpath, core::Cancellation());
  rig.driver.frame(toolpath, core::Cancellation());  // from where the last one ended
  EXPECT_EQ(rig.simulator.cuts().size(), wanted(toolpath).size());
}

TEST(Ruida, TheFrameTracesTheBoxWithoutLightingTheLaser) {
  auto options = fast();
  std::atomic<int> lit{0};
  options.laserChanged = [&](bool on) { lit += on; };
  Rig rig(options);
  const jobs::Toolpath toolpath = sheet();
  rig.driver.frame(toolpath, core::Cancellation());
  EXPECT_EQ(lit, 0);
  EXPECT_TRUE(rig.simulator.cuts().empty());
  EXPECT_TRUE(rig.simulator.errors().empty());
  // Back at the box's first corner, the sheet's lowest x and highest y.
  const auto box = jobs::toolpathBounds(toolpath);
  const DeviceStatus at = rig.driver.status();
  EXPECT_NEAR(at.x, box[0], 0.001);
  EXPECT_NEAR(at.y, box[3], 0.001);
}

// A 634XG scrambles with 0x11: a driver left at 0x88 reads none of its
// answers, and says which magic number they are in.
TEST(Ruida, AControllerOfAnotherMagicNumberIsNamedWithIt) {
  auto options = fast();
  options.magic = 0x11;
  Rig rig(options, impatient());
  try {
    rig.driver.connect();
    FAIL() << "connected";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Refused);
    EXPECT_NE(std::string(fault.what()).find("add ?magic=0x11 to its URI"), std::string::npos) << fault.what();
  }
}

TEST(Ruida, AStopIsConfirmedOnlyByAControllerThatAnswers) {
  Rig rig(fast());
  rig.driver.connect();
  EXPECT_TRUE(rig.driver.stopSafely());
  EXPECT_EQ(rig.simulator.stops(), 1u);
  auto options = fast();
  options.fault = sim::RuidaFault::Silence;
  options.after = 4;
  Rig silent(options, impatient());
  silent.driver.connect();
  const auto start = Clock::now();
  EXPECT_FALSE(silent.driver.stopSafely());
  EXPECT_LT(Clock::now() - start, 5s);
}

// The .rd file of a dry run, read by a decoder written from the public
// descriptions alone (tests/support/ruida_decode.py, none of the driver's
// code): every cut of the toolpath, in order, at its power.
TEST(Ruida, AnIndependentReadingOfTheRdFileCutsTheToolpath) {
  const jobs::Toolpath toolpath = sheet();
  ruida::RuidaDriver driver([]() -> std::unique_ptr<ruida::RuidaChannel> { throw std::logic_error("no controller"); },
                            ruida::kDefaultMagic, {});
  test::TempDir dir;
  const auto file = dir.path() / "sheet.rd";
  std::ofstream(file, std::ios::binary) << driver.program({toolpath});
  const test::CommandResult decoded = test::run(
      "/usr/bin/python3 " + test::quoted(std::filesystem::path(ROTAFAB_SOURCE_DIR) / "tests/support/ruida_decode.py") +
      " " + test::quoted(file));
  ASSERT_EQ(decoded.status, 0) << decoded.err;
  std::istringstream lines(decoded.out);
  std::vector<std::array<double, 5>> cuts;
  for (std::array<double, 5> cut{}; lines >> cut[0] >> cut[1] >> cut[2] >> cut[3] >> cut[4];) cuts.push_back(cut);
  const auto want = wanted(toolpath);
  ASSERT_EQ(cuts.size(), want.size());
  size_t stroke = 0, within = 0;
  for (size_t i = 0; i < want.size(); ++i) {
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(cuts[i][k], want[i][k], 0.001) << i;
    EXPECT_NEAR(cuts[i][4], 100 * toolpath.strokes[stroke].power, 0.01) << i;
    if (++within == toolpath.strokes[stroke].points.size() - 1) ++stroke, within = 0;
  }
}

// The controller's USB port, a serial device (here a pseudo-terminal): the
// same swizzled stream, without checksums or answers to each packet; a
// memory read's reply found among bytes from before it.
TEST(Ruida, OverItsUsbPortTheStreamGoesSwizzledWithoutChecksums) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);  // the test never hangs on it
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const std::string port = ::ptsname(master);
  const int slave = ::open(port.c_str(), O_RDWR | O_NOCTTY);  // held open, and raw
  termios raw{};
  ::tcgetattr(slave, &raw);
  ::cfmakeraw(&raw);
  ::tcsetattr(slave, TCSANOW, &raw);
  const ruida::Swizzle swizzle;
  auto channel = ruida::serialChannel(openSerialLink(port, 115200), ruida::kDefaultMagic, impatient());
  const auto readWire = [&](size_t count) {
    ruida::Bytes got;
    const auto until = Clock::now() + 2s;
    while (got.size() < count && Clock::now() < until) {
      uint8_t buffer[64];
      const ssize_t n = ::read(master, buffer, std::min(sizeof buffer, count - got.size()));
      if (n > 0) got.insert(got.end(), buffer, buffer + n);
      if (n <= 0) std::this_thread::sleep_for(1ms);
    }
    return swizzle.undo(got);
  };
  channel->send({0xD8, 0x02});
  EXPECT_EQ(readWire(2), (ruida::Bytes{0xD8, 0x02}));
  std::thread controller([&] {
    const ruida::Bytes asked = readWire(4);
    ruida::Bytes reply = {0xCC, 0xDA, 0x01, asked[2], asked[3]};  // a stray byte first
    ruida::appendU35(reply, 0x65106510);
    const ruida::Bytes wire = swizzle(reply);
    EXPECT_EQ(::write(master, wire.data(), wire.size()), static_cast<ssize_t>(wire.size()));
  });
  EXPECT_EQ(channel->read(ruida::kMemoryCardId), 0x65106510);
  controller.join();
  // Nothing answers: a Timeout naming the port, in the tries' time.
  const auto start = Clock::now();
  EXPECT_THROW(channel->read(ruida::kMemoryStatus), DeviceFault);
  EXPECT_LT(Clock::now() - start, 3s);
  ::close(slave);
  ::close(master);
}

// `rotafab devices` asks the network (its broadcast address) for card IDs:
// here the simulated controller's loopback address.
TEST(Ruida, AControllerOnTheNetworkAnswersTheProbeWithItsCard) {
  sim::RuidaSimulator simulator(fast());
  const auto found = ruida::probeControllers("127.0.0.1", simulator.port(), 0, 300ms);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].address, "127.0.0.1");
  EXPECT_EQ(found[0].card, 0x65106510);
  const auto start = Clock::now();
  EXPECT_TRUE(ruida::probeControllers("127.0.0.1", 9, 0, 200ms).empty());  // the discard port: nobody answers
  EXPECT_LT(Clock::now() - start, 2s);
  EXPECT_TRUE(ruida::probeControllers("not an address", 50200, 0, 200ms).empty());
}

TEST(Ruida, UrisSayWhatIsWrong) {
  const auto message = [](const std::string& uri) {
    try {
      parseDeviceUri(uri);
      return std::string("accepted");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
  };
  EXPECT_EQ(message("ruida://192.168.1.100"), "accepted");
  EXPECT_EQ(message("ruida://laser.local:50200?magic=0x11&bind=0"), "accepted");
  EXPECT_EQ(message("ruida+serial:///dev/ttyUSB0?baud=115200"), "accepted");
  EXPECT_EQ(message("sim:ruida?fault=drop&after=3"), "accepted");
  EXPECT_NE(message("ruida://").find("no host"), std::string::npos);
  EXPECT_NE(message("ruida://1.2.3.4?magic=11").find("\"magic=11\": a Ruida URI takes"), std::string::npos);
  EXPECT_NE(message("ruida://1.2.3.4:99999").find("not a UDP port"), std::string::npos);
  EXPECT_NE(message("ruida+serial://ttyUSB0").find("absolute path"), std::string::npos);
  EXPECT_NE(message("ruida://fe80::1").find("IPv4 only"), std::string::npos);
  EXPECT_NE(message("ruida://[::1]:50200").find("IPv4 only"), std::string::npos);
  EXPECT_EQ(message("ruida://192.168.1.100/"), "accepted");
  EXPECT_NE(message("sim:ruida?fault=alarm")
                .find("fault=KIND (drop, corrupt or silence), after=PACKETS, witness=FILE "
                      "and cuts=FILE"),
            std::string::npos)
      << message("sim:ruida?fault=alarm");
}

}  // namespace
}  // namespace rotafab::devices
