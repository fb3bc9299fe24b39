#include "devices/sim/GrblSimulator.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <utility>

#include "toolpath/MotionPlan.h"

namespace rotafab::devices::sim {
namespace {

constexpr const char* kBanner = "\r\nGrbl 1.1h ['$' for help]\r\n";

// A line as GRBL's parser sees it: spaces dropped, letters upper case.
std::string normalised(const std::string& raw) {
  std::string line;
  for (char c : raw) {
    if (c != ' ') line += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return line;
}

}  // namespace

GrblSimulator::GrblSimulator(GrblSimulatorOptions options) : options_(options) {
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) {
    throw std::runtime_error("simulated GRBL: cannot open a pseudo-terminal");
  }
  path_ = ::ptsname(master_);
  // Hold the terminal open (a master with no slave open reads EIO) and make
  // it raw, so that nothing echoes before the driver opens it.
  slave_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY);
  if (slave_ < 0) throw std::runtime_error("simulated GRBL: cannot open " + path_);
  termios raw{};
  ::tcgetattr(slave_, &raw);
  ::cfmakeraw(&raw);
  ::tcsetattr(slave_, TCSANOW, &raw);
  record_.state = "Idle";
  reply(kBanner);
  thread_ = std::thread([this] { loop(); });
}

GrblSimulator::~GrblSimulator() {
  stopping_ = true;
  if (thread_.joinable()) thread_.join();
  if (master_ >= 0) ::close(master_);
  if (slave_ >= 0) ::close(slave_);
}

GrblSimulatorRecord GrblSimulator::record() const {
  const std::lock_guard lock(mutex_);
  GrblSimulatorRecord copy = record_;
  copy.state = alarm_                          ? "Alarm"
               : held_                         ? (holdSettle_ > 0 ? "Hold:1" : "Hold:0")
               : planner_.empty() && !syncing_ ? "Idle"
                                               : "Run";
  copy.spindleEnabled = laserModal_;
  return copy;
}

void GrblSimulator::reply(const std::string& text) {
  if (muted_ || unplugged_) return;
  if (text == "ok\r\n" && loseOk_.exchange(false)) return;
  if (options_.replyLatency.count() > 0) {
    delayed_.emplace_back(std::chrono::steady_clock::now() + options_.replyLatency, text);
    return;
  }
  writeNow(text);
}

void GrblSimulator::writeNow(const std::string& text) {
  size_t written = 0;
  while (written < text.size()) {
    const ssize_t n = ::write(master_, text.data() + written, text.size() - written);
    if (n <= 0) return;
    written += static_cast<size_t>(n);
  }
}

void GrblSimulator::loop() {
  auto last = std::chrono::steady_clock::now();
  double lineBudget = 0;  // bytes the paced serial line has carried and not yet delivered
  while (!stopping_) {
    if (unplugRequested_.exchange(false)) {
      // The driver's side sees the port go: hang up the terminal.
      const std::lock_guard lock(mutex_);
      unplugged_ = true;
      ::close(slave_);
      slave_ = -1;
      ::close(master_);
      master_ = -1;
    }
    pollfd fd{master_, POLLIN, 0};
    const int ready = unplugged_ ? 0 : ::poll(&fd, 1, 1);
    if (unplugged_) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    std::function<void(GrblSimulator&)> fault;
    bool lineBusy = false;
    {
      const std::lock_guard lock(mutex_);
      if (ready > 0 && (fd.revents & POLLIN)) {
        char bytes[256];
        size_t want = sizeof bytes;
        if (options_.baud > 0) {
          // The line carries baud/10 bytes a second while bytes wait; idle
          // time earns no credit, and at most 4 ms' worth is banked (46 bytes
          // at 115200 baud: a burst never skips the line's time).
          const auto now = std::chrono::steady_clock::now();
          lineBudget = std::min(lineBudget + std::chrono::duration<double>(now - paced_).count() * options_.baud / 10,
                                std::max(1.0, options_.baud / 10.0 * 0.004));
          paced_ = now;
          want = static_cast<size_t>(lineBudget);
        }
        const ssize_t n = want > 0 ? ::read(master_, bytes, want) : 0;
        if (n > 0 && options_.baud > 0) lineBudget -= static_cast<double>(n);
        for (ssize_t i = 0; i < n && !muted_; ++i) receive(bytes[i]);
      }
      if (!muted_ && !unplugged_) takeLines();
      while (!delayed_.empty() && delayed_.front().first <= std::chrono::steady_clock::now() && !unplugged_) {
        writeNow(delayed_.front().second);
        delayed_.pop_front();
      }
      const auto now = std::chrono::steady_clock::now();
      advance(std::chrono::duration<double>(now - last).count() * options_.timeScale);
      last = now;
      if (fault_ && record_.linesExecuted >= faultAfter_) fault = std::exchange(fault_, nullptr);
      if (ready <= 0 || !(fd.revents & POLLIN)) paced_ = now;  // nothing waiting: the line is idle
      lineBusy = options_.baud > 0 && ready > 0 && (fd.revents & POLLIN) && lineBudget < 1;
    }
    if (lineBusy) std::this_thread::sleep_for(std::chrono::microseconds(200));  // the line is busy
    if (fault) fault(*this);
  }
}

void GrblSimulator::receive(char byte) {
  switch (byte) {
    case '?':
      reply(statusReport() + "\r\n");
      return;
    case '!':
      // The machine decelerates before it stands (Hold:1, then Hold:0).
      // (Idle, it holds at once: Hold:0.)
      if (!held_) held_ = true, holdSettle_ = planner_.empty() ? 0 : 0.2;
      return;
    case '~':
      held_ = false, holdSettle_ = 0;
      return;
    case 0x18:
      reset();
      return;
    default:
      break;
  }
  if (static_cast<unsigned char>(byte) >= 0x80) return;  // the extended realtime commands: none simulated
  if (buffer_.size() >= options_.receiveBuffer) {
    record_.overflowed = true;  // GRBL's ring buffer (serial.c, RX_BUFFER_SIZE + 1 slots) drops it
    return;
  }
  buffer_ += byte;
  record_.mostBuffered = std::max(record_.mostBuffered, buffer_.size());
}

void GrblSimulator::takeLines() {
  if (stalled_) return;
  for (;;) {
    // A spindle change waits for the motion before it (spindle_sync():
    // protocol_buffer_synchronize()); nothing after it is read meanwhile.
    if (syncing_) {
      if (!planner_.empty()) return;
      const std::string line = *std::exchange(syncing_, std::nullopt);
      executeLine(line);
      continue;
    }
    const auto newline = buffer_.find('\n');
    if (newline == std::string::npos) return;
    if (planner_.size() >= options_.plannerBlocks) return;  // the line waits in the buffer
    if (held_) return;                                      // nothing is parsed during a hold
    std::string line = buffer_.substr(0, newline);
    buffer_.erase(0, newline + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!planner_.empty() && needsSync(line)) {
      syncing_ = line;
      continue;
    }
    executeLine(line);
  }
}

// gcode.c, laser mode: a change of M3/M4/M5 is synced; so is a new S on a
// line without motion while the spindle is on.
bool GrblSimulator::needsSync(const std::string& raw) const {
  const std::string line = normalised(raw);
  if (line.empty() || line[0] == '$') return false;
  bool motion = false;
  std::optional<double> s;
  std::optional<int> m;
  for (size_t at = 0; at < line.size();) {
    const char letter = line[at++];
    double value = 0;
    const auto [end, error] = std::from_chars(line.data() + at, line.data() + line.size(), value);
    if (error != std::errc()) return false;  // an error: answered at once
    at = static_cast<size_t>(end - line.data());
    if (letter == 'X' || letter == 'Y') motion = true;
    if (letter == 'S') s = value;
    if (letter == 'M' && (value == 3 || value == 4 || value == 5)) m = static_cast<int>(value);
  }
  if (m && *m != spindleMode_) return true;
  return s && *s != spindle_ && !motion && spindleMode_ != 5;
}

void GrblSimulator::executeLine(const std::string& raw) {
  const std::string line = normalised(raw);
  record_.lines.push_back(line);
  if (line.empty()) return reply("ok\r\n");
  if (line[0] == '$') {
    // system.c: settings, build info, homing and the rest need Idle or
    // Alarm ($G and $X do not).
    const bool busy = !planner_.empty() || held_;
    if (busy && line != "$G" && line != "$X") return reply("error:8\r\n");
    if (line == "$$") {
      reply(fmt::format(
          "$0=10\r\n$1=25\r\n$10=1\r\n$11={:.3f}\r\n$12=0.002\r\n$20=0\r\n$21=0\r\n$22=0\r\n$30={}\r\n$31=0\r\n"
          "$32={}\r\n$100=80.000\r\n$101=80.000\r\n$110={:.3f}\r\n$111={:.3f}\r\n$120={:.3f}\r\n$121={:.3f}\r\n"
          "$130=400.000\r\n$131=400.000\r\nok\r\n",
          options_.junctionDeviation, options_.maxSpindle, options_.laserMode ? 1 : 0, options_.maxRate,
          options_.maxRate, options_.acceleration, options_.acceleration));
    } else if (line == "$I") {
      reply(fmt::format("[VER:1.1h.20190825:]\r\n[OPT:V,{},{}]\r\nok\r\n", options_.plannerBlocks,
                        options_.receiveBuffer));
    } else if (line == "$G") {
      reply(fmt::format("[GC:G{} G54 G17 G21 G90 G94 M{} M9 T0 F{:g} S{:g}]\r\nok\r\n", rapid_ ? 0 : 1, spindleMode_,
                        feed_, spindle_));
    } else if (line == "$X") {
      alarm_ = false;
      reply("[MSG:Caution: Unlocked]\r\nok\r\n");
    } else if (line == "$H") {
      reply("error:5\r\n");
    } else if (line == "$32=1" || line == "$32=0") {
      options_.laserMode = line.back() == '1';
      reply("ok\r\n");
    } else {
      reply("error:3\r\n");
    }
    return;
  }
  if (alarm_) return reply("error:9\r\n");
  // Words: a letter and a number each.
  std::optional<double> x, y;
  size_t at = 0;
  while (at < line.size()) {
    const char letter = line[at++];
    // (std::from_chars, not strtod: "G0X25" is no hexadecimal number)
    double value = 0;
    const auto [end, error] = std::from_chars(line.data() + at, line.data() + line.size(), value);
    if (error != std::errc())
      return reply(!std::isalpha(static_cast<unsigned char>(letter)) ? "error:1\r\n" : "error:2\r\n");
    at = static_cast<size_t>(end - line.data());
    switch (letter) {
      case 'G':
        if (value == 0)
          rapid_ = true;
        else if (value == 1)
          rapid_ = false;
        else if (value != 21 && value != 90 && value != 94)
          return reply("error:20\r\n");
        break;
      case 'M':
        if (value == 3 || value == 4)
          laserModal_ = true, spindleMode_ = static_cast<int>(value);
        else if (value == 5)
          laserModal_ = false, spindleMode_ = 5;
        else
          return reply("error:20\r\n");
        break;
      case 'S':
        spindle_ = value;
        break;
      case 'F':
        if (value <= 0) return reply("error:4\r\n");
        feed_ = value, feedSet_ = true;
        break;
      case 'X':
        x = value;
        break;
      case 'Y':
        y = value;
        break;
      default:
        return reply("error:20\r\n");
    }
  }
  if (x || y) {
    if (!rapid_ && !feedSet_) return reply("error:22\r\n");
    double fromX = record_.x, fromY = record_.y;
    if (!planner_.empty()) fromX = planner_.back().x, fromY = planner_.back().y;
    // Laser mode lights only G1 (and never at S0); without it the laser stays on through G0 too.
    const bool lit = laserModal_ && spindle_ > 0 && (!rapid_ || !options_.laserMode);
    Block block{x.value_or(fromX), y.value_or(fromY), lit, 0, 0, 0, 0, 0, 0};
    block.length = std::hypot(block.x - fromX, block.y - fromY);
    // planner.c: a move of no steps is dropped (and acknowledged).
    if (block.length >= 0.5 / 80.0) {
      block.unitX = (block.x - fromX) / block.length, block.unitY = (block.y - fromY) / block.length;
      const jobs::Point2 unit(block.unitX, block.unitY);
      const double rate = jobs::axisLimited(options_.maxRate / 60, unit);
      block.nominal = rapid_ ? rate : std::min(feed_ / 60, rate);
      block.acceleration = jobs::axisLimited(options_.acceleration, unit);
      // From a stop there is no junction; else the corner's and both blocks' speeds bound the entry.
      if (!planner_.empty()) {
        const double nominals = std::min(planner_.back().nominal, block.nominal);
        block.maxEntrySquared = std::min(
            nominals * nominals, jobs::junctionSpeedSquared(jobs::Point2(lastUnitX_, lastUnitY_), unit,
                                                            options_.acceleration, options_.junctionDeviation, true));
      }
      lastUnitX_ = block.unitX, lastUnitY_ = block.unitY;
      if (record_.motionStartedAt < 0) record_.motionStartedAt = clock_;
      planner_.push_back(block);
      replan();
    }
  }
  ++record_.linesExecuted;
  reply("ok\r\n");
}

// The look-ahead (planner.c's recalculation): how fast the first block may
// leave, so that every block after it can still stop by the end of the last.
void GrblSimulator::replan() {
  if (planner_.size() < 2) {
    exitSpeed_ = 0;
    return;
  }
  std::vector<jobs::PlannedBlock> ahead;
  for (size_t i = 1; i < planner_.size(); ++i) {
    ahead.push_back(
        {planner_[i].length, planner_[i].nominal, planner_[i].acceleration, planner_[i].maxEntrySquared, 0});
  }
  const Block& first = planner_.front();
  const double reachable =
      std::sqrt(speed_ * speed_ + 2 * first.acceleration * std::max(0.0, first.length - blockDone_));
  jobs::planEntrySpeeds(ahead, reachable);
  exitSpeed_ = std::sqrt(ahead.front().entrySquared);
}

void GrblSimulator::advance(double seconds) {
  setLaser(false);
  clock_ += seconds;
  if (held_) {
    holdSettle_ = std::max(0.0, holdSettle_ - seconds);
    speed_ = 0;  // (the deceleration of a hold is not modelled: it stands at once)
  }
  if (stalled_) return;
  replan();
  // Small steps of the trapezoid: accelerate toward the block's speed,
  // brake when the distance left is what braking to the exit speed takes.
  constexpr double kStep = 0.0005;  // simulated seconds
  while (seconds > 1e-12 && !held_ && !alarm_ && !planner_.empty()) {
    const Block& block = planner_.front();
    if (blockDone_ == 0) startX_ = record_.x, startY_ = record_.y;
    const double dt = std::min(seconds, kStep);
    const double left = block.length - blockDone_;
    const double exit = std::min(exitSpeed_, block.nominal);
    double next = speed_;
    if (speed_ * speed_ - exit * exit >= 2 * block.acceleration * left) {
      next = std::max(exit, speed_ - block.acceleration * dt);
    } else if (speed_ < block.nominal) {
      next = std::min(block.nominal, speed_ + block.acceleration * dt);
    } else {
      next = block.nominal;
    }
    double step = (speed_ + next) / 2 * dt, used = dt;
    if (step <= 0) step = std::min(left, 1e-9), used = dt;  // (cannot stand still in a block)
    if (step >= left) {
      used = dt * left / step;
      step = left;
    }
    speed_ = next;
    record_.topSpeed = std::max(record_.topSpeed, speed_);
    blockDone_ += step;
    seconds -= used;
    if (block.lit) record_.litSeconds += used;
    setLaser(block.lit);
    if (blockDone_ >= block.length - 1e-9) {
      if (block.lit) {
        record_.litMoves.push_back(
            {block.x - block.unitX * block.length, block.y - block.unitY * block.length, block.x, block.y});
        if (options_.litMoveFinished) options_.litMoveFinished(record_.litMoves.back());
      }
      record_.x = block.x, record_.y = block.y;
      planner_.erase(planner_.begin());
      blockDone_ = 0;
      speed_ = std::min(speed_, exit);
      if (planner_.empty()) {
        speed_ = 0;
        record_.motionEndedAt = clock_ - seconds;
      }
      replan();
    } else {
      const double t = block.length > 0 ? blockDone_ / block.length : 1;
      record_.x = startX_ + (block.x - startX_) * t, record_.y = startY_ + (block.y - startY_) * t;
    }
  }
  if (planner_.empty() || held_ || alarm_) setLaser(false);
}

void GrblSimulator::reset() {
  const bool moving = !planner_.empty() && (!held_ || holdSettle_ > 0);
  buffer_.clear();
  planner_.clear();
  syncing_.reset();
  blockDone_ = 0, speed_ = 0, exitSpeed_ = 0;
  stalled_ = false;
  wcoCounter_ = 0, overrideCounter_ = 0;
  held_ = false, laserModal_ = false, spindle_ = 0, feedSet_ = false, rapid_ = true, spindleMode_ = 5;
  setLaser(false);
  if (moving) {
    alarm_ = true;
    reply("ALARM:3\r\n");
  }
  reply(kBanner);
  if (alarm_) reply("[MSG:'$H'|'$X' to unlock]\r\n");
}

std::string GrblSimulator::statusReport() {
  const char* state = alarm_                          ? "Alarm"
                      : held_                         ? (holdSettle_ > 0 ? "Hold:1" : "Hold:0")
                      : planner_.empty() && !syncing_ ? "Idle"
                                                      : "Run";
  const bool busy = !planner_.empty() || held_;
  std::string report = fmt::format("<{}|MPos:{:.3f},{:.3f},0.000|FS:{:.0f},{:.0f}", state, record_.x, record_.y,
                                   speed_ * 60, laserModal_ ? spindle_ : 0.0);
  // report.c: the pins only while one is active; the work offset every 10
  // (idle) or 30 (busy) reports, the overrides every 10 or 20, and at once
  // after the work offset.
  if (!pins_.empty()) report += "|Pn:" + pins_;
  if (wcoCounter_ > 0) {
    --wcoCounter_;
  } else {
    wcoCounter_ = (busy ? 30 : 10) - 1;
    if (overrideCounter_ == 0) overrideCounter_ = 1;
    report += "|WCO:0.000,0.000,0.000";
  }
  if (overrideCounter_ > 0) {
    --overrideCounter_;
  } else {
    overrideCounter_ = (busy ? 20 : 10) - 1;
    report += "|Ov:100,100,100";
    if (laserModal_) report += spindleMode_ == 3 ? "|A:S" : "|A:C";
  }
  report += ">";
  if (std::exchange(garbleStatus_, false)) {
    // Line noise: a few bytes changed on the way.
    report[report.size() / 2] = '\xb7';
    report[report.find('|')] = '~';
  }
  return report;
}

void GrblSimulator::unplug() { unplugRequested_ = true; }  // the loop thread closes the terminal

void GrblSimulator::mute(bool silent) { muted_ = silent; }

void GrblSimulator::loseNextOk() { loseOk_ = true; }

void GrblSimulator::garbleNextStatus() {
  const std::lock_guard lock(mutex_);
  garbleStatus_ = true;
}

void GrblSimulator::stall() {
  const std::lock_guard lock(mutex_);
  stalled_ = true;
}

void GrblSimulator::setPins(std::string pins) {
  const std::lock_guard lock(mutex_);
  pins_ = std::move(pins);
}

void GrblSimulator::sendGarbage() {
  const std::lock_guard lock(mutex_);
  reply("\x07\x1b[2J\xfe\xff%%garbage%%\r\n");
}

void GrblSimulator::setLaser(bool lit) {
  const bool changed = record_.laserOn != lit;
  record_.laserOn = lit;
  if (changed && options_.laserChanged) options_.laserChanged(lit);
}

void GrblSimulator::raiseAlarm(int code) {
  const std::lock_guard lock(mutex_);
  planner_.clear();
  buffer_.clear();
  blockDone_ = 0;
  syncing_.reset();
  speed_ = 0;
  alarm_ = true, held_ = false, laserModal_ = false, spindleMode_ = 5;
  setLaser(false);
  reply(fmt::format("ALARM:{}\r\n", code));
}

void GrblSimulator::afterLines(size_t lines, std::function<void(GrblSimulator&)> fault) {
  const std::lock_guard lock(mutex_);
  faultAfter_ = lines;
  fault_ = std::move(fault);
}

}  // namespace rotafab::devices::sim
