#include "devices/JobRun.h"

#include <fmt/format.h>

#include "toolpath/AtomicFile.h"

namespace rotafab::devices {

DeviceSetup deviceSetupFor(const profiles::MachineProfile& machine) {
  DeviceSetup setup;
  for (profiles::Operation operation : profiles::kAllOperations) {
    setup.colours[operation] = machine.settingFor(operation).rgb;
  }
  setup.motion = jobs::profileMotion(machine);
  setup.bedWidth = machine.bed.width, setup.bedHeight = machine.bed.height;
  return setup;
}

JobRun::JobRun(JobRunSetup setup) : setup_(std::move(setup)) {
  const DriverEntry& driver = *setup_.device.driver;
  const DeviceSetup deviceSetup = deviceSetupFor(setup_.machine);
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

std::vector<jobs::Toolpath> JobRun::toCut() const {
  std::vector<jobs::Toolpath> cut = toolpaths_;
  if (!cut.empty() && setup_.fromStroke > 0)
    cut[0] = jobs::restOfSheet(cut[0], setup_.fromStroke, device_->motionLimits());
  return cut;
}

std::string JobRun::writeDryRun(const std::filesystem::path& file) const {
  const std::vector<jobs::Toolpath> cut = toCut();
  jobs::writeFileAtomically(file, device_->program(cut));
  return device_->describeProgram(cut);
}

std::vector<std::string> JobRun::writeDryRunOfEachSheet(
    const std::function<std::filesystem::path(int sheet)>& fileOf) const {
  std::vector<std::string> written;
  for (const jobs::Toolpath& toolpath : toCut()) {
    throwIfCancelled(setup_.cancellation);
    const std::vector<jobs::Toolpath> one{toolpath};
    const std::filesystem::path file = fileOf(toolpath.sheet);
    jobs::writeFileAtomically(file, device_->program(one));
    written.push_back(fmt::format("{}: {}", file.string(), device_->describeProgram(one)));
  }
  return written;
}

RunSummary JobRun::run(const RunEvents& events, const core::Cancellation& cancel) {
  try {
    return runSheets(events, cancel);
  } catch (const DeviceFault&) {
    if (events.stopped) events.stopped();
    throw;
  }
}

namespace {

// What a fault says of the laser when it came while a sheet was framed
// (`tracing`) or after its frame was traced (`traced`): a dark frame sends
// nothing that lights it; a lit one (the machine's frame_power) leaves it as
// the driver's stop found it, or, traced whole, off as its closing M5 was
// acknowledged.
void sayLaserAfterFrame(DeviceFault& fault, const jobs::Toolpath& sheet, bool tracing, bool traced) {
  if (!(sheet.framePower > 0) || (!tracing && !traced)) {
    fault.nothingSent = true;
  } else {
    fault.nothingSent = false;
    if (!tracing) fault.laserOffConfirmed = true;
  }
}

}  // namespace

void JobRun::frameOnly(size_t index, const core::Cancellation& cancel) {
  const jobs::Toolpath& toolpath = toolpaths_.at(index);
  bool tracing = false, traced = false;
  try {
    throwIfCancelled(&cancel);
    tracing = true;
    device_->frame(toolpath, cancel);
    tracing = false, traced = true;
    throwIfCancelled(&cancel);
  } catch (DeviceFault& fault) {
    sayLaserAfterFrame(fault, toolpath, tracing, traced);
    fault.sheet = toolpath.sheet, fault.sheets = static_cast<int>(toolpaths_.size());
    throw;
  }
  device_->disconnect();
}

RunSummary JobRun::runSheets(const RunEvents& events, const core::Cancellation& cancel) {
  RunSummary summary;
  for (size_t s = 0; s < toolpaths_.size(); ++s) {
    const jobs::Toolpath& whole = toolpaths_[s];
    const size_t first = s == 0 ? std::min(setup_.fromStroke, whole.strokes.size()) : 0;
    // Where a fault finds the job: this sheet, and its strokes cut (those
    // before `first` were, by the run that stopped). Until the sheet's own
    // run starts, none of it has been sent; a frame lights the laser only at
    // the machine's frame_power.
    size_t cut = first;
    bool streaming = false, tracing = false, traced = false;
    try {
      // Stop, do not cut blind, unless told to cut (the sheet loaded, its frame checked).
      for (bool framed = false;;) {
        const SheetGo go = events.beforeSheet ? events.beforeSheet(s, whole, framed) : SheetGo::Cut;
        if (go == SheetGo::Stop) throw DeviceFault(FaultKind::Cancelled, setup_.device.address->uri() + ": cancelled");
        throwIfCancelled(&cancel);
        if (go == SheetGo::Cut) break;
        if (events.framing) events.framing(whole);
        tracing = true;
        device_->frame(whole, cancel);
        tracing = false, traced = true;
        throwIfCancelled(&cancel);
        framed = true;
      }
      const jobs::Toolpath rest = first == 0 ? whole : jobs::restOfSheet(whole, first, device_->motionLimits());
      if (events.sheetStarted) events.sheetStarted(s, whole, first, rest.seconds / device_->timeScale());
      streaming = true;
      device_->run(
          rest,
          [&](Progress progress) {
            progress.stroke += first, progress.strokesCut += first, progress.strokes = whole.strokes.size();
            cut = progress.strokesCut;
            progress.secondsLeft /= device_->timeScale();
            if (events.progress) events.progress(progress);
          },
          cancel);
      summary.burnt += rest.burnLength, summary.estimated += rest.seconds / device_->timeScale();
      summary.strokes += rest.strokes.size();
    } catch (DeviceFault& fault) {
      if (!streaming) {
        sayLaserAfterFrame(fault, whole, tracing, traced);
      }
      fault.sheet = whole.sheet, fault.sheets = static_cast<int>(toolpaths_.size());
      fault.strokesDone = cut, fault.strokes = whole.strokes.size();
      throw;
    }
    if (events.sheetFinished) events.sheetFinished();
    ++summary.sheets;
  }
  device_->disconnect();
  return summary;
}

}  // namespace rotafab::devices
