#pragma once
// The device abstraction: one interface for every cutter, whatever
// its wire protocol, as libsigrok has one for every logic analyser. A device
// knows toolpaths (toolpath/Toolpath.h), never meshes. Every call that waits on
// the device has a timeout; a timeout, a disconnect, an error or alarm the
// controller reports, or a cancel ends in a DeviceFault, and the driver has
// turned the laser off (as far as the controller still answers) before it
// throws.

#include <functional>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>

#include "core/Cancellation.h"
#include "toolpath/Toolpath.h"

namespace rotafab::devices {

enum class FaultKind {
  Timeout,       // the device stopped answering
  Disconnected,  // the port or the USB device went away
  Alarm,         // the controller stopped itself (GRBL ALARM:N, ...)
  Error,         // the controller refused a command (GRBL error:N, ...)
  Refused,       // the device is not set up to run this job (laser mode off, bed too small, ...)
  Protocol,      // the device said something no controller of its kind says
  Cancelled,     // the user stopped the job
  Stalled,       // the machine stopped moving while it says it runs
};
std::string_view faultName(FaultKind kind);

class DeviceFault : public std::runtime_error {
 public:
  DeviceFault(FaultKind kind, const std::string& what) : std::runtime_error(what), kind(kind) {}
  FaultKind kind;
  // Whether the driver saw the controller take its laser-off command after
  // the fault (it cannot when the device stopped answering or went away).
  bool laserOffConfirmed = false;
  // Nothing that could light the laser had been sent (the device never
  // connected, a sheet never started, the print spooler never took the
  // file): the laser is off whatever the controller says.
  bool nothingSent = false;
  // Where the job stopped (JobRun fills these in): the sheet (1-based, 0
  // before the first), and the strokes of it the machine had finished
  // (Progress::strokesCut): a resume goes on from the next.
  int sheet = 0, sheets = 0;
  size_t strokesDone = 0, strokes = 0;
};

// What is true of the laser after `fault`, in words for the operator:
// "nothing that lights the laser was sent", "the controller confirmed the
// laser off", or that it did not and the laser must be switched off at the machine.
std::string laserStateAfter(const DeviceFault& fault);

struct Progress {
  int sheet = 1;
  size_t stroke = 0, strokes = 0;  // strokes the controller has taken (acknowledged), of how many
  // Strokes the machine has surely finished cutting: a controller takes
  // strokes ahead of the head (GRBL's planner holds 15 moves), so this
  // trails `stroke`. Never more than were cut: a resume from the next
  // stroke cuts none twice but the one the head was in.
  size_t strokesCut = 0;
  size_t bytesAcknowledged = 0, bytesTotal = 0;
  double secondsLeft = 0;  // estimated
};

struct DeviceStatus {
  std::string state;    // the controller's own word: "Idle", "Run", "Hold:0", "Alarm", ...
  double x = 0, y = 0;  // inches, machine position
};

// In a catch block: runs `stopSafely` (the driver's way to leave the laser
// off; it returns whether the controller confirmed it, and never throws),
// then rethrows, a DeviceFault marked with that answer.
[[noreturn]] void stopAndRethrow(const std::function<bool()>& stopSafely);

class Device {
 public:
  virtual ~Device() = default;
  // Connects and checks that the controller is one this driver drives; returns what it says it is.
  virtual std::string connect() = 0;
  virtual void home() = 0;
  // Traces the box of the toolpath's strokes with the laser off, or lit at
  // its framePower where the machine allows one (GRBL); a cancel stops it,
  // and the machine, safely (DeviceFault Cancelled).
  virtual void frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) = 0;
  // Runs the job to its end; `progress` is called as the device acknowledges it.
  virtual void run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
                   const core::Cancellation& cancel) = 0;
  // From another thread while run() streams: hold and resume motion.
  virtual void pause() = 0;
  virtual void resume() = 0;
  virtual DeviceStatus status() = 0;
  // Stops the machine and turns its laser off (GRBL: feed hold, reset,
  // M5), connected or not; returns whether the controller confirmed the
  // laser off. Never throws. A daemon calls it on every device it starts
  // with, whatever a run before it left behind.
  virtual bool stopSafely() noexcept = 0;
  virtual void disconnect() = 0;
  // What the machine can do, for planning its toolpaths (once connected, as
  // the controller reports it).
  [[nodiscard]] virtual jobs::MotionLimits motionLimits() const { return {}; }
  // Machine seconds per real second: a simulator may run faster than the
  // machine it stands for; progress and estimates are said in real time.
  [[nodiscard]] virtual double timeScale() const { return 1.0; }
  // The bytes run() would send for these toolpaths, one after another, as a
  // dry run writes them (docs/CONTRACT.md, "Devices"), and what they are, for people:
  // "G-code for 1 sheet (108 strokes), as the driver would send it".
  [[nodiscard]] virtual std::string program(const std::vector<jobs::Toolpath>& toolpaths) const = 0;
  [[nodiscard]] virtual std::string describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const = 0;
};

}  // namespace rotafab::devices
