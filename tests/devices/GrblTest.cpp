// The GRBL driver against the simulated GRBL on a pseudo-terminal (issue 5):
// the real serial code, character counting against the 127-byte buffer, the
// G-code a controller accepts, and every fault ending with the laser off, a
// typed error and no hang.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <exception>
#include <regex>
#include <set>
#include <thread>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include "toolpath/SheetDrawing.h"

#include "devices/grbl/GCode.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/sim/GrblSimulator.h"
#include "profiles/Profiles.h"

namespace rotafab::devices {
namespace {

using jobs::Point2;
using namespace std::chrono_literals;

// A sheet: an etched label, a scored fold, and two parts with a hole each.
jobs::SheetDrawing sheet() {
  jobs::SheetDrawing s;
  s.width = 15, s.height = 15, s.margin = 0.25;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  s.paths.push_back({jobs::Operation::Etch, {{1, 1}, {1.5, 1.2}, {2, 1}}, false});
  s.paths.push_back({jobs::Operation::Score, {{1, 3}, {4, 3}}, false});
  for (double x : {1.0, 6.0}) {
    s.paths.push_back({jobs::Operation::Cut, {{x + 1, 5}, {x + 2, 5}, {x + 2, 6}, {x + 1, 6}}, true});  // hole
    s.paths.push_back({jobs::Operation::Cut, {{x, 4}, {x + 4, 4}, {x + 4, 8}, {x, 8}}, true});          // outline
  }
  return s;
}

jobs::Toolpath toolpath(const jobs::MotionLimits& limits = {}) {
  const auto machine =
      profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/grbl-diode-400.yaml");
  profiles::MaterialProfile material;
  material.name = "test";
  return jobs::planToolpath(sheet(), machine, material, limits);
}

grbl::GrblTimeouts quick() {
  grbl::GrblTimeouts t;
  t.banner = std::chrono::milliseconds(1000);
  t.answer = std::chrono::milliseconds(1500);
  t.poll = std::chrono::milliseconds(50);
  t.stopHold = std::chrono::milliseconds(1500);
  t.stopReset = std::chrono::milliseconds(1500);
  return t;
}

std::unique_ptr<grbl::GrblDriver> driverFor(const sim::GrblSimulator& simulator, double timeScale = 1) {
  const std::string path = simulator.path();
  return std::make_unique<grbl::GrblDriver>([path] { return openSerialLink(path, 115200); }, quick(), timeScale);
}

// A simulated GRBL moving `timeScale` times faster than real, a driver
// connected to it, and the test sheet's toolpath for its settings.
struct Rig {
  explicit Rig(double timeScale)
      : simulator([&] {
          sim::GrblSimulatorOptions options;
          options.timeScale = timeScale;
          return options;
        }()),
        driver(driverFor(simulator, timeScale)) {
    driver->connect();
    path = toolpath(driver->motionLimits());
  }
  sim::GrblSimulator simulator;
  std::unique_ptr<grbl::GrblDriver> driver;
  jobs::Toolpath path;
};

TEST(Grbl, ConnectReadsTheSettingsAndTheBuffer) {
  sim::GrblSimulator simulator;
  auto driver = driverFor(simulator);
  EXPECT_EQ(driver->connect(), "Grbl 1.1h ['$' for help] (receive buffer 128 bytes, laser mode on)");
  EXPECT_EQ(driver->receiveBuffer(), 128u);
  EXPECT_EQ(driver->settings().at(32), 1);
  EXPECT_EQ(driver->gcodeOptions().maxSpindle, 1000);
  EXPECT_NEAR(driver->motionLimits().maxSpeed, 6000 / 25.4 / 60, 1e-9);
}

TEST(Grbl, RefusesToCutWithLaserModeOff) {
  sim::GrblSimulatorOptions options;
  options.laserMode = false;
  sim::GrblSimulator simulator(options);
  auto driver = driverFor(simulator);
  try {
    driver->connect();
    FAIL() << "connected";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Refused);
    EXPECT_NE(std::string(fault.what()).find("send $32=1"), std::string::npos) << fault.what();
  }
}

// A connect that fails keeps no link: the next call opens the port again and
// asks the controller again, instead of sending to one it never accepted.
TEST(Grbl, AConnectThatFailsLeavesNoHalfSetLink) {
  sim::GrblSimulatorOptions options;
  options.laserMode = false;
  sim::GrblSimulator simulator(options);
  int opened = 0;
  const std::string path = simulator.path();
  grbl::GrblDriver driver(
      [&opened, path] {
        ++opened;
        return openSerialLink(path, 115200);
      },
      quick());
  EXPECT_THROW(driver.connect(), DeviceFault);
  EXPECT_EQ(opened, 1);
  // status() connects first when there is no link: the refusal again, from a fresh connect.
  EXPECT_THROW(driver.status(), DeviceFault);
  EXPECT_EQ(opened, 2);
  // With no link, a safe stop cannot hear the controller confirm anything, and says so.
  EXPECT_FALSE(driver.stopSafely());
}

// The whole job: every line taken in order, the buffer kept full and never
// overflowed, the laser lit only while cutting and off at the end.
TEST(Grbl, StreamsAJobToTheEndWithTheBufferFullAndNeverOverflowed) {
  Rig rig(40);
  auto& [simulator, driver, path] = rig;
  const auto lines = grbl::gcodeLines(path, driver->gcodeOptions());
  std::vector<Progress> seen;
  core::Cancellation cancel;
  driver->run(
      path, [&](const Progress& p) { seen.push_back(p); }, cancel);
  const auto record = simulator.record();
  EXPECT_FALSE(record.overflowed);
  EXPECT_GE(record.mostBuffered, 100u) << "character counting keeps the buffer nearly full";
  ASSERT_GE(record.lines.size(), lines.size());
  const std::vector<std::string> job(record.lines.end() - static_cast<long>(lines.size()), record.lines.end());
  std::vector<std::string> expected;
  for (std::string line : lines) {
    line.erase(std::remove(line.begin(), line.end(), ' '), line.end());
    expected.push_back(line);
  }
  EXPECT_EQ(job, expected);
  EXPECT_FALSE(record.laserOn);
  EXPECT_FALSE(record.spindleEnabled) << "M5 at the end";
  EXPECT_GT(record.litSeconds, 0);
  EXPECT_EQ(record.state, "Idle");
  ASSERT_FALSE(seen.empty());
  EXPECT_EQ(seen.back().bytesAcknowledged, seen.back().bytesTotal);
  EXPECT_EQ(seen.back().stroke, path.strokes.size());
}

// The estimate is the time the job takes on GRBL's planner (accelerations,
// corners at the junction deviation's speed, the drain before M5) within
// 15%, and the progress counts down that time.
TEST(Grbl, TheEstimateIsTheTimeTheSimulatedMachineTakes) {
  // The test sheet and a circle of 90 short segments, taken without a stop at each.
  jobs::SheetDrawing curved = sheet();
  jobs::DrawnPath circle{jobs::Operation::Cut, {}, true};
  for (int k = 0; k < 90; ++k)
    circle.points.emplace_back(10 + 2 * std::cos(k * M_PI / 45), 10 + 2 * std::sin(k * M_PI / 45));
  curved.paths.push_back(circle);
  // Two speed-ups of the simulated clock, so that the estimate is not matched
  // by chance at one; the run takes 7.5 s and 3.8 s.
  for (double scale : {20.0, 40.0}) {
    SCOPED_TRACE(scale);
    Rig rig(scale);
    auto& [simulator, driver, path] = rig;
    const auto machine =
        profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/grbl-diode-400.yaml");
    profiles::MaterialProfile material;
    material.name = "test";
    path = jobs::planToolpath(curved, machine, material, driver->motionLimits());
    std::vector<Progress> seen;
    core::Cancellation cancel;
    driver->run(
        path, [&](const Progress& p) { seen.push_back(p); }, cancel);
    const auto record = simulator.record();
    const double ran = record.motionEndedAt - record.motionStartedAt;
    EXPECT_NEAR(path.seconds, ran, 0.15 * ran) << "estimated " << path.seconds << " s, ran " << ran << " s";
    // The old estimate, from a stop to a stop at every corner, was far above.
    jobs::MotionLimits stopping = driver->motionLimits();
    stopping.junctionDeviation = 0;
    EXPECT_GT(jobs::estimateSeconds(path, stopping), path.seconds);
    ASSERT_FALSE(seen.empty());
    EXPECT_NEAR(seen.front().secondsLeft, path.seconds, 0.1 * path.seconds);
    for (size_t i = 1; i < seen.size(); ++i) EXPECT_LE(seen[i].secondsLeft, seen[i - 1].secondsLeft + 1e-9);
    EXPECT_EQ(seen.back().secondsLeft, 0);
  }
}

// Each fault: the driver throws its kind, and the controller is left with the laser off.
void expectFault(FaultKind kind, const std::function<void(sim::GrblSimulator&)>& inject, const std::string& says,
                 bool cancelIt = false) {
  Rig rig(2);
  auto& [simulator, driver, path] = rig;
  core::Cancellation cancel;
  simulator.afterLines(12, [&](sim::GrblSimulator& s) {
    if (cancelIt) cancel.cancel();
    if (inject) inject(s);
  });
  const auto started = std::chrono::steady_clock::now();
  bool confirmed = false;
  try {
    driver->run(path, nullptr, cancel);
    FAIL() << "the job ran to its end";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, kind) << fault.what();
    EXPECT_NE(std::string(fault.what()).find(says), std::string::npos) << fault.what();
    confirmed = fault.laserOffConfirmed;
  }
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(15)) << "no hang";
  // A controller that went away or stopped answering cannot be told to stop
  // (and the driver says so); every other fault ends with the laser off, and
  // the machine stopped by a hold before the reset, so without an alarm.
  if (kind != FaultKind::Disconnected && kind != FaultKind::Timeout) {
    const auto record = simulator.record();
    EXPECT_TRUE(confirmed) << "the controller took M5 after the fault";
    EXPECT_FALSE(record.laserOn);
    EXPECT_FALSE(record.spindleEnabled) << "reset or M5 after the fault";
    EXPECT_EQ(record.state, kind == FaultKind::Alarm ? "Alarm" : "Idle");
  } else {
    EXPECT_FALSE(confirmed);
  }
}

// A cut stopped mid-sheet says how many strokes the machine finished (not
// only took into its planner); going on from the next stroke cuts every
// segment of the sheet, and cuts again only the stroke the head was in.
TEST(Grbl, AStoppedSheetGoesOnFromTheStrokeItStoppedInAndMissesNothing) {
  const size_t lines = grbl::gcodeProgram(toolpath(), {}).lines.size();
  for (const size_t stopAt : {lines / 3, 2 * lines / 3, 5 * lines / 6}) {
    SCOPED_TRACE(fmt::format("stopped after {} of {} lines", stopAt, lines));
    Rig rig(40);
    auto& [simulator, driver, path] = rig;
    core::Cancellation cancel;
    simulator.afterLines(stopAt, [&](sim::GrblSimulator&) { cancel.cancel(); });
    size_t cut = 0, taken = 0;
    EXPECT_THROW(driver->run(
                     path,
                     [&](const Progress& p) {
                       EXPECT_GE(p.strokesCut, cut) << "never backwards";
                       cut = p.strokesCut, taken = p.stroke;
                     },
                     cancel),
                 DeviceFault);
    EXPECT_LE(cut, taken);
    core::Cancellation never;
    driver->run(jobs::restOfSheet(path, cut, driver->motionLimits()), nullptr, never);
    const auto lit = simulator.record().litMoves;
    // Each segment of the sheet as often as its strokes go over it (a cut's
    // passes go over the same ones): cut at least that often, and more often
    // only along the stroke the head was in when it stopped.
    const auto same = [](const std::array<double, 4>& move, jobs::Point2 a, jobs::Point2 b) {
      return std::hypot(move[0] - a.x() * 25.4, move[1] - a.y() * 25.4) < 0.01 &&
             std::hypot(move[2] - b.x() * 25.4, move[3] - b.y() * 25.4) < 0.01;
    };
    size_t extra = 0;
    std::set<std::pair<size_t, size_t>> counted;  // (stroke, segment) of a geometry already counted
    for (size_t i = 0; i < path.strokes.size(); ++i) {
      const auto& points = path.strokes[i].points;
      for (size_t j = 1; j < points.size(); ++j) {
        if ((points[j] - points[j - 1]).norm() < 1e-4 || counted.contains({i, j})) continue;
        size_t needed = 0, burnt = 0;
        for (size_t k = i; k < path.strokes.size(); ++k) {
          const auto& others = path.strokes[k].points;
          for (size_t l = 1; l < others.size(); ++l) {
            if ((others[l] - points[j]).norm() < 1e-6 && (others[l - 1] - points[j - 1]).norm() < 1e-6) {
              ++needed, counted.insert({k, l});
            }
          }
        }
        for (const auto& move : lit) burnt += same(move, points[j - 1], points[j]) ? 1 : 0;
        EXPECT_GE(burnt, needed) << "stroke " << i << ", segment " << j << ": a cut missed";
        extra += burnt > needed ? burnt - needed : 0;
      }
    }
    EXPECT_LT(cut, path.strokes.size());
    EXPECT_LE(extra, path.strokes[cut].points.size() - 1) << "more cut again than the stroke the head was in";
    if (stopAt > lines / 2) {
      EXPECT_GT(cut, 0U) << "the strokes the machine finished, counted";
    }
  }
}

TEST(Grbl, AnAlarmStopsTheJobWithTheLaserOff) {
  expectFault(
      FaultKind::Alarm, [](sim::GrblSimulator& s) { s.raiseAlarm(1); }, "ALARM:1 (hard limit");
}

TEST(Grbl, CancelHoldsResetsAndLeavesTheLaserOff) { expectFault(FaultKind::Cancelled, nullptr, "cancelled", true); }

// A link that brings nothing but garbage is broken: a run of lines that are no GRBL reply is a fault.
TEST(Grbl, ARunOfGarbageIsAProtocolFault) {
  expectFault(
      FaultKind::Protocol,
      [](sim::GrblSimulator& s) {
        for (int i = 0; i < 3; ++i) s.sendGarbage();
      },
      "3 lines in a row that are no GRBL reply");
}

// Line noise now and then is not a fault: a garbled status report and a
// garbled line are skipped, and the job ends as it would have.
TEST(Grbl, AGarbledReportOrLineNowAndThenIsSkipped) {
  Rig rig(40);
  auto& [simulator, driver, path] = rig;
  simulator.afterLines(12, [](sim::GrblSimulator& s) {
    s.garbleNextStatus();
    s.sendGarbage();
  });
  core::Cancellation cancel;
  driver->run(path, nullptr, cancel);
  const auto record = simulator.record();
  EXPECT_EQ(record.state, "Idle");
  EXPECT_FALSE(record.spindleEnabled);
  EXPECT_EQ(record.linesExecuted, record.lines.size() - 2) << "every line but $$ and $I ran";
}

// A machine that says Run and stands still, taking no line (a stepper
// driver's fault, a jammed axis): found within the bound the moves in its
// planner set, and stopped with the laser off.
TEST(Grbl, AStallIsFoundAndTheLaserTurnedOff) {
  expectFault(
      FaultKind::Stalled, [](sim::GrblSimulator& s) { s.stall(); }, "the machine stopped moving");
}

TEST(Grbl, AControllerThatStopsAnsweringTimesOut) {
  expectFault(
      FaultKind::Timeout, [](sim::GrblSimulator& s) { s.mute(true); }, "no answer");
}

// A lost `ok`: the controller goes idle with a line still unanswered; the
// driver says so instead of waiting for ever, and the controller, which still
// answers, takes M5.
TEST(Grbl, ALostReplyIsFoundAndTheLaserTurnedOff) {
  Rig rig(40);
  auto& [simulator, driver, path] = rig;
  simulator.afterLines(20, [](sim::GrblSimulator& s) { s.loseNextOk(); });
  core::Cancellation cancel;
  try {
    driver->run(path, nullptr, cancel);
    FAIL() << "the job ran to its end";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Timeout) << fault.what();
    EXPECT_NE(std::string(fault.what()).find("a reply was lost"), std::string::npos) << fault.what();
    EXPECT_TRUE(fault.laserOffConfirmed) << "the controller, still answering, took M5";
  }
}

TEST(Grbl, UnpluggedMidJobIsADisconnect) {
  expectFault(
      FaultKind::Disconnected, [](sim::GrblSimulator& s) { s.unplug(); }, "");
}

// Framing traces the toolpath's box with rapid moves and the laser off.
TEST(Grbl, FrameTracesTheBoxWithTheLaserOff) {
  Rig rig(40);
  auto& [simulator, driver, path] = rig;
  driver->frame(path, core::Cancellation());
  const auto record = simulator.record();
  const std::vector<std::string> framed(record.lines.end() - 8, record.lines.end());
  const auto box = jobs::toolpathBounds(path);
  const auto mm = [](double inches) { return jobs::formatDecimal(inches * 25.4, 3); };
  EXPECT_EQ(framed,
            (std::vector<std::string>{"M5S0", "G21", "G90", "G0X" + mm(box[0]) + "Y" + mm(box[1]),
                                      "G0X" + mm(box[2]) + "Y" + mm(box[1]), "G0X" + mm(box[2]) + "Y" + mm(box[3]),
                                      "G0X" + mm(box[0]) + "Y" + mm(box[3]), "G0X" + mm(box[0]) + "Y" + mm(box[1])}));
  EXPECT_EQ(record.litSeconds, 0);
  EXPECT_EQ(record.state, "Idle");
}

// Where the machine profile gives a marking power (frame_power), the box is
// traced lit at that power, S10 of $30=1000 for 1%, by G1 in laser mode
// (dark at the corners), and the laser is off after it.
TEST(Grbl, FrameAtTheProfilesMarkingPowerLightsOnlyTheTrace) {
  Rig rig(40);
  auto& [simulator, driver, path] = rig;
  path.framePower = 1;
  driver->frame(path, core::Cancellation());
  const auto record = simulator.record();
  const std::vector<std::string> framed(record.lines.end() - 10, record.lines.end());
  const auto box = jobs::toolpathBounds(path);
  const auto mm = [](double inches) { return jobs::formatDecimal(inches * 25.4, 3); };
  EXPECT_EQ(framed, (std::vector<std::string>{"M5S0", "G21", "G90", "M4S10", "G0X" + mm(box[0]) + "Y" + mm(box[1]),
                                              "G1X" + mm(box[2]) + "Y" + mm(box[1]) + "F3000",
                                              "G1X" + mm(box[2]) + "Y" + mm(box[3]) + "F3000",
                                              "G1X" + mm(box[0]) + "Y" + mm(box[3]) + "F3000",
                                              "G1X" + mm(box[0]) + "Y" + mm(box[1]) + "F3000", "M5S0"}));
  EXPECT_GT(record.litSeconds, 0);
  EXPECT_FALSE(record.laserOn);
  EXPECT_FALSE(record.spindleEnabled);
  EXPECT_EQ(record.state, "Idle");
}

// A lit frame is a job of its own: a cancel stops it at once, in real time,
// with the laser off and confirmed (GRBL's hold, reset and M5).
TEST(Grbl, ALitFrameStopsAtOnceOnACancelWithTheLaserOff) {
  Rig rig(1);
  // (Not a structured binding: the lambdas below capture them.)
  sim::GrblSimulator& simulator = rig.simulator;
  std::unique_ptr<grbl::GrblDriver>& driver = rig.driver;
  jobs::Toolpath& path = rig.path;
  path.framePower = 1;
  core::Cancellation cancel;
  std::thread canceller([&] {
    for (int i = 0; i < 500 && !simulator.record().laserOn; ++i) std::this_thread::sleep_for(10ms);
    cancel.cancel();
  });
  const auto started = std::chrono::steady_clock::now();
  try {
    driver->frame(path, cancel);
    ADD_FAILURE() << "the frame ran to its end";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Cancelled) << fault.what();
    EXPECT_TRUE(fault.laserOffConfirmed);
  }
  canceller.join();
  EXPECT_LT(std::chrono::steady_clock::now() - started, 10s) << "tracing the box takes 16 s at 3000 mm/min";
  EXPECT_GT(simulator.record().litSeconds, 0) << "the frame was lit before the cancel";
  EXPECT_FALSE(simulator.record().laserOn);
}

// A hold from another thread stops the machine (and its laser) mid-job; a
// resume lets the job run to its end.
TEST(Grbl, PauseHoldsAndResumeFinishes) {
  Rig rig(40);
  // (Not a structured binding: the lambdas below capture them.)
  sim::GrblSimulator& simulator = rig.simulator;
  std::unique_ptr<grbl::GrblDriver>& driver = rig.driver;
  jobs::Toolpath& path = rig.path;
  core::Cancellation cancel;
  std::exception_ptr failed;
  std::thread job([&] {
    try {
      driver->run(path, nullptr, cancel);
    } catch (...) {
      failed = std::current_exception();
    }
  });
  for (int i = 0; i < 1000 && simulator.record().linesExecuted < 10; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  driver->pause();
  bool held = false;
  for (int i = 0; i < 200 && !held; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    held = simulator.record().state == "Hold:0";
  }
  EXPECT_TRUE(held);
  const size_t linesWhileHeld = simulator.record().linesExecuted;
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_FALSE(simulator.record().laserOn);
  EXPECT_EQ(simulator.record().linesExecuted, linesWhileHeld) << "nothing is parsed during a hold";
  driver->resume();
  job.join();
  ASSERT_FALSE(failed) << "the job failed";
  const auto record = simulator.record();
  EXPECT_EQ(record.state, "Idle");
  EXPECT_FALSE(record.spindleEnabled);
  EXPECT_GT(record.linesExecuted, linesWhileHeld);
}

// ser2net in miniature: a TCP port on this machine whose one connection is
// joined byte for byte to the simulator's pseudo-terminal, as an ESP32 board
// or ser2net joins a telnet port to a GRBL controller's serial line.
class TcpBridge {
 public:
  explicit TcpBridge(const std::string& ptyPath) {
    listener_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (listener_ < 0 || ::bind(listener_, reinterpret_cast<sockaddr*>(&address), length) != 0 ||
        ::listen(listener_, 1) != 0 || ::getsockname(listener_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      throw std::runtime_error("no TCP port for the bridge");
    }
    port_ = std::to_string(ntohs(address.sin_port));
    thread_ = std::thread([this, ptyPath] { forward(ptyPath); });
  }
  ~TcpBridge() {
    stop_ = true;
    thread_.join();
    ::close(listener_);
  }
  [[nodiscard]] const std::string& port() const { return port_; }
  void drop() { drop_ = true; }  // the network goes away: the connection closes

 private:
  void forward(const std::string& ptyPath) {
    int client = -1;
    while (!stop_ && client < 0) {
      pollfd waiting{listener_, POLLIN, 0};
      if (::poll(&waiting, 1, 50) > 0) client = ::accept(listener_, nullptr, nullptr);
    }
    const int pty = ::open(ptyPath.c_str(), O_RDWR | O_NOCTTY);
    termios raw{};
    if (pty >= 0 && ::tcgetattr(pty, &raw) == 0) {
      ::cfmakeraw(&raw);
      ::tcsetattr(pty, TCSANOW, &raw);
    }
    char buffer[512];
    while (!stop_ && !drop_ && client >= 0 && pty >= 0) {
      pollfd both[2] = {{client, POLLIN, 0}, {pty, POLLIN, 0}};
      if (::poll(both, 2, 20) <= 0) continue;
      for (int i = 0; i < 2; ++i) {
        if (!(both[i].revents & (POLLIN | POLLHUP))) continue;
        const ssize_t n = ::read(both[i].fd, buffer, sizeof buffer);
        if (n <= 0) drop_ = true;
        if (n > 0 && ::write(both[1 - i].fd, buffer, static_cast<size_t>(n)) != n) drop_ = true;
      }
    }
    if (client >= 0) ::close(client);
    if (pty >= 0) ::close(pty);
  }

  int listener_ = -1;
  std::string port_;
  std::atomic<bool> stop_{false}, drop_{false};
  std::thread thread_;
};

// GRBL over TCP (grbl+tcp://): the same driver and job through a socket.
TEST(Grbl, StreamsOverTcpAsOverSerial) {
  sim::GrblSimulatorOptions options;
  options.timeScale = 40;
  sim::GrblSimulator simulator(options);
  TcpBridge bridge(simulator.path());
  grbl::GrblDriver driver([&] { return openTcpLink("127.0.0.1", bridge.port(), std::chrono::milliseconds(2000)); },
                          quick());
  EXPECT_NE(driver.connect().find("Grbl 1.1h"), std::string::npos);
  const jobs::Toolpath path = toolpath(driver.motionLimits());
  core::Cancellation cancel;
  driver.run(path, nullptr, cancel);
  const auto record = simulator.record();
  const auto lines = grbl::gcodeLines(path, driver.gcodeOptions());
  ASSERT_GE(record.lines.size(), lines.size());
  EXPECT_EQ(record.lines.back(), "G0X0Y0");
  EXPECT_FALSE(record.overflowed);
  EXPECT_FALSE(record.spindleEnabled);
  EXPECT_EQ(record.state, "Idle");
}

TEST(Grbl, ADroppedTcpConnectionIsADisconnectNotAHang) {
  sim::GrblSimulatorOptions options;
  options.timeScale = 2;
  sim::GrblSimulator simulator(options);
  TcpBridge bridge(simulator.path());
  grbl::GrblDriver driver([&] { return openTcpLink("127.0.0.1", bridge.port(), std::chrono::milliseconds(2000)); },
                          quick());
  driver.connect();
  const size_t before = simulator.record().linesExecuted;
  simulator.afterLines(before + 12, [&](sim::GrblSimulator&) { bridge.drop(); });
  const auto started = std::chrono::steady_clock::now();
  core::Cancellation cancel;
  try {
    driver.run(toolpath(driver.motionLimits()), nullptr, cancel);
    FAIL() << "the job ran to its end";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Disconnected) << fault.what();
    EXPECT_NE(std::string(fault.what()).find("127.0.0.1:" + bridge.port()), std::string::npos) << fault.what();
    EXPECT_FALSE(fault.laserOffConfirmed);
  }
  EXPECT_GE(simulator.record().linesExecuted, before + 12) << "the job had begun";
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(15)) << "no hang";
}

// $H with homing off ($22=0, GRBL's default): refused, with the fix.
TEST(Grbl, HomingOffIsRefusedWithTheFix) {
  Rig rig(40);
  try {
    rig.driver->home();
    FAIL() << "homed without homing switches";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Refused) << fault.what();
    EXPECT_NE(std::string(fault.what()).find("$22"), std::string::npos) << fault.what();
    EXPECT_TRUE(fault.laserOffConfirmed);
  }
  EXPECT_EQ(rig.simulator.record().state, "Idle");
}

TEST(Grbl, StatusReportsParse) {
  const auto report = grbl::parseStatusReport("<Run|MPos:25.400,-50.800,0.000|FS:500,300>");
  ASSERT_TRUE(report);
  EXPECT_EQ(report->state, "Run");
  EXPECT_DOUBLE_EQ(report->x, 1.0);
  EXPECT_DOUBLE_EQ(report->y, -2.0);
  EXPECT_EQ(grbl::parseStatusReport("<Hold:0|MPos:0.000,0.000,0.000|Bf:15,128|FS:0,0>")->state, "Hold:0");
  EXPECT_FALSE(grbl::parseStatusReport("ok"));
}

}  // namespace
}  // namespace rotafab::devices
