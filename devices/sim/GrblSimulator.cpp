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

namespace rotafab::devices::sim {
namespace {

constexpr const char* kBanner = "\r\nGrbl 1.1h ['$' for help]\r\n";

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
  copy.state = alarm_ ? "Alarm" : held_ ? (holdSettle_ > 0 ? "Hold:1" : "Hold:0") : planner_.empty() ? "Idle" : "Run";
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
  if (buffer_.size() >= options_.receiveBuffer - 1) {
    record_.overflowed = true;  // GRBL's ring buffer drops it
    return;
  }
  buffer_ += byte;
  record_.mostBuffered = std::max(record_.mostBuffered, buffer_.size());
}

void GrblSimulator::takeLines() {
  for (;;) {
    const auto newline = buffer_.find('\n');
    if (newline == std::string::npos) return;
    if (planner_.size() >= options_.plannerBlocks) return;  // the line waits in the buffer
    if (held_) return;                                      // nothing is parsed during a hold
    std::string line = buffer_.substr(0, newline);
    buffer_.erase(0, newline + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    executeLine(line);
  }
}

void GrblSimulator::executeLine(const std::string& raw) {
  std::string line;
  for (char c : raw) {
    if (c != ' ') line += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  record_.lines.push_back(line);
  if (line.empty()) return reply("ok\r\n");
  if (line[0] == '$') {
    if (line == "$$") {
      reply(fmt::format(
          "$0=10\r\n$1=25\r\n$10=1\r\n$20=0\r\n$21=0\r\n$22=0\r\n$30={}\r\n$31=0\r\n$32={}\r\n$100=80.000\r\n"
          "$101=80.000\r\n$110={:.3f}\r\n$111={:.3f}\r\n$120={:.3f}\r\n$121={:.3f}\r\n$130=400.000\r\n$131=400.000\r\n"
          "ok\r\n",
          options_.maxSpindle, options_.laserMode ? 1 : 0, options_.maxRate, options_.maxRate, options_.acceleration,
          options_.acceleration));
    } else if (line == "$I") {
      reply(fmt::format("[VER:1.1h.20190825:]\r\n[OPT:V,{},{}]\r\nok\r\n", options_.plannerBlocks,
                        options_.receiveBuffer));
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
          laserModal_ = true;
        else if (value == 5)
          laserModal_ = false;
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
    planner_.push_back(
        {x.value_or(fromX), y.value_or(fromY), rapid_ ? options_.maxRate : std::min(feed_, options_.maxRate), lit});
  }
  ++record_.linesExecuted;
  reply("ok\r\n");
}

void GrblSimulator::advance(double seconds) {
  record_.laserOn = false;
  if (held_) holdSettle_ = std::max(0.0, holdSettle_ - seconds);
  while (seconds > 0 && !held_ && !alarm_ && !planner_.empty()) {
    const Block& block = planner_.front();
    if (blockDone_ == 0) startX_ = record_.x, startY_ = record_.y;
    const double length = std::hypot(block.x - startX_, block.y - startY_);
    const double speed = block.feed / 60;  // mm/s
    const double step = std::min(length - blockDone_, speed * seconds);
    blockDone_ += step;
    seconds -= step / speed;
    if (block.lit) record_.litSeconds += step / speed;
    record_.laserOn = block.lit;
    if (blockDone_ >= length - 1e-9) {
      record_.x = block.x, record_.y = block.y;
      planner_.erase(planner_.begin());
      blockDone_ = 0;
    } else {
      const double t = length > 0 ? blockDone_ / length : 1;
      record_.x = startX_ + (block.x - startX_) * t, record_.y = startY_ + (block.y - startY_) * t;
      break;
    }
  }
  if (planner_.empty() || held_ || alarm_) record_.laserOn = false;
}

void GrblSimulator::reset() {
  const bool moving = !planner_.empty() && (!held_ || holdSettle_ > 0);
  buffer_.clear();
  planner_.clear();
  blockDone_ = 0;
  held_ = false, laserModal_ = false, spindle_ = 0, feedSet_ = false, rapid_ = true;
  record_.laserOn = false;
  if (moving) {
    alarm_ = true;
    reply("ALARM:3\r\n");
  }
  reply(kBanner);
  if (alarm_) reply("[MSG:'$H'|'$X' to unlock]\r\n");
}

std::string GrblSimulator::statusReport() const {
  const char* state = alarm_             ? "Alarm"
                      : held_            ? (holdSettle_ > 0 ? "Hold:1" : "Hold:0")
                      : planner_.empty() ? "Idle"
                                         : "Run";
  return fmt::format("<{}|MPos:{:.3f},{:.3f},0.000|FS:{:.0f},{:.0f}>", state, record_.x, record_.y,
                     planner_.empty() ? 0.0 : planner_.front().feed, laserModal_ ? spindle_ : 0.0);
}

void GrblSimulator::unplug() { unplugRequested_ = true; }  // the loop thread closes the terminal

void GrblSimulator::mute(bool silent) { muted_ = silent; }

void GrblSimulator::loseNextOk() { loseOk_ = true; }

void GrblSimulator::sendGarbage() {
  const std::lock_guard lock(mutex_);
  reply("\x07\x1b[2J\xfe\xff%%garbage%%\r\n");
}

void GrblSimulator::raiseAlarm(int code) {
  const std::lock_guard lock(mutex_);
  planner_.clear();
  buffer_.clear();
  blockDone_ = 0;
  alarm_ = true, held_ = false, laserModal_ = false;
  record_.laserOn = false;
  reply(fmt::format("ALARM:{}\r\n", code));
}

void GrblSimulator::afterLines(size_t lines, std::function<void(GrblSimulator&)> fault) {
  const std::lock_guard lock(mutex_);
  faultAfter_ = lines;
  fault_ = std::move(fault);
}

}  // namespace rotafab::devices::sim
