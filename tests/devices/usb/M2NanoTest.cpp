// The M2 Nano driver against the simulated board (issue 5): the real libusb
// code path through umockdev's usbfs emulation, the packets and status
// protocol a K40 answers, what the machine burns, and every fault ending with
// the laser off (or said not to be confirmed), a typed error and no hang.

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <set>
#include <thread>

#include "devices/m2nano/Lhymicro.h"
#include "devices/m2nano/M2NanoDriver.h"
#include "devices/sim/M2NanoSimulator.h"
#include "profiles/Profiles.h"
#include "toolpath/SheetDrawing.h"

namespace rotafab::devices {
namespace {

using Clock = std::chrono::steady_clock;

// A sheet: an etched label, a scored fold, a part with a hole and a diagonal.
jobs::SheetDrawing sheet() {
  jobs::SheetDrawing s;
  s.width = 11, s.height = 7, s.margin = 0.25;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  s.paths.push_back({jobs::Operation::Etch, {{1, 1}, {1.5, 1.2}, {2, 1}}, false});
  s.paths.push_back({jobs::Operation::Score, {{1, 3}, {4, 3.5}}, false});
  s.paths.push_back({jobs::Operation::Cut, {{6, 2}, {7, 2}, {7, 3}, {6, 3}}, true});  // hole
  s.paths.push_back({jobs::Operation::Cut, {{5, 1}, {9, 1}, {9.5, 5}, {5, 5}}, true});
  return s;
}

jobs::Toolpath toolpath() {
  const auto machine =
      profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/k40-m2nano.yaml");
  profiles::MaterialProfile material;
  material.name = "test";
  return jobs::planToolpath(sheet(), machine, material, m2nano::motionLimits());
}

m2nano::M2NanoTimeouts quick() {
  m2nano::M2NanoTimeouts t;
  t.transfer = std::chrono::milliseconds(1500);
  t.ready = std::chrono::milliseconds(2000);
  t.busy = std::chrono::milliseconds(5000);
  t.poll = std::chrono::milliseconds(5);
  return t;
}

// A simulated board running `timeScale` times faster than real, and a driver connected to it.
struct Rig {
  explicit Rig(double timeScale, m2nano::M2NanoTimeouts timeouts = quick())
      : Rig(
            [&] {
              sim::M2NanoSimulatorOptions options;
              options.timeScale = timeScale;
              return options;
            }(),
            timeouts) {}
  explicit Rig(const sim::M2NanoSimulatorOptions& options, m2nano::M2NanoTimeouts timeouts = quick())
      : simulator(options), driver([match = simulator.match()] { return UsbLink::open(match, 0); }, timeouts) {
    identity = driver.connect();
  }
  ~Rig() { driver.disconnect(); }  // before the device goes
  sim::M2NanoSimulator simulator;
  m2nano::M2NanoDriver driver;
  std::string identity;
};

// The laser-on moves of the board, joined into polylines (mils, board coordinates).
std::vector<std::vector<std::pair<long, long>>> burns(const std::vector<sim::BoardSegment>& trace) {
  std::vector<std::vector<std::pair<long, long>>> out;
  bool burning = false;
  for (const sim::BoardSegment& s : trace) {
    if (!s.laser) {
      burning = false;
      continue;
    }
    if (!burning || out.back().back() != std::pair{s.x0, s.y0}) out.push_back({{s.x0, s.y0}});
    out.back().emplace_back(s.x1, s.y1);
    burning = true;
  }
  return out;
}

TEST(M2Nano, ConnectsThroughLibusbAndInitialisesTheBridge) {
  Rig rig(1);
  EXPECT_NE(rig.identity.find("M2 Nano"), std::string::npos) << rig.identity;
  EXPECT_NE(rig.identity.find("001:004"), std::string::npos) << rig.identity;
  EXPECT_NE(rig.identity.find("CH341 version 48"), std::string::npos) << rig.identity;
  const auto record = rig.simulator.record();
  EXPECT_TRUE(record.initialised);
  EXPECT_GE(record.statusRequests, 1u);
  EXPECT_EQ(rig.driver.status().state, "OK");
}

TEST(M2Nano, NoSuchDeviceIsADisconnectedFault) {
  sim::M2NanoSimulator simulator;
  UsbMatch elsewhere = simulator.match();
  elsewhere.bus = 9;
  try {
    UsbLink::open(elsewhere, 0);
    FAIL() << "opened a device that is not there";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Disconnected);
    EXPECT_NE(std::string(fault.what()).find("no such USB device"), std::string::npos) << fault.what();
  }
}

TEST(M2Nano, CutsTheSheetAsDrawnAndHomes) {
  Rig rig(200);
  const jobs::Toolpath path = toolpath();
  std::vector<Progress> reports;
  core::Cancellation cancel;
  rig.driver.run(
      path, [&](const Progress& p) { reports.push_back(p); }, cancel);
  const auto record = rig.simulator.record();
  EXPECT_TRUE(record.violations.empty()) << record.violations.front();
  EXPECT_FALSE(record.laser);
  EXPECT_FALSE(record.busy);
  EXPECT_EQ(record.x, 0);  // homed after the job
  EXPECT_EQ(record.y, 0);
  // The packets the board took are the job's, once each, then the home.
  std::vector<std::string> expected;
  for (const std::string& line : m2nano::jobLines(path)) {
    for (const m2nano::Packet& p : m2nano::packets(line)) expected.emplace_back(p.begin() + 2, p.begin() + 32);
  }
  expected.push_back("IPP" + std::string(27, 'F'));
  EXPECT_EQ(record.payloads, expected);
  // What burnt is each stroke, in order, within a mil, at the stroke's speed.
  const auto burnt = burns(record.trace);
  ASSERT_EQ(burnt.size(), path.strokes.size());
  for (size_t i = 0; i < burnt.size(); ++i) {
    const auto& points = path.strokes[i].points;
    ASSERT_EQ(burnt[i].front(), (std::pair{std::lround(points.front().x() * 1000),
                                           std::lround((path.height - points.front().y()) * 1000)}));
    ASSERT_EQ(burnt[i].back(), (std::pair{std::lround(points.back().x() * 1000),
                                          std::lround((path.height - points.back().y()) * 1000)}));
  }
  for (const sim::BoardSegment& s : record.trace) {
    if (s.laser) {
      EXPECT_GT(s.mmPerSecond, 0.5);
    }
  }
  // Progress: monotonic, to the last stroke and every byte.
  ASSERT_FALSE(reports.empty());
  for (size_t i = 1; i < reports.size(); ++i) {
    EXPECT_GE(reports[i].bytesAcknowledged, reports[i - 1].bytesAcknowledged);
    EXPECT_GE(reports[i].stroke, reports[i - 1].stroke);
  }
  // (The last report, once the board has finished, says so regardless; the
  // one before counts the strokes the board took.)
  ASSERT_GE(reports.size(), 3u);
  const Progress& sent = reports[reports.size() - 2];
  EXPECT_EQ(sent.stroke, path.strokes.size());
  EXPECT_EQ(sent.bytesAcknowledged, sent.bytesTotal);
  EXPECT_LT(reports.front().stroke, path.strokes.size() / 2);
  EXPECT_EQ(rig.driver.resends(), 0u);
}

TEST(M2Nano, ResendsPacketsThatArriveCorrupted) {
  Rig rig(200);
  rig.simulator.afterPackets(2, [](sim::M2NanoSimulator& s) { s.corruptPackets(3); });
  const jobs::Toolpath path = toolpath();
  core::Cancellation cancel;
  rig.driver.run(path, {}, cancel);
  const auto record = rig.simulator.record();
  EXPECT_EQ(record.packetsRejected, 3u);
  EXPECT_EQ(rig.driver.resends(), 3u);
  EXPECT_EQ(burns(record.trace).size(), path.strokes.size());  // each packet executed once
  EXPECT_TRUE(record.violations.empty()) << record.violations.front();
}

TEST(M2Nano, TooManyCrcErrorsIsAFaultWithTheLaserOff) {
  Rig rig(200);
  // 50 rejects of one packet make the fault; the stop ("I") gets through on its third try.
  rig.simulator.afterPackets(2, [](sim::M2NanoSimulator& s) { s.corruptPackets(52); });
  core::Cancellation cancel;
  try {
    rig.driver.run(toolpath(), {}, cancel);
    FAIL() << "the job ran through a broken cable";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Protocol);
    EXPECT_NE(std::string(fault.what()).find("CRC"), std::string::npos) << fault.what();
    EXPECT_TRUE(fault.laserOffConfirmed);
  }
  const auto record = rig.simulator.record();
  EXPECT_FALSE(record.laser);
  EXPECT_EQ(record.mode, sim::BoardMode::Default);
  EXPECT_EQ(record.packetsRejected, 52u);
}

// Runs the job until `fault` has been injected after `packets` packets; the
// fault the driver threw, and how long the run took.
struct Outcome {
  FaultKind kind;
  bool laserOffConfirmed;
  std::string what;
  double seconds;
};
Outcome runInto(Rig& rig, size_t packets, std::function<void(sim::M2NanoSimulator&)> fault) {
  rig.simulator.afterPackets(packets, std::move(fault));
  core::Cancellation cancel;
  const auto started = Clock::now();
  try {
    rig.driver.run(toolpath(), {}, cancel);
  } catch (const DeviceFault& error) {
    return {error.kind, error.laserOffConfirmed, error.what(),
            std::chrono::duration<double>(Clock::now() - started).count()};
  }
  ADD_FAILURE() << "the job ran through the fault";
  return {FaultKind::Protocol, false, "", 0};
}

// Runs the job and cancels it once two strokes are taken: a Cancelled
// fault, with the laser off confirmed.
void cancelAfterTwoStrokes(m2nano::M2NanoDriver& driver, const jobs::Toolpath& path) {
  core::Cancellation cancel;
  try {
    driver.run(
        path,
        [&](const Progress& p) {
          if (p.stroke >= 2) cancel.cancel();
        },
        cancel);
    FAIL() << "the job ran to its end";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Cancelled);
    EXPECT_TRUE(fault.laserOffConfirmed);
  }
}

TEST(M2Nano, CancelMidJobDropsTheQueueAndLeavesTheLaserOff) {
  Rig rig(2);
  const jobs::Toolpath path = toolpath();
  cancelAfterTwoStrokes(rig.driver, path);
  const auto before = rig.simulator.record();
  EXPECT_FALSE(before.laser);
  EXPECT_EQ(before.mode, sim::BoardMode::Default);
  EXPECT_FALSE(before.busy);  // nothing left queued to burn
  EXPECT_LT(burns(before.trace).size(), path.strokes.size());
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  const auto after = rig.simulator.record();
  EXPECT_EQ(after.trace.size(), before.trace.size());  // and nothing moves any more
}

TEST(M2Nano, UnplugMidJobIsADisconnectNotAHang) {
  Rig rig(40);
  const Outcome outcome = runInto(rig, 4, [](sim::M2NanoSimulator& s) { s.unplug(); });
  EXPECT_EQ(outcome.kind, FaultKind::Disconnected) << outcome.what;
  EXPECT_FALSE(outcome.laserOffConfirmed);  // nothing can be confirmed of a board that is gone
  EXPECT_LT(outcome.seconds, 10);
}

TEST(M2Nano, ABoardThatStopsAnsweringIsATimeoutAndStillGetsTheStop) {
  auto timeouts = quick();
  timeouts.transfer = std::chrono::milliseconds(300);  // a silent board: three requests of 300 ms
  Rig rig(40, timeouts);
  const Outcome outcome = runInto(rig, 4, [](sim::M2NanoSimulator& s) { s.mute(true); });
  EXPECT_EQ(outcome.kind, FaultKind::Timeout) << outcome.what;
  EXPECT_FALSE(outcome.laserOffConfirmed);
  EXPECT_LT(outcome.seconds, 15);
  // The board still took the stop packet ("I"), unconfirmed: its laser is off and its queue dropped.
  const auto record = rig.simulator.record();
  EXPECT_FALSE(record.laser);
  EXPECT_EQ(record.mode, sim::BoardMode::Default);
  EXPECT_EQ(record.payloads.back(), "I" + std::string(29, 'F'));
}

TEST(M2Nano, GarbageStatusIsAProtocolFaultWithTheLaserOff) {
  Rig rig(40);
  const Outcome outcome = runInto(rig, 4, [](sim::M2NanoSimulator& s) { s.sendGarbage(); });
  EXPECT_EQ(outcome.kind, FaultKind::Protocol) << outcome.what;
  EXPECT_NE(outcome.what.find("no M2 Nano reports"), std::string::npos) << outcome.what;
  EXPECT_TRUE(outcome.laserOffConfirmed);
  const auto record = rig.simulator.record();
  EXPECT_FALSE(record.laser);
  EXPECT_EQ(record.mode, sim::BoardMode::Default);
}

TEST(M2Nano, APowerFaultIsAnAlarm) {
  Rig rig(40);
  const Outcome outcome = runInto(rig, 4, [](sim::M2NanoSimulator& s) { s.powerFault(true); });
  EXPECT_EQ(outcome.kind, FaultKind::Alarm) << outcome.what;
  const auto record = rig.simulator.record();
  EXPECT_FALSE(record.laser);
  EXPECT_NE(record.mode, sim::BoardMode::Compact);
}

// A pause holds the job at the end of a stroke: the board runs what it has,
// leaves compact mode and stands with its laser off; a resume sends the
// rest, and every stroke is burnt once, whole.
TEST(M2Nano, PauseHoldsAtAStrokesEndWithTheLaserOffAndResumeFinishes) {
  Rig rig(20);
  const jobs::Toolpath path = toolpath();
  core::Cancellation cancel;
  std::exception_ptr failed;
  std::thread job([&] {
    try {
      rig.driver.run(path, {}, cancel);
    } catch (...) {
      failed = std::current_exception();
    }
  });
  const auto until = Clock::now() + std::chrono::seconds(30);
  while (burns(rig.simulator.record().trace).empty() && Clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  rig.driver.pause();
  auto held = rig.simulator.record();
  while ((held.busy || held.mode != sim::BoardMode::Default) && Clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    held = rig.simulator.record();
  }
  EXPECT_FALSE(held.busy);
  EXPECT_EQ(held.mode, sim::BoardMode::Default);
  EXPECT_FALSE(held.laser);
  // The head stands where a stroke ended.
  bool atAStrokesEnd = false;
  for (const jobs::ToolpathStroke& stroke : path.strokes) {
    atAStrokesEnd |= held.x == std::lround(stroke.points.back().x() * 1000) &&
                     held.y == std::lround((path.height - stroke.points.back().y()) * 1000);
  }
  EXPECT_TRUE(atAStrokesEnd) << held.x << ", " << held.y;
  const size_t burntWhenHeld = burns(held.trace).size();
  EXPECT_LT(burntWhenHeld, path.strokes.size());
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  EXPECT_EQ(rig.simulator.record().trace.size(), held.trace.size()) << "nothing moves while held";
  rig.driver.resume();
  job.join();
  if (failed) std::rethrow_exception(failed);
  const auto record = rig.simulator.record();
  const auto burnt = burns(record.trace);
  ASSERT_EQ(burnt.size(), path.strokes.size());
  for (size_t i = 0; i < burnt.size(); ++i) {
    const auto& end = path.strokes[i].points.back();
    EXPECT_EQ(burnt[i].back(), (std::pair{std::lround(end.x() * 1000), std::lround((path.height - end.y()) * 1000)}));
  }
  EXPECT_TRUE(record.violations.empty()) << record.violations.front();
}

// A board that runs "I" in its turn, behind the packets it has queued: the
// laser is called off only once the board has run it and homed.
TEST(M2Nano, AStopTheBoardRunsInItsTurnIsConfirmedOnlyOnceRun) {
  sim::M2NanoSimulatorOptions options;
  options.timeScale = 5;
  options.board.abortAtOnce = false;
  Rig rig(options);
  cancelAfterTwoStrokes(rig.driver, toolpath());
  const auto record = rig.simulator.record();
  EXPECT_FALSE(record.busy) << "confirmed before the board had run its queue";
  EXPECT_FALSE(record.laser);
  EXPECT_EQ(record.x, 0);  // homed
  EXPECT_EQ(record.y, 0);
}

TEST(M2Nano, FramingTracesTheBoxWithTheLaserOff) {
  Rig rig(40);
  const jobs::Toolpath path = toolpath();
  rig.driver.frame(path, core::Cancellation());
  const auto record = rig.simulator.record();
  EXPECT_TRUE(burns(record.trace).empty());
  const auto box = jobs::toolpathBounds(path);
  const long left = std::lround(box[0] * 1000), right = std::lround(box[2] * 1000);
  const long back = std::lround((path.height - box[3]) * 1000), front = std::lround((path.height - box[1]) * 1000);
  std::set<std::pair<long, long>> corners;
  for (const sim::BoardSegment& s : record.trace) corners.emplace(s.x1, s.y1);
  for (const auto& corner : {std::pair{left, back}, {right, back}, {right, front}, {left, front}})
    EXPECT_TRUE(corners.count(corner)) << corner.first << ", " << corner.second;
  EXPECT_TRUE(record.violations.empty()) << record.violations.front();
}

}  // namespace
}  // namespace rotafab::devices
