#pragma once
// A job's sheets run on a device, as `rotafab run` and the daemon run them:
// the device opened through the registry (DriverEntry.h) and connected
// (unless a dry run need not), each sheet's toolpath planned with the
// machine and material profiles and the device's own limits; then either
// the bytes of a dry run written, or the sheets cut one after another:
// progress, pause and resume from another thread, a stop before each sheet
// after the first (for the next to be loaded), and a cancel that leaves the
// laser off (the driver's safe stop) and says where the job had got to.

#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/Cancellation.h"
#include "devices/Device.h"
#include "devices/DriverEntry.h"
#include "profiles/Profiles.h"
#include "toolpath/SheetDrawing.h"
#include "toolpath/Toolpath.h"

namespace rotafab::devices {

struct JobRunSetup {
  ParsedUri device;  // parseDeviceUri()
  profiles::MachineProfile machine;
  profiles::MaterialProfile material;
  std::vector<jobs::SheetDrawing> sheets;  // in the order to cut
  bool dryRun = false;
  // Told what the controller says it is, once connected.
  std::function<void(const std::string& identity)> connected;
  // Checked once connected and for each sheet planned: JobRun() then throws
  // DeviceFault Cancelled (the device is disconnected; nothing was sent).
  const core::Cancellation* cancellation = nullptr;
  // The first sheet goes on from this stroke (0-based): the strokes before
  // it were cut by a run that stopped. Framing traces the whole sheet.
  size_t fromStroke = 0;
};

// Before a sheet is cut: cut it now, trace its box first with the laser
// off (and then be asked again), or stop (nothing of it is sent).
enum class SheetGo { Cut, Frame, Stop };

struct RunEvents {
  // Before each sheet (`index` from 0), and again after each frame of it
  // (`framed`): whether to cut it, frame it, or stop (the job stops as
  // cancelled). The command line asks at the terminal whether the next
  // sheet is loaded, and after a frame whether to cut; a daemon waits for
  // its client. Not set: cut.
  std::function<SheetGo(size_t index, const jobs::Toolpath& sheet, bool framed)> beforeSheet;
  // Index of all, from 0; the whole sheet, the stroke its cut begins at
  // (JobRunSetup::fromStroke, else 0) and the estimated seconds of what is
  // left, in real time (Device::timeScale).
  std::function<void(size_t index, const jobs::Toolpath& sheet, size_t fromStroke, double seconds)> sheetStarted;
  std::function<void(const jobs::Toolpath& sheet)> framing;
  std::function<void(const Progress&)> progress;
  std::function<void()> sheetFinished;
  std::function<void()> stopped;  // by a fault or a cancel, before the fault is thrown
};

struct RunSummary {
  size_t sheets = 0, strokes = 0;
  double burnt = 0;      // inches
  double estimated = 0;  // seconds, real time
};

// What a device of `machine` is opened with.
DeviceSetup deviceSetupFor(const profiles::MachineProfile& machine);

class JobRun {
 public:
  // Throws std::invalid_argument (an operation with no usable setting) and
  // DeviceFault (the device cannot be opened or is not one the driver drives).
  explicit JobRun(JobRunSetup setup);
  ~JobRun();  // disconnects
  JobRun(const JobRun&) = delete;
  JobRun& operator=(const JobRun&) = delete;

  [[nodiscard]] const std::vector<jobs::Toolpath>& toolpaths() const { return toolpaths_; }
  [[nodiscard]] const DriverEntry& driver() const { return *setup_.device.driver; }

  // Writes exactly the bytes the device would be sent, atomically; returns
  // what they are ("G-code for 1 sheet (108 strokes), as the driver would send it").
  std::string writeDryRun(const std::filesystem::path& file) const;
  // The same, one file for each sheet (`fileOf(sheet number)`), each the
  // program of that sheet alone: a file of several sheets would be cut back
  // to back, onto one. Returns what each holds, in the sheets' order.
  std::vector<std::string> writeDryRunOfEachSheet(const std::function<std::filesystem::path(int sheet)>& fileOf) const;

  // Runs every sheet, each framed first where beforeSheet asks. Throws
  // DeviceFault: the driver has stopped the machine and says whether the
  // controller confirmed the laser off; a cancel is FaultKind::Cancelled.
  // Progress is the whole sheet's (strokes counted from its first).
  RunSummary run(const RunEvents& events, const core::Cancellation& cancel);

  // Traces the box of the sheet at `index` (of the setup's) with the laser
  // off, and disconnects; nothing is cut. Throws DeviceFault as run().
  void frameOnly(size_t index, const core::Cancellation& cancel);

  // From another thread while run() goes on.
  void pause() { device_->pause(); }
  void resume() { device_->resume(); }

 private:
  RunSummary runSheets(const RunEvents& events, const core::Cancellation& cancel);
  void throwIfCancelled(const core::Cancellation* cancel) const;
  // The sheets as a dry run writes them: the first from JobRunSetup::fromStroke.
  [[nodiscard]] std::vector<jobs::Toolpath> toCut() const;

  JobRunSetup setup_;
  std::unique_ptr<Device> device_;
  bool connected_ = false;
  std::vector<jobs::Toolpath> toolpaths_;
};

}  // namespace rotafab::devices
