// A device in a helper process (devices/remote/): the host side serves a
// real driver (GRBL, against its simulator) over a socket, and stops the job
// with the laser off when the side that asked goes away; the asking side
// turns a helper that dies or falls silent into a typed fault, never a hang.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "devices/grbl/GCode.h"
#include "devices/grbl/GrblDriver.h"
#include "devices/remote/DeviceHost.h"
#include "devices/remote/LinePipe.h"
#include "devices/remote/RemoteDevice.h"
#include "devices/remote/RemoteProtocol.h"
#include "devices/sim/GrblSimulator.h"
#include "profiles/Profiles.h"

namespace rotafab::devices::remote {
namespace {

using namespace std::chrono_literals;

jobs::Toolpath square(const jobs::MotionLimits& limits) {
  jobs::SheetDrawing s;
  s.width = 15, s.height = 15, s.margin = 0.25;
  for (auto op : profiles::kAllOperations) s.colours[op] = {0, 0, 0};
  for (double x : {1.0, 6.0}) s.paths.push_back({jobs::Operation::Cut, {{x, 4}, {x + 4, 4}, {x + 4, 8}, {x, 8}}, true});
  const auto machine =
      profiles::loadMachineProfile(std::string(ROTAFAB_SOURCE_DIR) + "/profiles/machines/grbl-diode-400.yaml");
  return jobs::planToolpath(s, machine, profiles::MaterialProfile{}, limits);
}

// A simulated GRBL, its driver served on one end of a socket, the test on the other.
struct HostRig {
  explicit HostRig(double timeScale)
      : simulator([&] {
          sim::GrblSimulatorOptions options;
          options.timeScale = timeScale;
          return options;
        }()),
        driver([path = simulator.path()] { return openSerialLink(path, 115200); }) {
    int sockets[2];
    EXPECT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, sockets), 0);
    client = std::make_unique<LinePipe>(sockets[0], ::dup(sockets[0]));
    host = std::thread([this, fd = sockets[1]] {
      serveDevice(driver, fd, fd);
      ::close(fd);
    });
  }
  ~HostRig() {
    client.reset();
    if (host.joinable()) host.join();
  }
  nlohmann::json next(std::chrono::milliseconds timeout = 5s) {
    std::string line;
    EXPECT_EQ(client->readLine(line, timeout), LinePipe::Read::Line);
    return nlohmann::json::parse(line.empty() ? "{}" : line);
  }
  sim::GrblSimulator simulator;
  grbl::GrblDriver driver;
  std::unique_ptr<LinePipe> client;
  std::thread host;
};

TEST(DeviceHost, ServesARunToItsEndWithProgress) {
  HostRig rig(500);
  ASSERT_TRUE(rig.client->writeLine(nlohmann::json{{"op", "connect"}, {"id", 1}}.dump()));
  const auto connected = rig.next();
  ASSERT_TRUE(connected.value("ok", false)) << connected.dump();
  EXPECT_NE(connected.at("identity").get<std::string>().find("Grbl 1.1h"), std::string::npos);
  const jobs::Toolpath path = square(rig.driver.motionLimits());
  ASSERT_TRUE(rig.client->writeLine(nlohmann::json{{"op", "run"}, {"id", 2}, {"toolpath", toJson(path)}}.dump()));
  size_t strokes = 0;
  for (;;) {
    const auto answer = rig.next(30s);
    if (answer.contains("alive")) continue;
    if (answer.contains("progress")) {
      strokes = progressOf(answer.at("progress")).stroke;
      continue;
    }
    ASSERT_TRUE(answer.value("ok", false)) << answer.dump();
    break;
  }
  EXPECT_EQ(strokes, path.strokes.size());
  // The host ran the very toolpath planned here: the controller's last
  // lines are its G-code (which GRBL takes without the spaces).
  const auto record = rig.simulator.record();
  auto lines = grbl::gcodeLines(path, rig.driver.gcodeOptions());
  for (std::string& line : lines) std::erase(line, ' ');
  ASSERT_GE(record.lines.size(), lines.size());
  EXPECT_TRUE(std::equal(lines.rbegin(), lines.rend(), record.lines.rbegin()))
      << "the lines the controller took differ from the program";
  EXPECT_FALSE(record.laserOn);
}

// A cancel sent right behind its run, before the host has started it, still
// stops it; a cancel that comes after its run has ended stops nothing later.
TEST(DeviceHost, ACancelAheadOfItsRunStopsItAndALateOneStopsNothing) {
  HostRig rig(20);
  rig.client->writeLine(nlohmann::json{{"op", "connect"}, {"id", 1}}.dump());
  ASSERT_TRUE(rig.next().value("ok", false));
  const auto path = toJson(square(rig.driver.motionLimits()));
  rig.client->writeLine(nlohmann::json{{"op", "run"}, {"id", 2}, {"toolpath", path}}.dump());
  rig.client->writeLine(nlohmann::json{{"op", "cancel"}, {"id", 2}}.dump());
  for (;;) {
    const auto answer = rig.next(20s);
    if (answer.contains("alive") || answer.contains("progress")) continue;
    ASSERT_TRUE(answer.contains("fault")) << answer.dump();
    EXPECT_EQ(answer.at("fault").at("kind"), "cancelled");
    EXPECT_TRUE(answer.at("fault").at("confirmed").get<bool>());
    break;
  }
  EXPECT_FALSE(rig.simulator.record().laserOn);
  // A cancel for run 2, late: run 3 goes to its end.
  rig.client->writeLine(nlohmann::json{{"op", "cancel"}, {"id", 2}}.dump());
  rig.client->writeLine(nlohmann::json{{"op", "run"}, {"id", 3}, {"toolpath", path}}.dump());
  for (;;) {
    const auto answer = rig.next(60s);
    if (answer.contains("alive") || answer.contains("progress")) continue;
    EXPECT_TRUE(answer.value("ok", false)) << answer.dump();
    EXPECT_EQ(answer.at("id"), 3);
    break;
  }
}

TEST(DeviceHost, WhenTheOtherSideGoesTheRunStopsWithTheLaserOff) {
  HostRig rig(20);  // slow enough to be mid-job
  rig.client->writeLine(nlohmann::json{{"op", "connect"}, {"id", 1}}.dump());
  ASSERT_TRUE(rig.next().value("ok", false));
  rig.client->writeLine(
      nlohmann::json{{"op", "run"}, {"id", 2}, {"toolpath", toJson(square(rig.driver.motionLimits()))}}.dump());
  // Mid-job (the laser lit), the asking side is gone, as if killed.
  const auto until = std::chrono::steady_clock::now() + 20s;
  while (!rig.simulator.record().laserOn && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(5ms);
  ASSERT_TRUE(rig.simulator.record().laserOn) << "the job never lit the laser";
  const auto gone = std::chrono::steady_clock::now();
  rig.client.reset();
  rig.host.join();  // the host ends: the run cancelled, the device disconnected
  EXPECT_LT(std::chrono::steady_clock::now() - gone, 10s);
  const auto record = rig.simulator.record();
  EXPECT_FALSE(record.laserOn);
  EXPECT_FALSE(record.spindleEnabled) << "M5 after the reset";
}

// A remote device with no dry run of its own (sim:m2nano's has the M2 Nano's).
class Remote : public RemoteDevice {
 public:
  using RemoteDevice::RemoteDevice;
  [[nodiscard]] std::string program(const std::vector<jobs::Toolpath>&) const override { return {}; }
  [[nodiscard]] std::string describeProgram(const std::vector<jobs::Toolpath>&) const override { return {}; }
};

TEST(RemoteDevice, AHelperThatDiesMidJobIsADisconnectNotConfirmedOff) {
  // It answers the connect, then dies when the run comes.
  Remote device({"/bin/sh", "-c", R"(read l; echo '{"ok":true,"identity":"fake","id":1}'; read l; exit 3)"});
  EXPECT_EQ(device.connect(), "fake");
  const core::Cancellation never;
  try {
    device.run(square({}), {}, never);
    FAIL() << "ran";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Disconnected) << fault.what();
    EXPECT_FALSE(fault.laserOffConfirmed);
  }
}

TEST(RemoteDevice, ASilentHelperTimesOutAndACancelIsPassedOn) {
  RemoteTimeouts quick;
  quick.request = 300ms;
  quick.stop = 500ms;
  quick.exit = 200ms;
  quick.silence = 400ms;
  {
    Remote device({"/bin/sh", "-c", "sleep 30"}, quick);
    const auto start = std::chrono::steady_clock::now();
    try {
      device.connect();
      FAIL() << "connected";
    } catch (const DeviceFault& fault) {
      EXPECT_EQ(fault.kind, FaultKind::Timeout) << fault.what();
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, 3s);
  }
  // A helper that answers the connect, then falls silent in the run (no word
  // that it is alive): a timeout, not a hang, the laser not confirmed off;
  // and what the helper started (here `sleep`) ends with it.
  {
    const std::string pidFile = "/tmp/rotafab-test-helper-" + std::to_string(::getpid());
    Remote device({"/bin/sh", "-c",
                   "echo $$ > " + pidFile + R"(; read l; echo '{"ok":true,"identity":"fake","id":1}'; sleep 30)"},
                  quick);
    device.connect();
    std::ifstream pidText(pidFile);
    pid_t helper = 0;
    pidText >> helper;
    std::remove(pidFile.c_str());
    ASSERT_GT(helper, 0);
    EXPECT_EQ(::kill(-helper, 0), 0) << "the helper leads a process group of its own";
    const core::Cancellation never;
    const auto start = std::chrono::steady_clock::now();
    try {
      device.run(square({}), {}, never);
      FAIL() << "ran";
    } catch (const DeviceFault& fault) {
      EXPECT_EQ(fault.kind, FaultKind::Timeout) << fault.what();
      EXPECT_FALSE(fault.laserOffConfirmed);
    }
    EXPECT_LT(std::chrono::steady_clock::now() - start, 3s);
    // (Killed, the orphaned `sleep` is gone once the system has reaped it.)
    const auto killed = std::chrono::steady_clock::now();
    while (::kill(-helper, 0) == 0 && std::chrono::steady_clock::now() - killed < 2s) std::this_thread::sleep_for(10ms);
    EXPECT_NE(::kill(-helper, 0), 0) << "the helper's `sleep` outlived it";
  }
  // A helper that answers a cancel with the driver's fault: the cancel reaches it.
  Remote device(
      {"/bin/sh", "-c",
       R"(read l; echo '{"ok":true,"identity":"fake","id":1}'; read l; read l; case "$l" in *cancel*) echo '{"fault":{"kind":"cancelled","message":"fake: cancelled","confirmed":true},"id":2}';; esac; read l)"},
      quick);
  device.connect();
  core::Cancellation cancel;
  cancel.cancel();
  try {
    device.run(square({}), {}, cancel);
    FAIL() << "ran";
  } catch (const DeviceFault& fault) {
    EXPECT_EQ(fault.kind, FaultKind::Cancelled) << fault.what();
    EXPECT_TRUE(fault.laserOffConfirmed);
  }
}

}  // namespace
}  // namespace rotafab::devices::remote
