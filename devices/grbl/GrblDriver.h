#pragma once
// GRBL 1.1 (and grblHAL) laser controllers, over serial or TCP.
// Connect: wait for the banner, read `$$` and `$I` (the receive buffer from
// [OPT:...]), refuse to cut unless laser mode is on ($32=1). Run: the job's
// G-code (GCode.h) streamed by character counting against the receive
// buffer (gnea/grbl's stream.py method), with realtime `?` status polls; a
// hold is `!`, a resume `~`. On any error, alarm, timeout, cancel or
// disconnect: feed hold, soft reset (0x18), and `M5 S0` once the controller
// answers again, then a DeviceFault. A garbled line now and then is
// skipped (a run of them is a fault); a machine that says Run and stands
// still without taking lines is a stall.

#include <atomic>
#include <map>
#include <memory>

#include "devices/Device.h"
#include "devices/DriverEntry.h"
#include "devices/grbl/GCode.h"
#include "devices/transport/SerialLink.h"

namespace rotafab::devices::grbl {

struct GrblTimeouts {
  Millis banner{5000};     // after opening (an Arduino resets and waits in its bootloader first)
  Millis answer{5000};     // for `ok` to a command, or any line while a job streams
  Millis homing{120000};   // for `$H`
  Millis poll{200};        // between status polls while streaming
  Millis stopHold{5000};   // after a fault: for the machine to stand in its hold
  Millis stopReset{3000};  // after a fault: for the banner after the reset
};

class GrblDriver : public Device {
 public:
  // `open` makes the link (serial, TCP, or the simulator's pseudo-terminal).
  // `timeScale`: machine seconds per real second, for a simulator that runs faster than real.
  GrblDriver(std::function<std::unique_ptr<Link>()> open, GrblTimeouts timeouts = {}, double timeScale = 1.0);
  std::string connect() override;
  void home() override;
  void frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) override;
  void run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
           const core::Cancellation& cancel) override;
  // Send-and-wait instead of character counting: one line at a time, each
  // after the last one's `ok` (for comparison: the benchmark).
  void setCharacterCounting(bool on) { characterCounting_ = on; }
  void pause() override { holdRequested_ = true; }
  void resume() override { resumeRequested_ = true; }
  DeviceStatus status() override;
  bool stopSafely() noexcept override;
  void disconnect() override;

  // What the controller reported at connect().
  [[nodiscard]] const std::map<int, double>& settings() const { return settings_; }
  [[nodiscard]] size_t receiveBuffer() const { return receiveBuffer_; }
  // The G-code options (S scale) and motion limits ($110, $120) of the
  // controller; GRBL's defaults before connect().
  [[nodiscard]] GCodeOptions gcodeOptions() const;
  [[nodiscard]] jobs::MotionLimits motionLimits() const override;
  [[nodiscard]] double timeScale() const override { return timeScale_; }
  // The G-code, each line ended by a newline.
  [[nodiscard]] std::string program(const std::vector<jobs::Toolpath>& toolpaths) const override;
  [[nodiscard]] std::string describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const override;

 private:
  void send(const std::string& line);  // a command and its `ok`
  std::string expectLine(Millis timeout, const char* waitingFor);
  // Polls until the controller is Idle; throws on silence, an alarm, a cancel,
  // or a stall (Run at one position for `stallAfter`).
  // `reported`: told each status report line on the way.
  void waitIdle(Millis silence, const core::Cancellation* cancel, Millis stallAfter = Millis(30000),
                const std::function<void(const std::string&)>& reported = nullptr);
  // Feed hold; once the machine has stopped (Hold:0), soft reset, which
  // turns the laser off without the alarm a reset in motion raises; then
  // M5 S0. Returns whether the controller answered it all. Never throws.

  std::function<std::unique_ptr<Link>()> open_;
  GrblTimeouts timeouts_;
  std::unique_ptr<Link> link_;
  std::map<int, double> settings_;
  size_t receiveBuffer_ = 128;
  size_t plannerBlocks_ = 15;  // [OPT:]'s
  bool characterCounting_ = true;
  double timeScale_ = 1.0;
  std::atomic<bool> holdRequested_{false}, resumeRequested_{false};
};

// The registry's entry (DriverEntry.h): grbl:///dev/PORT[?baud=N] and
// grbl+tcp://HOST[:PORT]; CH340, FTDI, CP210x and Arduino USB serial adapters.
const DriverEntry& entry();

// A status report "<Run|MPos:1.000,2.000,0.000|FS:500,0>" as a DeviceStatus (MPos in mm -> inches).
std::optional<DeviceStatus> parseStatusReport(const std::string& line);

}  // namespace rotafab::devices::grbl
