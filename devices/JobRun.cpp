#include "devices/JobRun.h"

#include <fmt/format.h>

#include "toolpath/AtomicFile.h"

namespace rotafab::devices {

JobRun::JobRun(JobRunSetup setup) : setup_(std::move(setup)) {
  const DriverEntry& driver = *setup_.device.driver;
  DeviceSetup deviceSetup;
  for (profiles::Operation operation : profiles::kAllOperations) {
    deviceSetup.colours[operation] = setup_.machine.settingFor(operation).rgb;
  }
  // Nothing of the job is sent before run(): a fault here leaves the laser as it was.
  try {
    device_ = driver.open(*setup_.device.address, deviceSetup);
    if (!setup_.dryRun || driver.connectsForDryRun(*setup_.device.address)) {
      const std::string identity = device_->connect();
      connected_ = true;
      if (setup_.connected) setup_.connected(identity);
    }
  } catch (DeviceFault& fault) {
    fault.nothingSent = true;
    throw;
  }
  const jobs::MotionLimits limits = device_->motionLimits();
  for (const jobs::SheetDrawing& sheet : setup_.sheets) {
    throwIfCancelled(setup_.cancellation);
    toolpaths_.push_back(jobs::planToolpath(sheet, setup_.machine, setup_.material, limits));
  }
  throwIfCancelled(setup_.cancellation);
}

void JobRun::throwIfCancelled(const core::Cancellation* cancel) const {
  if (cancel && cancel->cancelled()) {
    throw DeviceFault(FaultKind::Cancelled, setup_.device.address->uri() + ": cancelled");
  }
}

JobRun::~JobRun() {
  if (device_) device_->disconnect();
}

std::string JobRun::writeDryRun(const std::filesystem::path& file) const {
  jobs::writeFileAtomically(file, device_->program(toolpaths_));
  return device_->describeProgram(toolpaths_);
}

std::vector<std::string> JobRun::writeDryRunOfEachSheet(
    const std::function<std::filesystem::path(int sheet)>& fileOf) const {
  std::vector<std::string> written;
  for (const jobs::Toolpath& toolpath : toolpaths_) {
    throwIfCancelled(setup_.cancellation);
    const std::vector<jobs::Toolpath> one{toolpath};
    const std::filesystem::path file = fileOf(toolpath.sheet);
    jobs::writeFileAtomically(file, device_->program(one));
    written.push_back(fmt::format("{}: {}", file.string(), device_->describeProgram(one)));
  }
  return written;
}

RunSummary JobRun::run(bool frame, const RunEvents& events, const core::Cancellation& cancel) {
  try {
    return runSheets(frame, events, cancel);
  } catch (const DeviceFault&) {
    if (events.stopped) events.stopped();
    throw;
  }
}

RunSummary JobRun::runSheets(bool frame, const RunEvents& events, const core::Cancellation& cancel) {
  RunSummary summary;
  for (size_t s = 0; s < toolpaths_.size(); ++s) {
    const jobs::Toolpath& toolpath = toolpaths_[s];
    // Where a fault finds the job: this sheet, and its strokes acknowledged.
    // Until the sheet's own run starts, none of it has been sent (framing
    // moves with the laser off).
    size_t acknowledged = 0;
    bool streaming = false;
    try {
      // Stop, do not cut blind, unless the next sheet is known to be loaded.
      const bool loaded = s == 0 || !events.beforeSheet || events.beforeSheet(toolpath);
      if (!loaded) throw DeviceFault(FaultKind::Cancelled, setup_.device.address->uri() + ": cancelled");
      throwIfCancelled(&cancel);
      if (events.sheetStarted) events.sheetStarted(s, toolpath, toolpath.seconds / device_->timeScale());
      if (frame) {
        if (events.framing) events.framing();
        device_->frame(toolpath);
        throwIfCancelled(&cancel);  // a cancel while framing: the laser was never lit
      }
      streaming = true;
      device_->run(
          toolpath,
          [&](Progress progress) {
            acknowledged = progress.stroke;
            progress.secondsLeft /= device_->timeScale();
            if (events.progress) events.progress(progress);
          },
          cancel);
    } catch (DeviceFault& fault) {
      fault.nothingSent = fault.nothingSent || !streaming;
      fault.sheet = static_cast<int>(s) + 1, fault.sheets = static_cast<int>(toolpaths_.size());
      fault.strokesDone = acknowledged, fault.strokes = toolpath.strokes.size();
      throw;
    }
    if (events.sheetFinished) events.sheetFinished();
    ++summary.sheets;
    summary.burnt += toolpath.burnLength, summary.estimated += toolpath.seconds / device_->timeScale();
    summary.strokes += toolpath.strokes.size();
  }
  device_->disconnect();
  return summary;
}

}  // namespace rotafab::devices
