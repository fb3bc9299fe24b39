// The simulated GRBL as the firmware (gnea/grbl 1.1h) is, byte for byte
// where a driver can tell, so that the driver's tests run against what a
// real controller does: spindle changes acknowledged only after the motion
// before them, `$` commands refused while moving, a receive buffer of the
// 128 bytes [OPT:] reports, and the status fields the firmware adds.

#include <gtest/gtest.h>

#include <chrono>
#include <regex>
#include <string>

#include "devices/grbl/GrblDriver.h"
#include "devices/sim/GrblSimulator.h"
#include "devices/transport/SerialLink.h"

namespace rotafab::devices {
namespace {

using std::chrono::milliseconds;

// A raw serial client of the simulator, past its banner.
struct Client {
  explicit Client(double timeScale = 10)
      : simulator([&] {
          sim::GrblSimulatorOptions options;
          options.timeScale = timeScale;
          return options;
        }()),
        link(openSerialLink(simulator.path(), 115200)) {
    while (auto line = link->readLine(milliseconds(300))) {
      if (line->starts_with("Grbl ")) break;
    }
  }
  // The next line that is not a status report.
  std::string reply() {
    for (;;) {
      auto line = link->readLine(milliseconds(3000));
      if (!line) return "(nothing)";
      if (!line->starts_with("<")) return *line;
    }
  }
  std::string status() {
    link->write("?", milliseconds(500));
    for (;;) {
      auto line = link->readLine(milliseconds(3000));
      if (!line) return "(nothing)";
      if (line->starts_with("<")) return *line;
    }
  }
  sim::GrblSimulator simulator;
  std::unique_ptr<Link> link;
};

// gcode.c: "All spindle state changes are synced, even in laser mode": the
// `ok` for M5 comes once the move before it has ended, not when it is read.
TEST(GrblSimulator, ASpindleChangeIsAcknowledgedOnlyOnceTheMotionBeforeItEnds) {
  Client c;
  c.link->write("G21\nG90\nM4 S500\nG1 X40 F1200\n", milliseconds(500));
  for (int i = 0; i < 4; ++i) ASSERT_EQ(c.reply(), "ok");
  EXPECT_TRUE(c.status().starts_with("<Run|")) << "the move runs (2 s of machine time)";
  c.link->write("M5 S0\n", milliseconds(500));
  ASSERT_EQ(c.reply(), "ok");
  const auto record = c.simulator.record();
  EXPECT_EQ(record.state, "Idle") << "M5's ok came before the move ended";
  EXPECT_NEAR(record.x, 40, 1e-9);
  EXPECT_FALSE(record.spindleEnabled);
  // An S alone, spindle on, in laser mode: synced as well.
  c.link->write("M4 S100\nG1 X0 F1200\nS300\n", milliseconds(500));
  for (int i = 0; i < 3; ++i) ASSERT_EQ(c.reply(), "ok");
  EXPECT_NEAR(c.simulator.record().x, 0, 1e-9);
}

// system.c: settings and the rest need Idle or Alarm (STATUS_IDLE_ERROR).
TEST(GrblSimulator, DollarCommandsWhileMovingAreError8) {
  Client c;
  c.link->write("G21\nG1 X40 F1200\n$$\n", milliseconds(500));
  EXPECT_EQ(c.reply(), "ok");
  EXPECT_EQ(c.reply(), "ok");
  EXPECT_EQ(c.reply(), "error:8");
  c.link->write("$G\n", milliseconds(500));
  EXPECT_TRUE(c.reply().starts_with("[GC:G1 ")) << "$G is allowed in any state";
  EXPECT_EQ(c.reply(), "ok");
}

// serial.c: a ring of RX_BUFFER_SIZE + 1 bytes holds 128, as [OPT:V,15,128] says.
TEST(GrblSimulator, TheReceiveBufferHolds128Bytes) {
  Client c;
  c.link->write("!", milliseconds(500));  // a hold: nothing is parsed, the bytes stay in the buffer
  c.link->write(std::string(127, ' ') + "\n", milliseconds(500));
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_EQ(c.simulator.record().mostBuffered, 128u);
  EXPECT_FALSE(c.simulator.record().overflowed);
  c.link->write(" ", milliseconds(500));
  std::this_thread::sleep_for(milliseconds(100));
  EXPECT_TRUE(c.simulator.record().overflowed) << "the 129th byte is lost";
}

// report.c: the work offset in the first report and then every 10 (idle) or
// 30 (busy) reports, the overrides with it and then every 10 or 20 (with the
// accessory state while the spindle is on), the pins while one is active;
// and the driver reads every one of them.
TEST(GrblSimulator, StatusReportsCarryTheFirmwaresOptionalFields) {
  Client c(1);
  c.simulator.setPins("P");
  c.link->write("G21\nM4 S500\nG1 X100 F600\n", milliseconds(500));
  for (int i = 0; i < 3; ++i) ASSERT_EQ(c.reply(), "ok");
  int wco = 0, overrides = 0, accessories = 0, pins = 0;
  const int reports = 45;
  for (int i = 0; i < reports; ++i) {
    const std::string report = c.status();
    wco += report.find("|WCO:0.000,0.000,0.000") != std::string::npos;
    overrides += report.find("|Ov:100,100,100") != std::string::npos;
    accessories += report.find("|A:C") != std::string::npos;
    pins += report.find("|Pn:P") != std::string::npos;
    const auto parsed = grbl::parseStatusReport(report);
    ASSERT_TRUE(parsed) << report;
    EXPECT_EQ(parsed->state, "Run") << report;
  }
  EXPECT_EQ(wco, 2) << "the first, then every 30 while busy";
  EXPECT_EQ(overrides, 3) << "after each WCO, then every 20 while busy";
  EXPECT_EQ(accessories, overrides) << "M4 on: A:C with the overrides";
  EXPECT_EQ(pins, reports);
}

}  // namespace
}  // namespace rotafab::devices
