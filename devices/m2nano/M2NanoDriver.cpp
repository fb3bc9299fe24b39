#include "devices/m2nano/M2NanoDriver.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

namespace rotafab::devices::m2nano {
namespace {

constexpr uint8_t kOut = 0x02, kIn = 0x82;  // the CH341's bulk endpoints
constexpr uint8_t kStatusRequest = 0xA0;    // the CH341's "read parallel status" command

using Clock = std::chrono::steady_clock;

std::string_view statusWord(int status) {
  switch (status) {
    case kOk:
      return "OK";
    case kBusy:
      return "Busy";
    case kCrcError:
      return "CRC error";
    case kFinished:
      return "Finished";
    case kPowerFault:
      return "Power fault";
    default:
      return "Unknown";
  }
}

}  // namespace

M2NanoDriver::M2NanoDriver(std::function<std::unique_ptr<UsbLink>()> open, M2NanoTimeouts timeouts)
    : open_(std::move(open)), timeouts_(timeouts) {}

std::string M2NanoDriver::connect() {
  // The link is kept only once the board answers: a half-set-up one would
  // let run() skip connecting.
  link_.reset();
  struct Keep {
    std::unique_ptr<UsbLink>& link;
    bool connected = false;
    ~Keep() {
      if (!connected) link.reset();
    }
  } keep{link_};
  link_ = open_();
  // The CH341's parallel port in EPP 1.9 mode, as every K40 program starts it.
  link_->control(0x40, 0xB1, 0x0102, 0, nullptr, 0, timeouts_.transfer);
  std::string chip;
  try {
    uint8_t version[2] = {0, 0};
    if (link_->control(0xC0, 0x5F, 0, 0, version, 2, timeouts_.transfer) == 2) {
      chip = fmt::format(", CH341 version {}", version[0] | version[1] << 8);
    }
  } catch (const DeviceFault& fault) {
    if (fault.kind == FaultKind::Disconnected) throw;  // the version is only informative
  }
  const auto until = Clock::now() + timeouts_.ready;
  for (;;) {
    const int status = readStatus();
    // A CRC error or "finished" left from an earlier job is ready too.
    if (status == kOk || status == kFinished || status == kCrcError) break;
    if (status == kPowerFault) {
      throw DeviceFault(FaultKind::Refused, link_->name() +
                                                ": the board reports a power fault (status 239): is the laser's "
                                                "power supply on?");
    }
    if (Clock::now() > until) {
      throw DeviceFault(FaultKind::Timeout, fmt::format("{}: the board stayed busy for {} ms after connecting",
                                                        link_->name(), timeouts_.ready.count()));
    }
    std::this_thread::sleep_for(timeouts_.poll);
  }
  resends_ = 0;
  paused_ = false;
  holdWanted_ = false;
  keep.connected = true;
  return fmt::format("Lihuiyu M2 Nano on {}{}", link_->name(), chip);
}

int M2NanoDriver::readStatus() {
  for (int attempt = 1;; ++attempt) {
    link_->bulkWrite(kOut, &kStatusRequest, 1, timeouts_.transfer);
    uint8_t reply[32] = {};  // the board sends 6 bytes; a larger buffer cannot overflow
    const auto got = link_->bulkRead(kIn, reply, sizeof reply, timeouts_.transfer);
    if (got && *got >= 2) {
      const int status = reply[1];
      if (status != kOk && status != kBusy && status != kCrcError && status != kFinished && status != kPowerFault) {
        throw DeviceFault(FaultKind::Protocol, fmt::format("{}: status {} (0x{:02x}), which no M2 Nano reports",
                                                           link_->name(), status, status));
      }
      return status;
    }
    if (got) {
      throw DeviceFault(FaultKind::Protocol,
                        fmt::format("{}: a status reply of {} byte (the board sends 6)", link_->name(), *got));
    }
    if (attempt == 3) {
      throw DeviceFault(FaultKind::Timeout, fmt::format("{}: no answer to 3 status requests of {} ms each",
                                                        link_->name(), timeouts_.transfer.count()));
    }
  }
}

void M2NanoDriver::send(const Packet& packet, const core::Cancellation* cancel, Clock::time_point deadline) {
  finishedSeen_ = false;
  for (int rejected = 0;;) {
    link_->bulkWrite(kOut, packet.data(), packet.size(), timeouts_.transfer);
    // Busy (238) means the board is still checking the packet or has no room
    // for another yet: ask again until it says OK, or that the packet arrived corrupted.
    const auto until = std::min(deadline, Clock::now() + busy_);
    int status = readStatus();
    for (int polls = 1; status != kOk && status != kCrcError; ++polls) {
      // The board can finish (FNSE, a home) before it says OK to the packet that ended the job.
      if (status == kFinished) finishedSeen_ = true;
      if (status == kPowerFault) {
        throw DeviceFault(FaultKind::Alarm, link_->name() + ": the board reports a power fault (status 239)");
      }
      if (cancel && cancel->cancelled()) throw DeviceFault(FaultKind::Cancelled, link_->name() + ": cancelled");
      if (Clock::now() > until) {
        throw DeviceFault(FaultKind::Timeout,
                          fmt::format("{}: the board stayed busy for {} s", link_->name(), busy_.count() / 1000));
      }
      // A packet is checked in moments, a full queue drains at the speed of the cut.
      if (polls > 10) std::this_thread::sleep_for(timeouts_.poll);
      status = readStatus();
    }
    if (status == kOk) return;
    if (Clock::now() > deadline) {
      throw DeviceFault(FaultKind::Timeout, link_->name() + ": the board rejected the packet until the time ran out");
    }
    ++resends_;
    if (++rejected >= timeouts_.crcResends) {
      throw DeviceFault(FaultKind::Protocol, fmt::format("{}: the board rejected the same packet {} times (CRC "
                                                         "errors): check the USB cable",
                                                         link_->name(), rejected));
    }
  }
}

void M2NanoDriver::sendLines(const std::vector<std::string>& lines, const core::Cancellation* cancel) {
  for (const std::string& line : lines) {
    for (const Packet& p : packets(line)) send(p, cancel);
  }
}

void M2NanoDriver::waitFinished(Millis limit, const core::Cancellation* cancel) {
  const auto until = Clock::now() + limit;
  for (;;) {
    if (std::exchange(finishedSeen_, false)) return;
    if (cancel && cancel->cancelled()) throw DeviceFault(FaultKind::Cancelled, link_->name() + ": cancelled");
    const int status = readStatus();
    if (status == kFinished) return;
    if (status == kPowerFault) {
      throw DeviceFault(FaultKind::Alarm, link_->name() + ": the board reports a power fault (status 239)");
    }
    std::this_thread::sleep_for(timeouts_.poll);
    if (Clock::now() > until) {
      throw DeviceFault(FaultKind::Timeout,
                        fmt::format("{}: the board did not report the job finished within {} s", link_->name(),
                                    std::chrono::duration_cast<std::chrono::seconds>(limit).count()));
    }
  }
}

bool M2NanoDriver::stopSafely() noexcept {
  // "I" alone (K40 Whisperer's emergency stop): the board leaves compact
  // mode, where alone the laser fires, and drops what it has queued. Sent at
  // once, without waiting for the board to be ready. A board that took it
  // says OK; one that has run it (even behind what it had queued) can then
  // home ("IPP") and say it has finished: only that confirms the laser off.
  try {
    if (!link_) return false;
    paused_ = false;
    busy_ = timeouts_.busy;
    const auto until = Clock::now() + timeouts_.stop;
    const Packet stop = packet("I");
    bool taken = false;
    for (int sent = 0; sent < 5 && !taken && Clock::now() < until; ++sent) {
      link_->bulkWrite(kOut, stop.data(), stop.size(), timeouts_.transfer);
      int status = readStatus();
      while ((status == kBusy || status == kFinished) && Clock::now() < until) {
        std::this_thread::sleep_for(timeouts_.poll);
        status = readStatus();
      }
      if (status == kPowerFault) return false;  // it may not have taken it
      taken = status == kOk;
    }
    if (!taken) return false;
    send(packet("IPP"), nullptr, until);
    for (;;) {
      if (std::exchange(finishedSeen_, false) || readStatus() == kFinished) return true;
      if (Clock::now() > until) return false;
      std::this_thread::sleep_for(timeouts_.poll);
    }
  } catch (...) {
    return false;
  }
}

void M2NanoDriver::home() {
  if (!link_) connect();
  try {
    sendLines({"IPP"}, nullptr);
    waitFinished(Millis(60000), nullptr);
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

void M2NanoDriver::frame(const jobs::Toolpath& toolpath, const core::Cancellation& cancel) {
  if (!link_) connect();
  try {
    const double mmPerSecond = 30;  // slow enough to follow with the eye
    sendLines(frameLines(toolpath, mmPerSecond), &cancel);
    const auto box = jobs::toolpathBounds(toolpath);
    const double seconds = (2 * (box[2] - box[0] + box[3] - box[1]) + box[2] + box[3]) * 25.4 / mmPerSecond;
    waitFinished(Millis(60000 + static_cast<long>(timeouts_.finishSlack * seconds * 1000)), &cancel);
  } catch (...) {
    stopAndRethrow([this] { return stopSafely(); });
  }
}

void M2NanoDriver::run(const jobs::Toolpath& toolpath, const std::function<void(const Progress&)>& progress,
                       const core::Cancellation& cancel) {
  if (!link_) connect();
  holdWanted_ = false;  // a pause from before the job is not for it
  try {
    // A packet's moves can take long at a slow speed ('z' is 255 mils): a
    // full board makes room only when it has run one.
    double slowest = 100;
    for (const jobs::ToolpathStroke& stroke : toolpath.strokes) slowest = std::min(slowest, stroke.speed * 25.4);
    busy_ = std::max(timeouts_.busy, Millis(static_cast<long>(2 * 30 * 255 * 0.0254 / std::max(slowest, 1.0) * 1000)));
    const LhymicroJob whole = jobProgram(toolpath);
    Progress report;
    report.sheet = toolpath.sheet;
    report.strokes = toolpath.strokes.size();
    for (const std::string& line : whole.lines) report.bytesTotal += line.size();
    // The program sent: the whole job, or after a hold, the rest of it from stroke `first` on.
    bool finishing = false;  // the job's end (FNSE) has been sent
    for (size_t first = 0;;) {
      const LhymicroJob job = first == 0 ? whole : jobProgram(toolpath, first);
      size_t programBytes = 0, sent = 0;
      for (const std::string& line : job.lines) programBytes += line.size();
      const size_t base = first == 0 ? 0 : whole.strokeEnds[first - 1];
      const auto tell = [&] {
        // (Proportional within a resumed program, whose bytes differ from the
        // whole job's; never backwards across a hold.)
        report.bytesAcknowledged = std::max(
            report.bytesAcknowledged,
            base + static_cast<size_t>(static_cast<double>(sent) * static_cast<double>(report.bytesTotal - base) /
                                       static_cast<double>(std::max<size_t>(programBytes, 1))));
        report.stroke =
            first + static_cast<size_t>(std::upper_bound(job.strokeEnds.begin(), job.strokeEnds.end(), sent) -
                                        job.strokeEnds.begin());
        // The board runs what it has queued after the packets are taken: a
        // stroke is surely cut once twice the simulator's queue (8 packets;
        // a real board's depth is not documented) has been sent after it.
        constexpr size_t kQueuedBytes = 16 * 30;
        if (sent > kQueuedBytes) {
          report.strokesCut =
              std::max(report.strokesCut,
                       first + static_cast<size_t>(
                                   std::upper_bound(job.strokeEnds.begin(), job.strokeEnds.end(), sent - kQueuedBytes) -
                                   job.strokeEnds.begin()));
        }
        report.secondsLeft =  // the board queues only a few packets
            toolpath.seconds * (1 - static_cast<double>(report.bytesAcknowledged) /
                                        static_cast<double>(std::max<size_t>(report.bytesTotal, 1)));
        if (progress) progress(report);
      };
      std::optional<size_t> heldAfter;  // the stroke of `job` after which the job is held
      for (const std::string& line : job.lines) {
        const size_t lineStart = sent;
        for (size_t at = 0; at < line.size() && !heldAfter;) {
          if (cancel.cancelled()) throw DeviceFault(FaultKind::Cancelled, link_->name() + ": cancelled");
          // A hold comes at the end of the next stroke in this line, where
          // the laser is off: the rest of the stroke, then "@NSE" (compact
          // mode left, the job not finished), then nothing until the resume.
          // (The board's own pause, "PN", could stop it with the laser lit.)
          const auto end = std::lower_bound(job.strokeEnds.begin(), job.strokeEnds.end(), lineStart + at);
          if (holdWanted_ && end != job.strokeEnds.end() && *end <= lineStart + line.size()) {
            for (const Packet& p : packets(line.substr(at, *end - lineStart - at) + "@NSE")) send(p, &cancel);
            sent = *end;
            heldAfter = static_cast<size_t>(end - job.strokeEnds.begin());
            tell();
            break;
          }
          const size_t upTo = std::min(line.size(), at + 30);
          send(packet(line.substr(at, upTo - at)), &cancel);
          sent += upTo - at, at = upTo;
          tell();
        }
        if (heldAfter) break;
      }
      if (!heldAfter) {
        finishing = !job.strokeEnds.empty();
        break;
      }
      paused_ = true;
      while (holdWanted_) {
        if (cancel.cancelled()) throw DeviceFault(FaultKind::Cancelled, link_->name() + ": cancelled");
        std::this_thread::sleep_for(Millis(100));
        if (readStatus() == kPowerFault) {  // the board must still answer, and well
          throw DeviceFault(FaultKind::Alarm, link_->name() + ": the board reports a power fault (status 239)");
        }
      }
      paused_ = false;
      first += *heldAfter + 1;
      if (first == toolpath.strokes.size()) break;  // held after the last stroke: nothing left to cut
    }
    // The board has the rest of the job queued; it has cut it when it says
    // "finished" (a job held after its last stroke never says it: the home does).
    if (finishing) {
      waitFinished(Millis(60000 + static_cast<long>(timeouts_.finishSlack * toolpath.seconds * 1000)), &cancel);
    }
    report.stroke = report.strokesCut = report.strokes;
    report.bytesAcknowledged = report.bytesTotal;
    report.secondsLeft = 0;
    if (progress) progress(report);
    // Home, so that the next sheet starts from a known place.
    sendLines({"IPP"}, &cancel);
    waitFinished(Millis(60000), &cancel);
    busy_ = timeouts_.busy;
  } catch (...) {
    busy_ = timeouts_.busy;
    stopAndRethrow([this] { return stopSafely(); });
  }
}

DeviceStatus M2NanoDriver::status() {
  if (!link_) connect();
  DeviceStatus status;
  status.state = std::string(statusWord(readStatus()));
  return status;  // the board does not say where the head is
}

void M2NanoDriver::disconnect() { link_.reset(); }

std::string M2NanoDriver::program(const std::vector<jobs::Toolpath>& toolpaths) const { return egvProgram(toolpaths); }

std::string M2NanoDriver::describeProgram(const std::vector<jobs::Toolpath>& toolpaths) const {
  return describeEgvProgram(toolpaths);
}

}  // namespace rotafab::devices::m2nano
