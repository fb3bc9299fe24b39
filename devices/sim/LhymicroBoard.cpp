#include "devices/sim/LhymicroBoard.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string_view>
#include <utility>

namespace rotafab::devices::sim {

namespace {

constexpr double kMmPerMil = 0.0254;

// Every byte of the M2's language; the rest (M3-only 'W', 'A'/'T' power packets, NULs, ...) is a driver's mistake.
bool known(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') ||
         std::string_view("IBTRLMDUNSEPFC@VG|").find(c) != std::string_view::npos;
}

}  // namespace

LhymicroBoard::LhymicroBoard(Options options) : options_(options) {}

void LhymicroBoard::accept(const std::array<uint8_t, 30>& payload) {
  finishedLatch_ = false;
  // Abort and pause act on arrival, not in turn (see the header): recognised
  // by the whole packet, as the hosts send them alone.
  size_t end = payload.size();
  while (end > 0 && payload[end - 1] == 'F') --end;
  const std::string_view text(reinterpret_cast<const char*>(payload.data()), end);
  if (text == "I" && options_.abortAtOnce) {
    ++packetsExecuted_;
    abort();
    return;
  }
  if (text == "P" || text == "PN") {
    ++packetsExecuted_;
    paused_ = !paused_;
    return;
  }
  if (full()) violation(fmt::format("a packet accepted while the buffer was full ({} waiting)", queue_.size()));
  queue_.push_back(payload);
}

bool LhymicroBoard::full() const { return queue_.size() >= options_.capacityPackets; }

bool LhymicroBoard::busy() const { return !queue_.empty() || !actions_.empty(); }

bool LhymicroBoard::finished() const { return finishedLatch_ && !busy(); }

long LhymicroBoard::x() const {
  if (actions_.empty() || actions_.front().duration <= 0) return x_;
  const Action& a = actions_.front();
  return std::lround(a.segment.x0 + (a.segment.x1 - a.segment.x0) * (a.elapsed / a.duration));
}

long LhymicroBoard::y() const {
  if (actions_.empty() || actions_.front().duration <= 0) return y_;
  const Action& a = actions_.front();
  return std::lround(a.segment.y0 + (a.segment.y1 - a.segment.y0) * (a.elapsed / a.duration));
}

void LhymicroBoard::advance(double seconds) {
  clock_ += seconds;
  double left = seconds;
  // Bytes are read only when nothing is moving, so that what a byte changes
  // (laser, directions, mode) never reaches a move queued before it.
  while (!paused_) {
    if (!actions_.empty()) {
      Action& action = actions_.front();
      const double need = action.duration - action.elapsed;
      if (left < need) {
        action.elapsed += left;
        return;
      }
      left -= need;
      const Action done = action;
      actions_.pop_front();
      complete(done);
      continue;
    }
    if (queue_.empty()) return;
    const uint8_t byte = queue_.front()[readAt_++];
    interpret(byte);
    while (!queue_.empty() && readAt_ >= queue_.front().size()) {
      queue_.pop_front();
      readAt_ = 0;
      ++packetsExecuted_;
    }
  }
}

void LhymicroBoard::complete(const Action& action) {
  const BoardSegment& s = action.segment;
  x_ = s.x1, y_ = s.y1;
  if (s.x0 != s.x1 || s.y0 != s.y1) trace_.push_back(s);
  checkOnBed(x_, y_);
  if (s.homing && actions_.empty() && onlyPaddingLeft()) finishedLatch_ = true;
}

void LhymicroBoard::checkOnBed(long x, long y) {
  if (x < 0 || y < 0 || x > options_.bedWidthMils || y > options_.bedHeightMils) {
    violation(fmt::format("head off the bed at ({}, {})", x, y));
  }
}

void LhymicroBoard::violation(std::string text) { violations_.push_back(std::move(text)); }

int LhymicroBoard::peekInPacket() const {
  if (queue_.empty() || readAt_ >= queue_.front().size()) return -1;
  return queue_.front()[readAt_];
}

bool LhymicroBoard::onlyPaddingLeft() const {
  for (size_t i = 0; i < queue_.size(); ++i) {
    for (size_t j = i == 0 ? readAt_ : 0; j < queue_[i].size(); ++j) {
      if (queue_[i][j] != 'F') return false;
    }
  }
  return true;
}

void LhymicroBoard::reset() {
  mode_ = BoardMode::Default;
  jogging_ = paused_ = laser_ = false;
  xDirection_ = yDirection_ = 1;
  engaged_ = majorAxis_ = 'x';
  rasterStep_ = 0;
  digits_ = Digits::Distance;
  digitText_.clear();
  pendingDistance_ = pendingX_ = pendingY_ = 0;
  smallJump_ = false;
  codeSpeed_ = 0;
  rasterGroups_ = 0;
  sMode_ = -2;
  leaving_ = 0, leavingStep_ = 0;
}

void LhymicroBoard::abort() {
  if (!actions_.empty()) {
    // The head stops where it is; the move cut short is in the trace as far as it went.
    BoardSegment partial = actions_.front().segment;
    partial.x1 = x(), partial.y1 = y();
    x_ = partial.x1, y_ = partial.y1;
    if (partial.x0 != partial.x1 || partial.y0 != partial.y1) trace_.push_back(partial);
    checkOnBed(x_, y_);
    actions_.clear();
  }
  packetsDropped_ += queue_.size();
  queue_.clear();
  readAt_ = 0;
  reset();
}

void LhymicroBoard::addDistance(long mils) { pendingDistance_ += mils; }

void LhymicroBoard::flushDistance() {
  smallJump_ = false;
  if (pendingDistance_ == 0) return;
  const long n = std::exchange(pendingDistance_, 0);
  const long dx = engaged_ != 'y' ? n * xDirection_ : 0;
  const long dy = engaged_ != 'x' ? n * yDirection_ : 0;
  if (mode_ == BoardMode::Default) {
    pendingX_ += dx, pendingY_ += dy;
  } else {
    move(dx, dy, jogging_);
  }
}

void LhymicroBoard::runDefaultMove() {
  if (mode_ != BoardMode::Default || (pendingX_ == 0 && pendingY_ == 0)) return;
  move(std::exchange(pendingX_, 0), std::exchange(pendingY_, 0), true);
}

void LhymicroBoard::move(long dx, long dy, bool rapid) {
  if (dx == 0 && dy == 0) return;
  Action action;
  BoardSegment& s = action.segment;
  s.x0 = actions_.empty() ? x_ : actions_.back().segment.x1;
  s.y0 = actions_.empty() ? y_ : actions_.back().segment.y1;
  s.x1 = s.x0 + dx, s.y1 = s.y0 + dy;
  s.laser = laser_;
  // A compact mode entered without a speed code was reported at S1E; it runs at rapid speed.
  s.mmPerSecond = rapid || compactSpeed_ <= 0 ? options_.rapidMmPerSecond : compactSpeed_;
  if (rapid && laser_) {
    violation(fmt::format("laser on in default mode: a rapid move from ({}, {}) to ({}, {})", s.x0, s.y0, s.x1, s.y1));
  }
  // An orthogonal run is n steps, a diagonal one n steps of sqrt(2) each: the Euclidean length either way.
  action.duration = std::hypot(static_cast<double>(dx), static_cast<double>(dy)) * kMmPerMil / s.mmPerSecond;
  actions_.push_back(action);
}

void LhymicroBoard::home() {
  laser_ = false;
  Action action;
  BoardSegment& s = action.segment;
  s.x0 = actions_.empty() ? x_ : actions_.back().segment.x1;
  s.y0 = actions_.empty() ? y_ : actions_.back().segment.y1;
  s.x1 = s.y1 = 0;
  s.laser = false;
  s.homing = true;
  action.duration = std::max(options_.homeSeconds, 0.0);
  const double mm = std::hypot(static_cast<double>(s.x0), static_cast<double>(s.y0)) * kMmPerMil;
  s.mmPerSecond = action.duration > 0 ? mm / action.duration : options_.rapidMmPerSecond;
  actions_.push_back(action);
}

void LhymicroBoard::finishSpeedCode(bool suffixC) {
  const std::string text = std::exchange(digitText_, std::string());
  digits_ = Digits::Distance;
  // "hhh lll a" and, on the M2, "sss ddd ddd" (step and diagonal correction:
  // read, not used; diagonal steps take sqrt(2) of the time instead).
  if (text.size() != 7 && text.size() != 16) {
    violation(fmt::format("a speed code of {} digits: V{}", text.size(), text));
    if (text.size() < 7) return;
  }
  const long value = std::stol(text.substr(0, 3)) * 256 + std::stol(text.substr(3, 3));
  const int gear = text[6] - '0';
  // value = 65536 - (m * period + b), period the ms per mil; the low-speed ("C") timebase is 12 times finer.
  const double m = suffixC ? 12120.0 / 12 : 12120.0;
  const double b = suffixC ? 8 : gear <= 2 ? 5120 : gear == 3 ? 5632 : 6144;
  const double period = (65536 - static_cast<double>(value) - b) / m;
  if (gear < 1 || gear > 4 || period <= 0) {
    violation(fmt::format("an unreadable speed code V{}{}", text, suffixC ? "C" : ""));
    return;
  }
  codeSpeed_ = 25.4 / period;
}

void LhymicroBoard::direction(char letter) {
  const bool horizontal = letter == 'B' || letter == 'T';
  const int sign = letter == 'B' || letter == 'R' ? 1 : -1;
  // Raster: reversing along the major axis steps the minor axis by the 'G' value, onward in its direction.
  if (mode_ == BoardMode::Compact && !jogging_ && rasterStep_ > 0) {
    if (horizontal && majorAxis_ == 'x' && sign != xDirection_) move(0, rasterStep_ * yDirection_, false);
    if (!horizontal && majorAxis_ == 'y' && sign != yDirection_) move(rasterStep_ * xDirection_, 0, false);
  }
  if (horizontal) {
    xDirection_ = sign, engaged_ = 'x';
  } else {
    yDirection_ = sign, engaged_ = 'y';
  }
}

void LhymicroBoard::interpret(uint8_t byte) {
  const char c = static_cast<char>(byte);
  if (!known(c)) {
    violation(fmt::format("unknown byte 0x{:02x} in packet {}", byte, packetsExecuted_ + 1));
    return;
  }
  if (c == 'I') {
    reset();
    return;
  }
  if (mode_ == BoardMode::Finished) return;  // until the next 'I'
  breakOffLeaving(c);
  if (c >= '0' && c <= '9') {
    readDigit(c);
    return;
  }
  if (endDigits(c)) return;  // a speed code's low-speed suffix 'C', read with it
  if (readDistanceLetter(c)) return;
  flushDistance();
  runCommand(c);
}

void LhymicroBoard::breakOffLeaving(char c) {
  // "FNSE" / "@NSE" must come unbroken: padding 'F' followed by anything else was only padding.
  if (leavingStep_ > 0 && c != "NSE"[leavingStep_ - 1]) {
    // Padding inside compact mode is a hazard: a real board may read its 'F'
    // as the start of a finish (MeerK40t's parser does). Drivers pad only
    // after "@NSE", "FNSE" or a default-mode line.
    if (leaving_ == 'F' && c != 'F' && mode_ == BoardMode::Compact) {
      violation(fmt::format("padding 'F' inside compact mode, before '{}', in packet {}", c, packetsExecuted_ + 1));
    }
    leaving_ = 0, leavingStep_ = 0;
  }
}

void LhymicroBoard::readDigit(char c) {
  switch (digits_) {
    case Digits::SMode:
      if (sMode_ == -1) {
        sMode_ = c - '0';
      } else {
        violation(fmt::format("a second digit '{}' after S", c));
      }
      return;
    case Digits::Speed:
      digitText_ += c;
      return;
    case Digits::Raster:
      digitText_ += c;
      if (digitText_.size() == 3) {
        if (rasterGroups_ == 1) rasterStep_ = std::stol(digitText_);
        digitText_.clear();
        digits_ = Digits::Distance;
      }
      return;
    case Digits::Distance:
      digitText_ += c;
      if (digitText_.size() == 3) {
        addDistance(std::stol(digitText_));
        digitText_.clear();
      }
      return;
  }
}

bool LhymicroBoard::endDigits(char c) {
  // A non-digit ends the digits before it.
  switch (digits_) {
    case Digits::Speed:
      finishSpeedCode(c == 'C');
      if (c == 'C') return true;  // the low-speed suffix
      break;
    case Digits::Raster:
      violation(fmt::format("a raster step of {} digits", digitText_.size()));
      break;
    case Digits::Distance:
      if (!digitText_.empty()) violation(fmt::format("{} stray digits before '{}'", digitText_.size(), c));
      break;
    case Digits::SMode:
      break;
  }
  digitText_.clear();
  if (sMode_ != -2 && c != 'P' && c != 'E') {
    violation(fmt::format("S{} followed by '{}'", sMode_ >= 0 ? std::to_string(sMode_) : std::string(), c));
    sMode_ = -2;
  }
  if (sMode_ == -2) digits_ = Digits::Distance;
  return false;
}

bool LhymicroBoard::readDistanceLetter(char c) {
  // Distances add up until the next command letter.
  if (c == '|') {
    addDistance(25);
    smallJump_ = true;
    return true;
  }
  if (c == 'z') {
    addDistance(smallJump_ ? 26 : 255);
    smallJump_ = false;
    return true;
  }
  if (c >= 'a' && c <= 'y') {
    addDistance(c - 'a' + 1);
    smallJump_ = false;
    return true;
  }
  return false;
}

void LhymicroBoard::runCommand(char c) {
  switch (c) {
    case 'B':
    case 'T':
    case 'R':
    case 'L':
      direction(c);
      break;
    case 'M':
      engaged_ = 'm';
      break;
    case 'D':
      laser_ = true;  // in default mode a dwell in place; a rapid move with it is a violation
      break;
    case 'U':
      laser_ = false;
      break;
    case 'N':
      runN();
      break;
    case 'S':
      runS();
      break;
    case 'E':
      runE();
      break;
    case 'P':
      runP();
      break;
    case 'F':
    case '@':
      leaving_ = c;
      leavingStep_ = 1;
      break;
    case 'C':  // a speed code begins; 'V' brings its digits
      break;
    case 'V':
      digits_ = Digits::Speed;
      rasterGroups_ = 0;
      break;
    case 'G':
      ++rasterGroups_;
      digits_ = Digits::Raster;
      break;
    default:
      break;
  }
}

void LhymicroBoard::runN() {
  if (mode_ == BoardMode::Default) {
    runDefaultMove();
  } else if (!jogging_) {
    if (laser_) violation(fmt::format("laser on when compact mode ends at ({}, {}) (no U before N)", x(), y()));
    laser_ = false;
    jogging_ = true;
  }
  if (leavingStep_ == 1) leavingStep_ = 2;
}

void LhymicroBoard::runS() {
  runDefaultMove();
  sMode_ = -1;
  digits_ = Digits::SMode;
  if (leavingStep_ == 2) leavingStep_ = 3;
}

void LhymicroBoard::runE() {
  if (leavingStep_ == 3) {
    // FNSE finishes the job; @NSE leaves compact mode for default mode, where a new speed code may follow.
    jogging_ = laser_ = false;
    pendingX_ = pendingY_ = 0;
    if (leaving_ == 'F') {
      mode_ = BoardMode::Finished;
      if (actions_.empty() && onlyPaddingLeft()) finishedLatch_ = true;
    } else {
      mode_ = BoardMode::Default;
    }
    leaving_ = 0, leavingStep_ = 0;
  } else if (sMode_ >= 0) {  // "S1E": compact mode at the last speed code, the last direction letter the major axis
    mode_ = BoardMode::Compact;
    jogging_ = false;
    compactSpeed_ = codeSpeed_;
    if (compactSpeed_ <= 0) violation("compact mode without a speed code");
    majorAxis_ = engaged_ == 'y' ? 'y' : 'x';
  } else if (sMode_ == -1) {  // "SE": back from a jog
    jogging_ = false;
  }
  sMode_ = -2;
  digits_ = Digits::Distance;
}

void LhymicroBoard::runP() {
  if (sMode_ != -2) {  // "S1P" runs the moves (at 'S') and locks the rail, "S2P" unlocks it
    if (sMode_ == 1) railLocked_ = true;
    if (sMode_ == 2) railLocked_ = false;
    sMode_ = -2;
    digits_ = Digits::Distance;
  } else if (peekInPacket() == 'P') {  // two P in one packet: home
    ++readAt_;
    runDefaultMove();
    home();
  } else {  // a lone P (or "PN") inside the stream
    if (peekInPacket() == 'N') ++readAt_;
    paused_ = !paused_;
  }
}

}  // namespace rotafab::devices::sim
