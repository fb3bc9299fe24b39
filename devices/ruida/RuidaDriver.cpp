#include "devices/ruida/RuidaDriver.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>
#include <utility>

namespace rotafab::devices::ruida {
namespace {

using Clock = std::chrono::steady_clock;

const Bytes kStop = {0xD8, 0x01}, kPause = {0xD8, 0x02}, kResume = {0xD8, 0x03}, kHomeXY = {0xD8, 0x2A};

}  // namespace

RuidaDriver::RuidaDriver(std::function<std::unique_ptr<RuidaChannel>()> open, uint8_t magic, jobs::MotionLimits motion,
                         RuidaTimeouts timeouts, double timeScale)
    : open_(std::move(open)), magic_(magic), motion_(motion), timeouts_(timeouts), timeScale_(timeScale) {}

std::string RuidaDriver::where() const { return channel_ ? channel_->name() : std::string("the Ruida controller"); }

std::string RuidaDriver::connect() {
  channel_.reset();
  auto channel = open_();
  // A controller answers its card ID; the magic number is right when the answer reads back.
  const int64_t card = channel->read(kMemoryCardId);
  const int64_t bedX = channel->read(kMemoryBedX), bedY = channel->read(kMemoryBedY);
  channel_ = std::move(channel);
  bedHeight_ = static_cast<double>(bedY) / kMicrometresPerInch;
  holdWanted_ = false;
  return fmt::format("Ruida controller (card 0x{:08X}, bed {:.0f} x {:.0f} mm) on {}", card,
                     static_cast<double>(bedX) / 1000, static_cast<double>(bedY) / 1000, channel_->name());
}

void RuidaDriver::followHold(bool& held) {
  const bool wanted = holdWanted_;  // once: a resume may come between two reads
  if (wanted != held) {
    channel_->send(wanted ? kPause : kResume);
    held = wanted;
  }
}

void RuidaDriver::runJob(const Bytes& stream, double machineSeconds, bool mustRun,
                         const std::function<void(size_t, Millis)>& sent, const core::Cancellation& cancel) {
  if (channel_->read(kMemoryStatus) & kStatusJobRuns) {
    throw DeviceFault(FaultKind::Refused, where() +
                                              ": the controller is running a job already (started from its "
                                              "panel or another program): stop it there, or wait for it");
  }
  holdWanted_ = false;
  bool held = false;
  const auto cancelled = [&] {
    if (cancel.cancelled()) throw DeviceFault(FaultKind::Cancelled, where() + ": cancelled");
  };
  const auto headAt = [&] { return std::pair{channel_->read(kMemoryX), channel_->read(kMemoryY)}; };
  // Where the head stands before the job (a jog from the panel let finish first, for a few seconds).
  for (const auto until = Clock::now() + Millis(5000);
       (channel_->read(kMemoryStatus) & kStatusMoving) && Clock::now() < until;) {
    cancelled();
    std::this_thread::sleep_for(timeouts_.poll);
  }
  const auto startedAt = headAt();
  size_t bytes = 0;
  for (const Bytes& packet : packetsOf(stream, channel_->maxPacket())) {
    cancelled();
    followHold(held);
    channel_->send(packet);
    bytes += packet.size();
    if (sent) sent(bytes, Millis(0));
  }
  // The controller has the whole job; it has run it once it has been seen
  // at it (a job running, the head moving, or the head moved: a job too
  // short to be caught running) and is now at rest: no job, the head
  // still, in the same place at two reads in a row. One not seen at it
  // within its estimated time and a few seconds has not been seen to run.
  const double expected =
      std::isfinite(machineSeconds) ? std::clamp(machineSeconds / timeScale_, 0.0, 1e6) : 0;  // seconds
  const auto limit = Millis(60000 + static_cast<long>(3 * expected * 1000));
  const auto grace = Millis(3000 + static_cast<long>(expected * 1000));
  Millis running(0);  // since the last packet, not held
  auto lastAt = startedAt;
  for (bool seen = false;;) {
    cancelled();
    followHold(held);
    const auto before = Clock::now();
    const int64_t word = channel_->read(kMemoryStatus);
    const bool runs = word & kStatusJobRuns, moving = word & kStatusMoving;
    const auto at = headAt();
    if (sent) sent(bytes, running);
    seen = seen || runs || moving || at != startedAt;
    if (seen && !runs && !moving && !held && at == lastAt) return;
    lastAt = at;
    if (!seen && !held && running > grace) {
      if (!mustRun) return;  // a frame: nothing of it lights the laser
      throw DeviceFault(FaultKind::Refused, where() +
                                                ": the controller took the sheet but was not seen to run it (no "
                                                "job running, the head where it was): look at the machine before "
                                                "sending it again (is it set to keep jobs in its memory?)");
    }
    if (!held && running > limit) {
      throw DeviceFault(
          FaultKind::Stalled,
          fmt::format("{}: the controller still runs the job {} s after it was sent (expected {:.0f} s)", where(),
                      std::chrono::duration_cast<std::chrono::seconds>(limit).count(), machineSeconds / timeScale_));
    }
    std::this_thread::sleep_for(timeouts_.poll);
    if (!held) running += std::chrono::duration_cast<Millis>(Clock::now() - before);
  }
}

void RuidaDriver::home() {
  if (!channel_) connect();
  try {
    channel_->send(kHomeXY);
    const auto until = Clock::now() + Millis(120000);
    std::this_thread::sleep_for(timeouts_.poll);
    while (channel_->read(kMemoryStatus) & kStatusMoving) {
      if (Clock::now() > until) throw DeviceFault(FaultKind::Timeout, where() + ": the head did not home in 120 s");
      std::this_thread::sleep_for(timeouts_.poll);
    }
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

void RuidaDriver::frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) {
  if (!channel_) connect();
  try {
    const auto box = jobs::toolpathBounds(toolpath);
    // The moves go at the controller's own travel speed; 50 mm/s is slow for one.
    const double seconds = (2 * (box[2] - box[0] + box[3] - box[1]) + box[2] + box[3]) * 25.4 / 50;
    runJob(frameStream(toolpath), seconds, false, {}, cancel);
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

void RuidaDriver::run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
                      const core::Cancellation& cancel) {
  if (!channel_) connect();
  try {
    const Bytes stream = jobStream(toolpath);
    Progress report;
    report.sheet = toolpath.sheet;
    report.strokes = toolpath.strokes.size();
    report.bytesTotal = stream.size();
    report.secondsLeft = toolpath.seconds;
    // The controller takes the whole job long before it has cut it, and
    // does not say how far it has got: a stroke counts as cut only once
    // the job has ended (a resume after a stop starts the sheet again).
    runJob(
        stream, toolpath.seconds, true,
        [&](size_t bytes, Millis running) {
          report.bytesAcknowledged = bytes;
          report.stroke = report.strokes * bytes / std::max<size_t>(stream.size(), 1);
          // The time left, as the estimate has it, once the whole job is with the controller.
          report.secondsLeft =
              std::max(0.0, toolpath.seconds - static_cast<double>(running.count()) / 1000 * timeScale_);
          if (progress) progress(report);
        },
        cancel);
    report.stroke = report.strokesCut = report.strokes;
    report.bytesAcknowledged = report.bytesTotal;
    report.secondsLeft = 0;
    if (progress) progress(report);
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

DeviceStatus RuidaDriver::status() {
  if (!channel_) connect();
  const int64_t word = channel_->read(kMemoryStatus);
  DeviceStatus status;
  status.state = (word & kStatusJobRuns) ? "Run" : (word & kStatusMoving) ? "Moving" : "Idle";
  // Micrometres from the machine's origin at the bed's top-left, y down.
  status.x = static_cast<double>(channel_->read(kMemoryX)) / kMicrometresPerInch;
  status.y = bedHeight_ - static_cast<double>(channel_->read(kMemoryY)) / kMicrometresPerInch;
  return status;
}

bool RuidaDriver::stopSafely() noexcept {
  // The controller's stop ends the job and its laser at once; it is
  // confirmed when the controller reports no job running.
  try {
    if (!channel_) return false;
    holdWanted_ = false;
    channel_->send(kStop);
    const auto until = Clock::now() + timeouts_.stop;
    for (;;) {
      if (!(channel_->read(kMemoryStatus) & kStatusJobRuns)) return true;
      if (Clock::now() > until) return false;
      std::this_thread::sleep_for(timeouts_.poll);
    }
  } catch (...) {
    return false;
  }
}

void RuidaDriver::disconnect() { channel_.reset(); }

std::string RuidaDriver::program(const std::vector<jobs::Toolpath>& toolpaths) const {
  const Swizzle swizzle(magic_);
  std::string out;
  for (const jobs::Toolpath& toolpath : toolpaths) {
    const Bytes file = swizzle(jobStream(toolpath));
    out.append(file.begin(), file.end());
  }
  return out;
}

std::string RuidaDriver::describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const {
  size_t strokes = 0;
  for (const jobs::Toolpath& toolpath : toolpaths) strokes += toolpath.strokes.size();
  return fmt::format("a Ruida job for {} sheet{} ({} strokes), as RDWorks saves it (.rd, magic 0x{:02X})",
                     toolpaths.size(), toolpaths.size() == 1 ? "" : "s", strokes, magic_);
}

}  // namespace rotafab::devices::ruida
